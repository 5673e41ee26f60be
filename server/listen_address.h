// The address a server listens on, checked before gRPC sees it: gRPC takes the port modulo
// 65536 or picks a random one for a port it cannot parse (127.0.0.1:99999 served on some other
// port), so the server checks it first.
#ifndef SPLINEGRID_SERVER_LISTEN_ADDRESS_H_
#define SPLINEGRID_SERVER_LISTEN_ADDRESS_H_

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace splinegrid::server {

// The port of HOST:PORT or [IPV6]:PORT, a decimal number in [min_port, 65535]; -1 for the
// forms without a port (unix:PATH, unix-abstract:NAME). INVALID_ARGUMENT, quoting the address,
// for a missing or malformed port, one out of range, or an IPv6 host without brackets.
absl::StatusOr<int> ParseListenPort(absl::string_view address, int min_port);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_LISTEN_ADDRESS_H_
