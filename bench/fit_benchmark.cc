// Fit throughput of the tensor least-squares fit (FitBlock: parametrisation, knots, banded QR
// passes and the deviation at every data point), over sizes spanning >= 100x in points.
// items_per_second = data points per second; the compression per direction is fixed (~5.3x,
// 128 -> 24 points) so that cost per point is comparable across sizes.
#include <cmath>

#include "Eigen/Dense"
#include "bench/grid_samples.h"
#include "bench/peak_memory.h"
#include "benchmark/benchmark.h"
#include "core/bspline/basis.h"
#include "core/fit/tensor_fit.h"

namespace splinegrid::bench {
namespace {

int Controls(int points) { return std::max(4, static_cast<int>(std::lround(points * 24.0 / 128))); }

void RunFit(benchmark::State& state, const Extents& points) {
  const StructuredBlock block = CurvilinearBlock(points);
  FitOptions options;
  for (int d = 0; d < 3; ++d) options.control_counts[d] = points[d] > 1 ? Controls(points[d]) : 0;
  double max_deviation = 0.0;
  for (auto _ : state) {
    absl::StatusOr<FittedBlock> fitted = FitBlock(block, options);
    if (!fitted.ok()) {
      state.SkipWithError(std::string(fitted.status().message()).c_str());
      return;
    }
    max_deviation = fitted->summary.deviation.max;
    benchmark::DoNotOptimize(fitted->spline.control().data());
  }
  state.SetItemsProcessed(state.iterations() * block.num_points());
  state.counters["max_deviation"] = max_deviation;
  const double input_bytes = static_cast<double>(block.coords().size() * sizeof(double));
  const int64_t extra = PeakExtraBytes([&] { benchmark::DoNotOptimize(FitBlock(block, options)); });
  if (extra >= 0) state.counters["peak_extra_over_input"] = extra / input_bytes;
}

void BM_FitCurve(benchmark::State& state) {
  RunFit(state, {static_cast<int>(state.range(0)), 1, 1});
}
BENCHMARK(BM_FitCurve)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMicrosecond);

void BM_FitSurface(benchmark::State& state) {
  const int n = static_cast<int>(std::lround(std::sqrt(double(state.range(0)))));
  RunFit(state, {n, n, 1});
}
BENCHMARK(BM_FitSurface)
    ->Arg(32 * 32)
    ->Arg(100 * 100)
    ->Arg(320 * 320)
    ->Arg(1024 * 1024)
    ->Unit(benchmark::kMicrosecond);

void BM_FitVolume(benchmark::State& state) {
  const int n = static_cast<int>(std::lround(std::cbrt(double(state.range(0)))));
  RunFit(state, {n, n, n});
}
BENCHMARK(BM_FitVolume)
    ->Arg(27 * 27 * 27)
    ->Arg(48 * 48 * 48)
    ->Arg(80 * 80 * 80)
    ->Arg(128 * 128 * 128)
    ->Unit(benchmark::kMillisecond);

// The least-squares solve alone (FitTensor with the parametrisation and knots precomputed): the
// three banded-QR passes, which is what SciPy's make_lsq_spline applied direction by direction
// computes (there via normal equations).
void BM_FitVolumeSolve(benchmark::State& state) {
  const int n = static_cast<int>(std::lround(std::cbrt(double(state.range(0)))));
  const StructuredBlock block = CurvilinearBlock({n, n, n});
  const auto params = ParametrizeBlock(block, Parametrization::kChordLength);
  std::array<KnotVector, 3> knots;
  for (int d = 0; d < 3; ++d) knots[d] = KnotVector::Averaged(4, Controls(n), params[d]).value();
  for (auto _ : state) {
    absl::StatusOr<TensorSpline> spline =
        FitTensor(block, params, knots, EndCondition::kInterpolate);
    benchmark::DoNotOptimize(spline->control().data());
  }
  state.SetItemsProcessed(state.iterations() * block.num_points());
}
BENCHMARK(BM_FitVolumeSolve)
    ->Arg(27 * 27 * 27)
    ->Arg(48 * 48 * 48)
    ->Arg(80 * 80 * 80)
    ->Arg(128 * 128 * 128)
    ->Unit(benchmark::kMillisecond);

// For contrast: the same surface fit as one dense least-squares problem on the Kronecker
// matrix (what the separable banded method avoids). Cost grows like points * controls^2.
void BM_FitSurfaceDenseReference(benchmark::State& state) {
  const int n = static_cast<int>(std::lround(std::sqrt(double(state.range(0)))));
  const StructuredBlock block = CurvilinearBlock({n, n, 1});
  const int c = Controls(n);
  std::vector<double> u(n);
  for (int i = 0; i < n; ++i) u[i] = double(i) / (n - 1);
  const KnotVector kv = KnotVector::Averaged(4, c, u).value();
  const SampledBasis b = SampleBasis(kv, u);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, c);
  for (int q = 0; q < n; ++q)
    for (int t = 0; t < 4; ++t) a(q, b.first[q] + t) = b.Row(q)[t];
  Eigen::MatrixXd rhs(n * n, 3);
  for (int p = 0; p < n * n; ++p)
    for (int x = 0; x < 3; ++x) rhs(p, x) = block.coords()[3 * p + x];
  for (auto _ : state) {
    Eigen::MatrixXd kron(n * n, c * c);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (int y = 0; y < c; ++y)
          for (int x = 0; x < c; ++x) kron(i + n * j, x + c * y) = a(i, x) * a(j, y);
    Eigen::MatrixXd p = kron.householderQr().solve(rhs);
    benchmark::DoNotOptimize(p.data());
  }
  state.SetItemsProcessed(state.iterations() * n * n);
}
BENCHMARK(BM_FitSurfaceDenseReference)
    ->Arg(32 * 32)
    ->Arg(64 * 64)
    ->Arg(100 * 100)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace splinegrid::bench
