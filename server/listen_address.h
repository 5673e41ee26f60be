// The address a server listens on, checked before gRPC sees it: gRPC takes the port modulo
// 65536 or picks a random one for a port it cannot parse (127.0.0.1:99999 served on some other
// port), so the server checks it first.
#ifndef SPLINEGRID_SERVER_LISTEN_ADDRESS_H_
#define SPLINEGRID_SERVER_LISTEN_ADDRESS_H_

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace splinegrid::server {

// The port of HOST:PORT or [IPV6]:PORT, a decimal number in [min_port, 65535]; -1 for the
// forms without a port (unix:PATH, unix-abstract:NAME). INVALID_ARGUMENT, quoting the address,
// for a missing or malformed port, one out of range, or an IPv6 host without brackets.
absl::StatusOr<int> ParseListenPort(absl::string_view address, int min_port);

// Whether a TCP listener could bind HOST:PORT (a checked address, ParseListenPort): binds a
// socket to every address the host resolves to, as gRPC does (SO_REUSEADDR, no SO_REUSEPORT),
// and closes it. OK when one of them binds, or when the check cannot say (port 0, unix
// sockets, a host that does not resolve: gRPC then answers). UNAVAILABLE naming the address and
// the system's reason when none binds: "in use" (another process listens there) or "not an
// address of this machine". Checked before the server starts, so that a busy port is refused
// with one line and before the store is opened, not after a page of gRPC's log.
absl::Status CheckCanListen(const std::string& address);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_LISTEN_ADDRESS_H_
