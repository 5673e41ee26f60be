#include "server/call_metrics.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "google/protobuf/descriptor.h"

namespace splinegrid::server {
namespace {

// The methods of the service as the generated code knows them.
std::vector<std::string> ServiceMethods() {
  std::vector<std::string> methods;
  const google::protobuf::ServiceDescriptor* service =
      google::protobuf::DescriptorPool::generated_pool()->FindServiceByName(
          "splinegrid.v1.SplineGrid");
  if (service == nullptr) return methods;  // the proto library is not linked in
  for (int i = 0; i < service->method_count(); ++i) methods.push_back(service->method(i)->name());
  std::sort(methods.begin(), methods.end());
  return methods;
}

// The Prometheus text form of a bucket bound: shortest decimal ("0.0001", "2.5", "300").
std::string Bound(double bound) { return absl::StrFormat("%g", bound); }

// The row index of `code` (absl::StatusCode 0..16, OK to UNAUTHENTICATED); any other value
// counts as UNKNOWN.
int CodeIndex(absl::StatusCode code) {
  constexpr int kCanonical = static_cast<int>(absl::StatusCode::kUnauthenticated) + 1;
  const int c = static_cast<int>(code);
  return c >= 0 && c < kCanonical ? c : static_cast<int>(absl::StatusCode::kUnknown);
}

}  // namespace

CallMetrics& CallMetrics::Global() {
  static CallMetrics* const metrics = new CallMetrics(ServiceMethods());
  return *metrics;
}

CallMetrics::CallMetrics(const std::vector<std::string>& methods) {
  for (const std::string& method : methods) {
    rows_.push_back(std::make_unique<Row>());
    rows_.back()->method = method;
    by_method_[method] = rows_.back().get();
  }
  rows_.push_back(std::make_unique<Row>());
  rows_.back()->method = "other";
}

CallMetrics::Row* CallMetrics::Find(absl::string_view method) const {
  const auto it = by_method_.find(method);
  return it == by_method_.end() ? rows_.back().get() : it->second;
}

void CallMetrics::Record(absl::string_view method, absl::StatusCode code,
                         absl::Duration latency) {
  static_assert(kCodes == static_cast<int>(absl::StatusCode::kUnauthenticated) + 1);
  Row& row = *Find(method);
  row.calls[CodeIndex(code)].fetch_add(1, std::memory_order_relaxed);
  const double seconds = absl::ToDoubleSeconds(latency);
  const size_t bucket =
      std::lower_bound(kBucketBounds.begin(), kBucketBounds.end(), seconds) -
      kBucketBounds.begin();  // first bound >= seconds (le is inclusive); size(): +Inf
  row.buckets[bucket].fetch_add(1, std::memory_order_relaxed);
  row.sum_nanos.fetch_add(static_cast<uint64_t>(std::max<int64_t>(0, absl::ToInt64Nanoseconds(
                                                                         latency))),
                          std::memory_order_relaxed);
}

uint64_t CallMetrics::calls(absl::string_view method, absl::StatusCode code) const {
  return Find(method)->calls[CodeIndex(code)].load(std::memory_order_relaxed);
}

void CallMetrics::AppendText(std::string* out) const {
  absl::StrAppend(out,
                  "# HELP splinegrid_calls_total Calls finished, by method and status code.\n"
                  "# TYPE splinegrid_calls_total counter\n");
  for (const auto& row : rows_) {
    for (int c = 0; c < kCodes; ++c) {
      const uint64_t n = row->calls[c].load(std::memory_order_relaxed);
      if (n == 0 && c != 0) continue;
      absl::StrAppend(out, "splinegrid_calls_total{method=\"", row->method, "\",code=\"",
                      absl::StatusCodeToString(static_cast<absl::StatusCode>(c)), "\"} ", n,
                      "\n");
    }
  }
  absl::StrAppend(out,
                  "# HELP splinegrid_call_duration_seconds Time from a call's arrival to its "
                  "status, by method.\n"
                  "# TYPE splinegrid_call_duration_seconds histogram\n");
  for (const auto& row : rows_) {
    uint64_t cumulative = 0;
    for (size_t b = 0; b < row->buckets.size(); ++b) {
      cumulative += row->buckets[b].load(std::memory_order_relaxed);
      absl::StrAppend(out, "splinegrid_call_duration_seconds_bucket{method=\"", row->method,
                      "\",le=\"", b < kBucketBounds.size() ? Bound(kBucketBounds[b]) : "+Inf",
                      "\"} ", cumulative, "\n");
    }
    absl::StrAppend(
        out, "splinegrid_call_duration_seconds_sum{method=\"", row->method, "\"} ",
        absl::StrFormat("%.9g", row->sum_nanos.load(std::memory_order_relaxed) * 1e-9), "\n",
        "splinegrid_call_duration_seconds_count{method=\"", row->method, "\"} ", cumulative,
        "\n");
  }
}

}  // namespace splinegrid::server
