// CallMetrics (server/call_metrics.h) and the label escaping of metrics_text.h: bucket edges are
// inclusive (Prometheus' `le`), buckets are cumulative, unknown methods count as "other".
#include "server/call_metrics.h"

#include <string>

#include "absl/strings/str_cat.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/metrics_text.h"

namespace splinegrid::server {
namespace {

using ::testing::HasSubstr;

// The value of the line starting with `prefix` in `text`, or -1.
double LineValue(const std::string& text, const std::string& prefix) {
  const size_t at = text.find("\n" + prefix);
  if (at == std::string::npos) return -1;
  const size_t start = at + 1 + prefix.size();
  return std::stod(text.substr(start, text.find('\n', start) - start));
}

TEST(CallMetrics, CountsByMethodAndCodeWithInclusiveCumulativeBuckets) {
  CallMetrics& metrics = CallMetrics::Global();  // per process: compare before and after
  std::string before;
  metrics.AppendText(&before);
  const uint64_t ok = metrics.calls("WatchGrid", absl::StatusCode::kOk);
  metrics.Record("WatchGrid", absl::StatusCode::kOk, absl::Milliseconds(1));  // le="0.001"
  metrics.Record("WatchGrid", absl::StatusCode::kOk, absl::Milliseconds(3));  // le="0.005"
  metrics.Record("WatchGrid", absl::StatusCode::kNotFound, absl::Seconds(400));  // +Inf only
  metrics.Record("NoSuchMethod", absl::StatusCode::kInternal, absl::Microseconds(1));
  std::string after;
  metrics.AppendText(&after);
  EXPECT_EQ(metrics.calls("WatchGrid", absl::StatusCode::kOk), ok + 2);
  const auto delta = [&](const std::string& prefix) {
    return LineValue(after, prefix) - std::max(0.0, LineValue(before, prefix));
  };
  const std::string bucket = R"(splinegrid_call_duration_seconds_bucket{method="WatchGrid",le=)";
  EXPECT_EQ(delta(bucket + R"("0.0005"} )"), 0);
  EXPECT_EQ(delta(bucket + R"("0.001"} )"), 1);
  EXPECT_EQ(delta(bucket + R"("0.0025"} )"), 1);
  EXPECT_EQ(delta(bucket + R"("0.005"} )"), 2);
  EXPECT_EQ(delta(bucket + R"("300"} )"), 2);
  EXPECT_EQ(delta(bucket + R"("+Inf"} )"), 3);
  EXPECT_EQ(delta(R"(splinegrid_call_duration_seconds_count{method="WatchGrid"} )"), 3);
  EXPECT_NEAR(delta(R"(splinegrid_call_duration_seconds_sum{method="WatchGrid"} )"), 400.004,
              1e-6);
  EXPECT_EQ(delta(R"(splinegrid_calls_total{method="WatchGrid",code="NOT_FOUND"} )"), 1);
  EXPECT_GE(LineValue(after, R"(splinegrid_calls_total{method="other",code="INTERNAL"} )"), 1);
}

TEST(MetricsText, EscapesLabelValues) {
  EXPECT_EQ(EscapeLabelValue("alice"), "alice");
  EXPECT_EQ(EscapeLabelValue("a\"b\\c\nd"), "a\\\"b\\\\c\\nd");
}

}  // namespace
}  // namespace splinegrid::server
