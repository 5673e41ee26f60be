// Counters of finished calls for the Prometheus endpoint (metrics_endpoint.h): calls by method
// and status code, and a latency histogram per method. Recorded once per call where the call
// log line is written (CallLog::Finish), so that the log and the metrics count the same calls.
//
// Cost on the call path: a lookup of the method in a hash map that is read-only after
// construction, then relaxed atomic increments (a calls counter, a histogram bucket, the sum);
// no lock, no allocation. The counters are per process (Prometheus' model: one target per
// process), shared by every Server the process runs.
#ifndef SPLINEGRID_SERVER_CALL_METRICS_H_
#define SPLINEGRID_SERVER_CALL_METRICS_H_

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "absl/time/time.h"

namespace splinegrid::server {

class CallMetrics {
 public:
  // Upper bounds (seconds) of the latency buckets: from 100 us (EvaluatePoints, GetGrid) to
  // 5 min (fits of large grids); +Inf is implicit.
  static constexpr std::array<double, 18> kBucketBounds = {
      0.0001, 0.00025, 0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05,
      0.1,    0.25,    0.5,    1,     2.5,    5,     10,   60,    300};

  // The process's counters, with a row for every method of splinegrid.v1.SplineGrid and one
  // named "other" for anything else.
  static CallMetrics& Global();

  // A call of `method` ended with `code` after `latency`. Thread-safe, lock-free.
  void Record(absl::string_view method, absl::StatusCode code, absl::Duration latency);

  // Appends splinegrid_calls_total and splinegrid_call_duration_seconds in the Prometheus text
  // format (version 0.0.4) to `out`: every method's OK count (zero included, so rates start at
  // once) and the other codes that occurred; every method's histogram.
  void AppendText(std::string* out) const;

  // Calls of `method` that ended with `code` so far (for tests).
  uint64_t calls(absl::string_view method, absl::StatusCode code) const;

 private:
  static constexpr int kCodes = 17;  // absl::StatusCode 0..16
  struct Row {
    std::string method;
    std::array<std::atomic<uint64_t>, kCodes> calls{};
    std::array<std::atomic<uint64_t>, kBucketBounds.size() + 1> buckets{};  // not cumulative
    std::atomic<uint64_t> sum_nanos{0};
  };

  explicit CallMetrics(const std::vector<std::string>& methods);
  // The row of `method`, or "other" (rows are shared: the counters are atomic).
  Row* Find(absl::string_view method) const;

  std::vector<std::unique_ptr<Row>> rows_;  // the last one is "other"
  absl::flat_hash_map<std::string, Row*> by_method_;  // read-only after construction
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_CALL_METRICS_H_
