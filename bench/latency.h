// Latency figures of the service benchmarks: elapsed time and percentiles of samples.
#ifndef SPLINEGRID_BENCH_LATENCY_H_
#define SPLINEGRID_BENCH_LATENCY_H_

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <vector>

namespace splinegrid::bench {

// Microseconds from `start` to now.
inline double MicrosecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
      .count();
}

// The q-quantile (0 < q <= 1) of `values` by the nearest-rank method: the smallest value with
// at least q of the values at or below it; 0 for no values.
inline double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t rank = static_cast<size_t>(std::ceil(q * values.size()));
  return values[std::clamp<size_t>(rank, 1, values.size()) - 1];
}

}  // namespace splinegrid::bench

#endif  // SPLINEGRID_BENCH_LATENCY_H_
