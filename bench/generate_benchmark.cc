// Grid generation around a profile (core/generate/profile_grid.h), from the coordinates file:
//   BM_GenerateOGrid/<airfoil>/<method>   GenerateProfileGrid at 257 x 129 points (first layer
//                                         1e-5 chords, far field 50 chords): the whole chain,
//                                         outline fit, wall loop, layers and the quality
//                                         measurement, with each stage's milliseconds
//                                         (method 2, elliptic: also its sweeps per level)
//   BM_EllipticCoarseToFine/<airfoil>/<tolerance>
//                                         the elliptic smoothing of the 257 x 129 O-grid: the
//                                         coarse level (129 x 65) from transfinite, the fine
//                                         level from the coarse spline, and the fine level from
//                                         its own transfinite grid, with each one's sweeps and
//                                         milliseconds and fine_ratio = plain sweeps / the
//                                         multigrid's fine work units;
//                                         tolerance 1e-2, 1e-3 (the default) or 1e-4 of the
//                                         local spacing per sweep
//   BM_TrackingControls/<airfoil>       the control functions of the 257 x 129 algebraic grid
//                                         (elliptic.h TrackingControls: psi by a safeguarded
//                                         Newton iteration per point); beside it, in the same
//                                         run, the baseline: one relaxation sweep of the same
//                                         grid, and sweeps = controls / sweep
//   BM_GenerateVolume/layers:<n>         the shared ONERA M6 wing's 9 surface blocks (16,001
//                                         points) marched outward to 5 with a first layer of
//                                         1e-4 (core/generate/surface_offset.h); beside it, in
//                                         the same run, the baseline: one interpolating fit of
//                                         every surface block (what each layer does once, plus
//                                         derivatives and smoothing), and ratio = march /
//                                         (layers x baseline)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <string>

#include "benchmark/benchmark.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/generate/cove_completion.h"
#include "core/generate/elliptic.h"
#include "core/generate/profile_grid.h"
#include "core/generate/surface_offset.h"
#include "core/generate/transfinite.h"
#include "core/io/airfoil.h"
#include "core/io/plot3d.h"
#include "tests/core/test_data.h"

