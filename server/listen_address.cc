#include "server/listen_address.h"

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/util/quote.h"

namespace splinegrid::server {

absl::StatusOr<int> ParseListenPort(absl::string_view address, int min_port) {
  if (absl::StartsWith(address, "unix:") || absl::StartsWith(address, "unix-abstract:")) {
    return -1;
  }
  const std::string quoted = QuoteClientString(address);
  absl::string_view host, port;
  if (absl::StartsWith(address, "[")) {
    const size_t close = address.find(']');
    if (close == absl::string_view::npos || address.substr(close + 1, 1) != ":") {
      return absl::InvalidArgumentError(
          absl::StrCat(quoted, " is not [IPV6]:PORT (the port is missing)"));
    }
    host = address.substr(0, close + 1);
    port = address.substr(close + 2);
  } else {
    const size_t colon = address.rfind(':');
    if (colon == absl::string_view::npos) {
      return absl::InvalidArgumentError(
          absl::StrCat(quoted, " has no port: give HOST:PORT or [IPV6]:PORT"));
    }
    host = address.substr(0, colon);
    port = address.substr(colon + 1);
    if (absl::StrContains(host, ':')) {
      return absl::InvalidArgumentError(
          absl::StrCat(quoted, ": write an IPv6 address in brackets, [IPV6]:PORT"));
    }
  }
  if (host.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(quoted, " has no host"));
  }
  int value = 0;
  bool digits = !port.empty() && port.size() <= 5;
  for (const char c : port) {
    digits = digits && absl::ascii_isdigit(static_cast<unsigned char>(c));
    if (digits) value = value * 10 + (c - '0');
  }
  if (!digits || value < min_port || value > 65535) {
    return absl::InvalidArgumentError(absl::StrCat("the port ", QuoteClientString(port), " of ",
                                                   quoted, " is not a number in ", min_port,
                                                   "-65535"));
  }
  return value;
}

}  // namespace splinegrid::server
