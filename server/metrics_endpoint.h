// The HTTP endpoint of `serve --metrics_address HOST:PORT`: GET /metrics answers the Prometheus
// text exposition (metrics_text.h); any other path is 404, any other method 405. Served by
// libmicrohttpd on one internal thread of its own, so that a scrape never takes a gRPC thread
// or a worker.
//
// Transport: plaintext HTTP without authentication. The counters name methods, status codes
// and (for queued long work) principals, not grid data, but they are still the server's
// business: like the gRPC port's rule (--insecure), a HOST that is not loopback is refused
// unless `insecure` (serve --metrics_insecure) says that the network is trusted (a pod network,
// a scrape-only VLAN). For scrapes across an untrusted network, put a TLS proxy in front of a
// loopback endpoint.
#ifndef SPLINEGRID_SERVER_METRICS_ENDPOINT_H_
#define SPLINEGRID_SERVER_METRICS_ENDPOINT_H_

#include <functional>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

struct MHD_Daemon;

namespace splinegrid::server {

// INVALID_ARGUMENT, naming --metrics_address and its value, unless `address` is HOST:PORT or
// [IPV6]:PORT (port 0: any free one) and loopback or `insecure`.
absl::Status CheckMetricsAddress(absl::string_view address, bool insecure);

class MetricsEndpoint {
 public:
  // Renders the body of one scrape; called on the endpoint's thread.
  using Render = std::function<std::string()>;

  // Listens on `address` (checked by CheckMetricsAddress). UNAVAILABLE when it cannot be bound.
  static absl::StatusOr<std::unique_ptr<MetricsEndpoint>> Start(absl::string_view address,
                                                                bool insecure, Render render);
  // Stops listening and joins the thread (a scrape in progress finishes first).
  ~MetricsEndpoint();
  MetricsEndpoint(const MetricsEndpoint&) = delete;
  MetricsEndpoint& operator=(const MetricsEndpoint&) = delete;

  // The bound port (useful with port 0).
  int port() const { return port_; }

  // Answers one request (libmicrohttpd's access handler calls it).
  const Render& render() const { return render_; }

 private:
  explicit MetricsEndpoint(Render render) : render_(std::move(render)) {}

  Render render_;
  MHD_Daemon* daemon_ = nullptr;
  int port_ = 0;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_METRICS_ENDPOINT_H_
