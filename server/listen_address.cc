#include "server/listen_address.h"

#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

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

absl::Status CheckCanListen(const std::string& address) {
  const absl::StatusOr<int> port = ParseListenPort(address, /*min_port=*/0);
  if (!port.ok() || *port <= 0) return absl::OkStatus();
  // The host as gRPC resolves it: brackets off an IPv6 literal; "[::]" and "0.0.0.0" are the
  // wildcard addresses, bound as such.
  std::string host = address.substr(0, address.rfind(':'));
  if (absl::StartsWith(host, "[")) host = host.substr(1, host.size() - 2);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* resolved = nullptr;
  if (getaddrinfo(host.c_str(), std::to_string(*port).c_str(), &hints, &resolved) != 0) {
    return absl::OkStatus();
  }
  int first_error = 0;
  bool bound = false;
  for (const addrinfo* a = resolved; a != nullptr && !bound; a = a->ai_next) {
    const int fd = socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;  // e.g. no IPv6 on this machine: gRPC skips it too
    const int on = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof(on));
    if (bind(fd, a->ai_addr, a->ai_addrlen) == 0) {
      bound = true;
    } else if (first_error == 0 || errno == EADDRINUSE) {
      first_error = errno;  // "in use" says more than another address's refusal
    }
    close(fd);
  }
  freeaddrinfo(resolved);
  if (bound || first_error == 0) return absl::OkStatus();
  const std::string reason = first_error == EADDRINUSE
                                 ? "the port is in use (is another server listening there?)"
                             : first_error == EADDRNOTAVAIL ? "it is not an address of this machine"
                                                            : std::strerror(first_error);
  return absl::UnavailableError(
      absl::StrCat("address: cannot listen on ", QuoteClientString(address), ": ", reason));
}

}  // namespace splinegrid::server
