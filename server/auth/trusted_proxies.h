// Proxies whose word on the client is taken: without tokens a caller is its connection, and
// behind a proxy (nginx) every call arrives on one of the proxy's connections, so each would be
// a caller of its own and the turns and per-caller limits would do nothing. A trusted proxy
// names the client's connection in the metadata `x-client-address: ADDRESS:PORT` (nginx:
// `grpc_set_header x-client-address $remote_addr:$remote_port;`), and the call's caller is that
// connection. The metadata of any other peer is ignored: a peer outside the trusted ranges
// cannot choose its principal (one inside them can: trust only what only the proxy reaches).
// With tokens the token names the caller and this plays no part.
#ifndef SPLINEGRID_SERVER_AUTH_TRUSTED_PROXIES_H_
#define SPLINEGRID_SERVER_AUTH_TRUSTED_PROXIES_H_

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace splinegrid::server {

// The metadata key a trusted proxy names the client's connection with.
inline constexpr char kClientAddressHeader[] = "x-client-address";

class TrustedProxies {
 public:
  // None: every peer is its own caller.
  TrustedProxies() = default;

  // `list`: comma-separated IPv4 or IPv6 addresses or CIDR ranges ("127.0.0.1",
  // "10.0.0.0/8", "::1", "fd00::/8"); blanks around entries are ignored; "" trusts none.
  // INVALID_ARGUMENT naming the entry.
  static absl::StatusOr<TrustedProxies> Parse(absl::string_view list);

  bool empty() const { return ranges_.empty(); }

  // The caller's name for a call from gRPC peer `peer` ("ipv4:127.0.0.1:40312",
  // "ipv6:%5B::1%5D:40312" as gRPC writes it, or with plain brackets) whose `x-client-address` metadata is `client` (nullopt: none): the
  // client's connection in the same form ("ipv4:192.0.2.7:51234") when the peer is a trusted
  // proxy and `client` is a valid ADDRESS:PORT (IPv6 with or without brackets), else `peer`.
  std::string CallerName(const std::string& peer, std::optional<absl::string_view> client) const;

 private:
  struct Range {
    int family = 0;  // AF_INET or AF_INET6
    std::array<uint8_t, 16> address{};
    int prefix_bits = 0;
  };
  bool Trusts(int family, const std::array<uint8_t, 16>& address) const;

  std::vector<Range> ranges_;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_AUTH_TRUSTED_PROXIES_H_
