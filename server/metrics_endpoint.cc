#include "server/metrics_endpoint.h"

#include <microhttpd.h>
#include <netdb.h>
#include <sys/socket.h>

#include <cstring>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/util/quote.h"
#include "server/auth/transport.h"
#include "server/listen_address.h"

namespace splinegrid::server {
namespace {

// The content type of the text exposition format 0.0.4.
constexpr char kContentType[] = "text/plain; version=0.0.4; charset=utf-8";

MHD_Result Reply(MHD_Connection* connection, unsigned status, const std::string& body,
                 const char* content_type) {
  MHD_Response* response = MHD_create_response_from_buffer(
      body.size(), const_cast<char*>(body.data()), MHD_RESPMEM_MUST_COPY);
  if (response == nullptr) return MHD_NO;
  MHD_add_response_header(response, MHD_HTTP_HEADER_CONTENT_TYPE, content_type);
  const MHD_Result result = MHD_queue_response(connection, status, response);
  MHD_destroy_response(response);
  return result;
}

// libmicrohttpd's access handler: GET /metrics, 404 and 405 otherwise. A request body is
// refused (405) before it is read.
MHD_Result Handle(void* endpoint, MHD_Connection* connection, const char* url, const char* method,
                  const char* /*version*/, const char* /*upload_data*/,
                  size_t* /*upload_data_size*/, void** /*request_state*/) {
  if (std::strcmp(method, MHD_HTTP_METHOD_GET) != 0 &&
      std::strcmp(method, MHD_HTTP_METHOD_HEAD) != 0) {
    return Reply(connection, MHD_HTTP_METHOD_NOT_ALLOWED, "only GET /metrics\n", "text/plain");
  }
  if (std::strcmp(url, "/metrics") != 0) {
    return Reply(connection, MHD_HTTP_NOT_FOUND, "not found: the metrics are at /metrics\n",
                 "text/plain");
  }
  const std::string body = static_cast<MetricsEndpoint*>(endpoint)->render()();
  return Reply(connection, MHD_HTTP_OK, body, kContentType);
}

// HOST and PORT of `address` (brackets of an IPv6 host removed).
std::pair<std::string, std::string> SplitHostPort(absl::string_view address) {
  const size_t colon = address.rfind(':');
  absl::string_view host = address.substr(0, colon);
  if (absl::StartsWith(host, "[") && absl::EndsWith(host, "]")) {
    host = host.substr(1, host.size() - 2);
  }
  return {std::string(host), std::string(address.substr(colon + 1))};
}

}  // namespace

absl::Status CheckMetricsAddress(absl::string_view address, bool insecure) {
  const absl::StatusOr<int> port = ParseListenPort(address, /*min_port=*/0);
  if (!port.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--metrics_address: ", port.status().message()));
  }
  if (*port < 0) {
    return absl::InvalidArgumentError(absl::StrCat("--metrics_address = ",
                                                   QuoteClientString(address),
                                                   ": give HOST:PORT (unix sockets: no)"));
  }
  if (!insecure && !IsLoopbackAddress(address)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--metrics_address = ", QuoteClientString(address),
        " is not a loopback address: /metrics is plaintext HTTP without authentication; give "
        "--metrics_insecure to serve it there anyway (a trusted network)"));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<MetricsEndpoint>> MetricsEndpoint::Start(absl::string_view address,
                                                                         bool insecure,
                                                                         Render render) {
  if (absl::Status status = CheckMetricsAddress(address, insecure); !status.ok()) return status;
  const auto [host, port] = SplitHostPort(address);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  if (const int error = getaddrinfo(host.c_str(), port.c_str(), &hints, &found); error != 0) {
    return absl::InvalidArgumentError(absl::StrCat("--metrics_address = ",
                                                   QuoteClientString(address),
                                                   ": cannot resolve the host: ",
                                                   gai_strerror(error)));
  }
  std::unique_ptr<MetricsEndpoint> endpoint(new MetricsEndpoint(std::move(render)));
  // AUTO picks epoll or poll: select() would refuse a scrape whose socket number is above
  // FD_SETSIZE (1024), which a busy server's connections reach.
  unsigned flags = MHD_USE_AUTO_INTERNAL_THREAD | MHD_USE_ERROR_LOG;
  if (found->ai_family == AF_INET6) flags |= MHD_USE_IPv6;
  endpoint->daemon_ = MHD_start_daemon(
      flags, /*port=*/0, /*apc=*/nullptr, nullptr, &Handle, endpoint.get(),
      MHD_OPTION_SOCK_ADDR, found->ai_addr,
      // Scrapes are small and rare: a few connections, and idle ones closed after 10 s.
      MHD_OPTION_CONNECTION_LIMIT, 16u, MHD_OPTION_CONNECTION_TIMEOUT, 10u, MHD_OPTION_END);
  freeaddrinfo(found);
  if (endpoint->daemon_ == nullptr) {
    return absl::UnavailableError(absl::StrCat("--metrics_address = ", QuoteClientString(address),
                                               ": cannot listen there (in use?)"));
  }
  const MHD_DaemonInfo* info = MHD_get_daemon_info(endpoint->daemon_, MHD_DAEMON_INFO_BIND_PORT);
  endpoint->port_ = info != nullptr ? info->port : 0;
  return endpoint;
}

MetricsEndpoint::~MetricsEndpoint() {
  if (daemon_ != nullptr) MHD_stop_daemon(daemon_);
}

}  // namespace splinegrid::server
