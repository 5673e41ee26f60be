#include "server/auth/trusted_proxies.h"

#include <arpa/inet.h>
#include <sys/socket.h>

#include <algorithm>

#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace splinegrid::server {
namespace {

// An IPv4 or IPv6 address (no brackets, no port): its family and bytes, or nullopt.
struct Address {
  int family = 0;
  std::array<uint8_t, 16> bytes{};
};
std::optional<Address> ParseAddress(absl::string_view text) {
  if (text.empty() || text.size() > 45) return std::nullopt;
  const std::string s(text);
  Address a;
  if (inet_pton(AF_INET, s.c_str(), a.bytes.data()) == 1) {
    a.family = AF_INET;
    return a;
  }
  if (inet_pton(AF_INET6, s.c_str(), a.bytes.data()) == 1) {
    a.family = AF_INET6;
    return a;
  }
  return std::nullopt;
}

// "ADDRESS:PORT" with ADDRESS IPv4, IPv6 or [IPv6]: the address and the port, or nullopt.
std::optional<std::pair<Address, int>> ParseAddressAndPort(absl::string_view text) {
  const size_t colon = text.rfind(':');
  if (colon == absl::string_view::npos) return std::nullopt;
  int port = 0;
  if (!absl::SimpleAtoi(text.substr(colon + 1), &port) || port < 0 || port > 65535) {
    return std::nullopt;
  }
  absl::string_view host = text.substr(0, colon);
  // gRPC writes an IPv6 peer as a URI, its brackets escaped: ipv6:%5B::1%5D:40312.
  if (absl::ConsumePrefix(&host, "[")) {
    if (!absl::ConsumeSuffix(&host, "]")) return std::nullopt;
  } else if (absl::ConsumePrefix(&host, "%5B") || absl::ConsumePrefix(&host, "%5b")) {
    if (!absl::ConsumeSuffix(&host, "%5D") && !absl::ConsumeSuffix(&host, "%5d")) {
      return std::nullopt;
    }
  }
  const std::optional<Address> address = ParseAddress(host);
  if (!address) return std::nullopt;
  return std::make_pair(*address, port);
}

std::string CanonicalName(const Address& a, int port) {
  char text[INET6_ADDRSTRLEN] = {};
  inet_ntop(a.family, a.bytes.data(), text, sizeof(text));
  return a.family == AF_INET ? absl::StrCat("ipv4:", text, ":", port)
                             : absl::StrCat("ipv6:[", text, "]:", port);
}

}  // namespace

absl::StatusOr<TrustedProxies> TrustedProxies::Parse(absl::string_view list) {
  TrustedProxies proxies;
  if (absl::StripAsciiWhitespace(list).empty()) return proxies;
  for (absl::string_view entry : absl::StrSplit(list, ',')) {
    entry = absl::StripAsciiWhitespace(entry);
    absl::string_view host = entry;
    std::optional<int> bits;  // none: the whole address
    bool bits_ok = true;
    if (const size_t slash = entry.find('/'); slash != absl::string_view::npos) {
      host = entry.substr(0, slash);
      int parsed = 0;
      bits_ok = absl::SimpleAtoi(entry.substr(slash + 1), &parsed) && parsed >= 0;
      bits = parsed;
    }
    const std::optional<Address> address = ParseAddress(host);
    const int max_bits = address && address->family == AF_INET ? 32 : 128;
    if (!address || !bits_ok || (bits && *bits > max_bits)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "trusted_proxies: '", entry,
          "' is not an IPv4 or IPv6 address or ADDRESS/BITS range (e.g. 127.0.0.1, 10.0.0.0/8, "
          "::1, fd00::/8)"));
    }
    proxies.ranges_.push_back({address->family, address->bytes, bits.value_or(max_bits)});
  }
  return proxies;
}

bool TrustedProxies::Trusts(int family, const std::array<uint8_t, 16>& address) const {
  for (const Range& r : ranges_) {
    if (r.family != family) continue;
    bool inside = true;
    for (int bit = 0; bit < r.prefix_bits && inside; ++bit) {
      const uint8_t mask = static_cast<uint8_t>(0x80 >> (bit % 8));
      inside = (address[bit / 8] & mask) == (r.address[bit / 8] & mask);
    }
    if (inside) return true;
  }
  return false;
}

std::string TrustedProxies::CallerName(const std::string& peer,
                                       std::optional<absl::string_view> client) const {
  if (ranges_.empty() || !client) return peer;
  absl::string_view from = peer;
  if (!absl::ConsumePrefix(&from, "ipv4:") && !absl::ConsumePrefix(&from, "ipv6:")) return peer;
  auto proxy = ParseAddressAndPort(from);
  if (!proxy) return peer;
  // An IPv4 proxy written as ::ffff:a.b.c.d (gRPC 1.51 itself writes those as ipv4:).
  Address& a = proxy->first;
  static constexpr uint8_t kMapped[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xff, 0xff};
  if (a.family == AF_INET6 && std::equal(kMapped, kMapped + 12, a.bytes.begin())) {
    std::array<uint8_t, 16> v4{};
    std::copy(a.bytes.begin() + 12, a.bytes.end(), v4.begin());
    a = {AF_INET, v4};
  }
  if (!Trusts(a.family, a.bytes)) return peer;
  const auto named = ParseAddressAndPort(absl::StripAsciiWhitespace(*client));
  if (!named) return peer;
  return CanonicalName(named->first, named->second);
}

}  // namespace splinegrid::server
