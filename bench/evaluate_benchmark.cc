// Evaluation throughput by sum factorisation (GridEvaluator) of a fixed control net at
// growing output resolutions spanning >= 100x; items_per_second = output points per second.
// The output array is allocated once and written in full each iteration. BM_EvaluateDistribution:
// the same surface with a distribution on demand (block_sampling.h), placing and evaluating the
// points, beside the original clustering by GridEvaluator in the same run.
#include <cmath>

#include "bench/grid_samples.h"
#include "benchmark/benchmark.h"
#include "core/bspline/block_sampling.h"
#include "core/bspline/evaluation.h"
#include "core/fit/solve/tensor_fit.h"

namespace splinegrid::bench {
namespace {

// A fitted spline with `controls` control points per active direction.
TensorSpline SampleSpline(const Extents& controls) {
  Extents points;
  FitOptions options;
  for (int d = 0; d < 3; ++d) {
    points[d] = controls[d] > 1 ? 2 * controls[d] : 1;
    options.control_counts[d] = controls[d] > 1 ? controls[d] : 0;
  }
  return FitBlock(CurvilinearBlock(points), options).value().spline;
}

void RunEvaluate(benchmark::State& state, const Extents& controls, const Extents& out) {
  const TensorSpline spline = SampleSpline(controls);
  std::array<std::vector<double>, 3> params;
  for (int d = 0; d < 3; ++d) {
    params[d].resize(out[d]);
    for (int i = 0; i < out[d]; ++i) params[d][i] = out[d] > 1 ? double(i) / (out[d] - 1) : 0.0;
  }
  std::vector<double> points(3 * NumPoints(out));
  for (auto _ : state) {
    GridEvaluator evaluator(spline, params, /*first_derivatives=*/false);
    evaluator.EvaluateLines(0, evaluator.num_lines(), points.data());
    benchmark::DoNotOptimize(points.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * NumPoints(out));
  state.SetBytesProcessed(state.iterations() * NumPoints(out) * 3 * sizeof(double));
}

void BM_EvaluateCurve(benchmark::State& state) {
  RunEvaluate(state, {24, 1, 1}, {static_cast<int>(state.range(0)), 1, 1});
}
BENCHMARK(BM_EvaluateCurve)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMicrosecond);

void BM_EvaluateSurface(benchmark::State& state) {
  const int n = static_cast<int>(std::lround(std::sqrt(double(state.range(0)))));
  RunEvaluate(state, {24, 24, 1}, {n, n, 1});
}
BENCHMARK(BM_EvaluateSurface)
    ->Arg(64 * 64)
    ->Arg(200 * 200)
    ->Arg(640 * 640)
    ->Arg(2048 * 2048)
    ->Unit(benchmark::kMicrosecond);

void BM_EvaluateVolume(benchmark::State& state) {
  const int n = static_cast<int>(std::lround(std::cbrt(double(state.range(0)))));
  RunEvaluate(state, {24, 24, 24}, {n, n, n});
}
BENCHMARK(BM_EvaluateVolume)
    ->Arg(32 * 32 * 32)
    ->Arg(64 * 64 * 64)
    ->Arg(128 * 128 * 128)
    ->Arg(160 * 160 * 160)
    ->Arg(256 * 256 * 256)
    ->Unit(benchmark::kMillisecond);

void BM_EvaluateVolumeWithDerivatives(benchmark::State& state) {
  const int n = static_cast<int>(std::lround(std::cbrt(double(state.range(0)))));
  const TensorSpline spline = SampleSpline({24, 24, 24});
  std::array<std::vector<double>, 3> params;
  for (int d = 0; d < 3; ++d) {
    params[d].resize(n);
    for (int i = 0; i < n; ++i) params[d][i] = double(i) / (n - 1);
  }
  const size_t size = 3 * NumPoints({n, n, n});
  std::vector<double> p(size), du(size), dv(size), dw(size);
  for (auto _ : state) {
    GridEvaluator evaluator(spline, params, /*first_derivatives=*/true);
    evaluator.EvaluateLines(0, evaluator.num_lines(), p.data(), du.data(), dv.data(), dw.data());
    benchmark::DoNotOptimize(p.data());
  }
  state.SetItemsProcessed(state.iterations() * NumPoints({n, n, n}));
}
BENCHMARK(BM_EvaluateVolumeWithDerivatives)
    ->Arg(64 * 64 * 64)
    ->Arg(128 * 128 * 128)
    ->Unit(benchmark::kMillisecond);

// Arg: 0 the original clustering (tensor grid, GridEvaluator), 1 geometric in j from a first
// spacing of 1e-4 (the surface spans about 2 x 3), 2 uniform arc length in i; 640 x 640 points
// of a 24 x 24 control net.
void BM_EvaluateDistribution(benchmark::State& state) {
  const TensorSpline spline = SampleSpline({24, 24, 1});
  std::array<std::vector<double>, 3> data = {
      std::vector<double>(48), std::vector<double>(48), {0.0}};
  for (int i = 0; i < 48; ++i) data[0][i] = data[1][i] = i / 47.0;
  const PointDistribution distribution = PointDistribution::Create(data).value();
  Resolution resolution;
  resolution.kind = Resolution::Kind::kCounts;
  resolution.counts = {640, 640, 1};
  if (state.range(0) == 1) resolution.distributions[1] = {Distribution::Kind::kGeometric, 1e-4};
  if (state.range(0) == 2) resolution.distributions[0] = {Distribution::Kind::kUniformArcLength};
  std::vector<double> points(3 * NumPoints(resolution.counts));
  for (auto _ : state) {
    const BlockSampling sampling = BlockSampling::Create(spline, distribution, resolution).value();
    if (sampling.measured_direction() < 0) {
      GridEvaluator evaluator(spline, sampling.params(), /*first_derivatives=*/false);
      evaluator.EvaluateLines(0, evaluator.num_lines(), points.data());
    } else {
      EvaluateSampledPoints(spline, sampling, 0, NumPoints(sampling.extents()), points.data());
    }
    benchmark::DoNotOptimize(points.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * NumPoints(resolution.counts));
}
BENCHMARK(BM_EvaluateDistribution)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace splinegrid::bench
