// The cell-quality check of a fitted volume block (CheckCellQuality, levels 0-2: 73 sub-cells per
// original cell), the step an adaptive volume fit repeats after every accepted change. Baseline
// in the same run: evaluating the level-2 points alone (GridEvaluator), which the check has to do
// and cannot be faster than. items_per_second = checked sub-cells per second (for the baseline:
// evaluated points).
#include <vector>

#include "bench/grid_samples.h"
#include "benchmark/benchmark.h"
#include "core/bspline/evaluation.h"
#include "core/fit/report/grid_quality.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/grid/sampling.h"

namespace splinegrid::bench {
namespace {

// A 65 x 49 x 33 curvilinear block (105,105 points, like an M6 volume block) and its fit with
// 24 x 20 x 14 control points.
struct FittedVolume {
  StructuredBlock block = CurvilinearBlock({65, 49, 33});
  FittedBlock fitted;
  FittedVolume() {
    FitOptions options;
    options.control_counts = {24, 20, 14};
    fitted = FitBlock(block, options).value();
  }
};

const FittedVolume& Volume() {
  static const FittedVolume* volume = new FittedVolume();
  return *volume;
}

void BM_CheckCellQualityVolume(benchmark::State& state) {
  const FittedVolume& volume = Volume();
  const CellReference reference = CellReference::Build(volume.block).value();
  int64_t checked = 0;
  for (auto _ : state) {
    const CellQuality quality = CheckCellQuality(volume.fitted, reference, {}).value();
    checked = quality.cells_checked;
    benchmark::DoNotOptimize(quality.min_ratio);
  }
  state.counters["sub_cells"] = static_cast<double>(checked);
  state.SetItemsProcessed(state.iterations() * checked);
}
BENCHMARK(BM_CheckCellQualityVolume)->Unit(benchmark::kMillisecond);

// The points of level 2 evaluated once, which the check evaluates too.
void BM_EvaluateLevelTwoVolume(benchmark::State& state) {
  const FittedVolume& volume = Volume();
  Resolution resolution;
  resolution.level = 2;
  const auto params = SampleParameters(volume.fitted.distribution, resolution).value();
  GridEvaluator sizing(volume.fitted.spline, params, /*first_derivatives=*/false);
  std::vector<double> points(3 * NumPoints(sizing.extents()));
  for (auto _ : state) {
    GridEvaluator evaluator(volume.fitted.spline, params, /*first_derivatives=*/false);
    evaluator.EvaluateLines(0, evaluator.num_lines(), points.data());
    benchmark::DoNotOptimize(points.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * NumPoints(sizing.extents()));
}
BENCHMARK(BM_EvaluateLevelTwoVolume)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace splinegrid::bench
