// The Prometheus text exposition (format 0.0.4) of a running server: the call counters and
// latency histograms (call_metrics.h) and gauges read at scrape time from the service state.
//
//   splinegrid_calls_total{method,code}               counter
//   splinegrid_call_duration_seconds{method}          histogram (_bucket{le}, _sum, _count)
//   splinegrid_grids, splinegrid_revisions            gauges: held by the store
//   splinegrid_memory_budget_used_bytes / _limit_bytes  gauges: server/memory_budget.h
//   splinegrid_scheduler_queued_tasks{kind}           gauge: cheap / long tasks waiting
//   splinegrid_scheduler_queued_long_tasks{principal} gauge: long tasks waiting per caller
//                                                     (only with a tokens file: bounded names)
//   splinegrid_open_streams                           gauge: streaming calls open
//   splinegrid_draining                               gauge: 1 once shutdown began
//   process_resident_memory_bytes                     gauge: from /proc/self/statm
// Scrape cost: the store's List over every grid (a page of 1000 at a time; with --store redis
// that reads the shared store), the scheduler's and stream limits' locks once each.
#ifndef SPLINEGRID_SERVER_METRICS_TEXT_H_
#define SPLINEGRID_SERVER_METRICS_TEXT_H_

#include <string>

#include "absl/strings/string_view.h"
#include "server/service.h"

namespace splinegrid::server {

// The whole exposition, ending with a newline.
std::string MetricsText(const ServiceState& state);

// `value` as the inside of a quoted label value: backslash, double quote and newline escaped
// (the text format's rule).
std::string EscapeLabelValue(absl::string_view value);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_METRICS_TEXT_H_