namespace splinegrid::bench {
namespace {

constexpr const char* kAirfoils[] = {"naca0012", "rae2822", "sc20714"};

std::string AirfoilPath(const std::string& name) {
  return SharedDataPath("airfoils/" + name + ".dat");
}

void BM_GenerateOGrid(benchmark::State& state) {
  const std::string name = kAirfoils[state.range(0)];
  absl::StatusOr<AirfoilCoordinates> coordinates = ReadAirfoilFile(AirfoilPath(name));
  if (!coordinates.ok()) return state.SkipWithError(coordinates.status().ToString().c_str());
  ProfileGridOptions options;  // 257 x 129, first 1e-5, far 50
  constexpr LayerMethod kMethods[] = {LayerMethod::kOffsets, LayerMethod::kTransfinite,
                                      LayerMethod::kElliptic};
  options.method = kMethods[state.range(1)];
  ProfileGrid grid;
  for (auto _ : state) {
    absl::StatusOr<ProfileGrid> generated = GenerateProfileGrid(coordinates->points, options);
    if (!generated.ok()) return state.SkipWithError(generated.status().ToString().c_str());
    grid = *std::move(generated);
  }
  state.SetLabel(name + " " + std::string(LayerMethodName(options.method)));
  state.counters["points"] = static_cast<double>(grid.block.num_points());
  state.counters["fit_ms"] = grid.fit_seconds * 1e3;
  state.counters["wall_ms"] = grid.wall_seconds * 1e3;
  state.counters["layers_ms"] = grid.layer_seconds * 1e3;
  state.counters["measure_ms"] = grid.measure_seconds * 1e3;
  state.counters["negative_cells"] = static_cast<double>(grid.quality.negative_cells);
  state.counters["orthogonality_deg"] = grid.quality.wall_orthogonality_degrees;
  if (options.method == LayerMethod::kElliptic) {
    state.counters["coarse_sweeps"] = grid.coarse_sweeps;
    state.counters["fine_sweeps"] = grid.fine_sweeps;
  }
}
BENCHMARK(BM_GenerateOGrid)
    ->ArgsProduct({{0, 1, 2}, {0, 1, 2}})
    ->ArgNames({"airfoil", "method"})
    ->Unit(benchmark::kMillisecond);

void BM_EllipticCoarseToFine(benchmark::State& state) {
  const std::string name = kAirfoils[state.range(0)];
  absl::StatusOr<AirfoilCoordinates> coordinates = ReadAirfoilFile(AirfoilPath(name));
  if (!coordinates.ok()) return state.SkipWithError(coordinates.status().ToString().c_str());
  ProfileGridOptions options;  // the wall loop of the 257-point grid
  options.method = LayerMethod::kTransfinite;
  options.layers = 2;
  absl::StatusOr<ProfileGrid> outline = GenerateProfileGrid(coordinates->points, options);
  if (!outline.ok()) return state.SkipWithError(outline.status().ToString().c_str());
  EllipticOptions elliptic;
  elliptic.tolerance = std::pow(10.0, -static_cast<double>(state.range(1)));
  const CompletionOptions completion;  // 128 layers, 1e-5, 50 chords
  absl::StatusOr<AlgebraicGrid> algebraic =
      AlgebraicOGrid(outline->wall, OuterSpacing::kEven, completion, nullptr);
  if (!algebraic.ok()) return state.SkipWithError(algebraic.status().ToString().c_str());
  const int held = HeldLayers(completion, *algebraic, /*chord=*/1.0);
  CoarseToFine run;
  for (auto _ : state) {
    absl::StatusOr<CoarseToFine> smoothed =
        SmoothCoarseToFine(algebraic->block, held, elliptic, /*compare=*/true);
    if (!smoothed.ok()) return state.SkipWithError(smoothed.status().ToString().c_str());
    run = *std::move(smoothed);
  }
  state.SetLabel(name);
  state.counters["coarse_sweeps"] = run.coarse.sweeps;
  state.counters["coarse_ms"] = run.coarse.seconds * 1e3;
  state.counters["fine_sweeps"] = run.fine.sweeps;
  // Fine-level work units: fine sweeps plus the coarse level's sweeps in the cycles, a quarter
  // each.
  const double work = run.fine.sweeps + run.fine.coarse_work;
  state.counters["fine_work"] = work;
  state.counters["fine_ms"] = run.fine.seconds * 1e3;
  state.counters["plain_sweeps"] = run.fine_from_transfinite.sweeps;
  state.counters["plain_ms"] = run.fine_from_transfinite.seconds * 1e3;
  state.counters["fine_ratio"] = run.fine_from_transfinite.sweeps / std::max(1.0, work);
}
BENCHMARK(BM_EllipticCoarseToFine)
    ->ArgsProduct({{0, 1, 2}, {2, 3, 4}})
    ->ArgNames({"airfoil", "tolerance_exp"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

void BM_TrackingControls(benchmark::State& state) {
  const std::string name = kAirfoils[state.range(0)];
  absl::StatusOr<AirfoilCoordinates> coordinates = ReadAirfoilFile(AirfoilPath(name));
  if (!coordinates.ok()) return state.SkipWithError(coordinates.status().ToString().c_str());
  ProfileGridOptions options;  // 257 x 129, first 1e-5, far 50
  options.method = LayerMethod::kTransfinite;
  absl::StatusOr<ProfileGrid> grid = GenerateProfileGrid(coordinates->points, options);
  if (!grid.ok()) return state.SkipWithError(grid.status().ToString().c_str());
  const StructuredBlock& algebraic = grid->block;
  ControlFunctions control;
  double controls = 1e300;  // the fastest iteration's seconds
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    absl::StatusOr<ControlFunctions> computed = TrackingControls(algebraic, 0);
    controls = std::min(
        controls, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (!computed.ok()) return state.SkipWithError(computed.status().ToString().c_str());
    control = *std::move(computed);
  }
  // The baseline: one sweep of the line relaxation on the same grid, the best of five.
  EllipticOptions one;
  one.max_sweeps = 1;
  double sweep = 1e300;
  for (int k = 0; k < 5; ++k) {
    absl::StatusOr<EllipticResult> relaxed = SmoothElliptic(algebraic, control, 1, one);
    if (!relaxed.ok()) return state.SkipWithError(relaxed.status().ToString().c_str());
    sweep = std::min(sweep, relaxed->seconds);
  }
  state.SetLabel(name);
  state.counters["points"] = static_cast<double>(algebraic.num_points());
  state.counters["controls_ms"] = controls * 1e3;
  state.counters["sweep_ms"] = sweep * 1e3;
  state.counters["sweeps"] = controls / sweep;
  state.counters["us_per_point"] = controls * 1e6 / static_cast<double>(algebraic.num_points());
}
BENCHMARK(BM_TrackingControls)
    ->DenseRange(0, 2)
    ->ArgName("airfoil")
    ->Unit(benchmark::kMillisecond);

void BM_GenerateVolume(benchmark::State& state) {
  absl::StatusOr<MultiBlockGrid> m6 = ReadPlot3dFile(SharedDataPath("surfaces/m6_small.fmt"));
  if (!m6.ok()) return state.SkipWithError(m6.status().ToString().c_str());
  absl::StatusOr<Connectivity> connectivity = FindConnectivity(*m6);
  if (!connectivity.ok()) return state.SkipWithError(connectivity.status().ToString().c_str());
  SurfaceOffsetOptions options;
  options.layers = static_cast<int>(state.range(0));
  options.first_height = 1e-4;
  options.distance = 5.0;
  options.outward = true;
  SurfaceOffsetGrid grid;
  double march_ms = 0.0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    absl::StatusOr<SurfaceOffsetGrid> marched = OffsetSurfaceGrid(*m6, *connectivity, options);
    march_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (!marched.ok()) return state.SkipWithError(marched.status().ToString().c_str());
    grid = *std::move(marched);
  }
  march_ms /= static_cast<double>(state.iterations());
  // The baseline, timed here: one interpolating fit of every surface block.
  constexpr int kBaselineRuns = 5;
  const auto start = std::chrono::steady_clock::now();
  for (int run = 0; run < kBaselineRuns; ++run) {
    for (const StructuredBlock& block : m6->blocks) {
      benchmark::DoNotOptimize(FitBlock(block, FitOptions{}));
    }
  }
  const double baseline_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() /
      kBaselineRuns;
  int64_t points = 0;
  for (const StructuredBlock& block : grid.blocks) points += block.num_points();
  state.counters["points"] = static_cast<double>(points);
  state.counters["surface_fit_ms"] = baseline_ms;
  state.counters["ratio"] = march_ms / (options.layers * baseline_ms);
  state.counters["min_scaled_jacobian"] = grid.min_scaled_jacobian;
  state.counters["retries"] = grid.retries;
  state.SetLabel("m6 to 5, first 1e-4");
}
BENCHMARK(BM_GenerateVolume)
    ->Arg(16)
    ->Arg(32)
    ->Arg(64)
    ->ArgName("layers")
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);

}  // namespace
}  // namespace splinegrid::bench
