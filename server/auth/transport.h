// The transport of a listening port: plaintext or TLS (optionally mutual), from ServerOptions.
#ifndef SPLINEGRID_SERVER_AUTH_TRANSPORT_H_
#define SPLINEGRID_SERVER_AUTH_TRANSPORT_H_

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "grpcpp/grpcpp.h"
#include "server/server_options.h"

namespace splinegrid::server {

// Whether the listening address `address` (host:port, [v6]:port or unix:PATH) only accepts
// connections from this machine: localhost, 127.0.0.0/8, ::1 and unix sockets.
bool IsLoopbackAddress(absl::string_view address);

// The credentials of the listening port: TLS with tls_cert_file/tls_key_file (mutual with
// tls_client_ca_file), else plaintext. INVALID_ARGUMENT for an incomplete TLS configuration or
// plaintext on a non-loopback address without `insecure`; NOT_FOUND / INVALID_ARGUMENT naming
// the flag and the path for a file that cannot be read or is not PEM.
absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> MakeServerCredentials(
    const ServerOptions& options);

// A short description for the start-up line: "plaintext", "TLS" or "mTLS".
std::string TransportName(const ServerOptions& options);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_AUTH_TRANSPORT_H_
