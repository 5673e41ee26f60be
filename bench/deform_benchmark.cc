// Deformation of the pitching NACA 0012 (the shared 257 x 129 C-grid, 2D view), fitted once to
// the paper's tolerances by boundary kind (FitGrid with default BoundaryTolerances):
//   BM_DeformPitching   Deformer::Rigid per step (the Deformer is created once): the wall turned
//                       about the quarter chord by a different angle each iteration, within
//                       +-10 degrees; the per-step kernel cost of a coupling client
//   BM_DeformCheck      CheckDeformation (the fold gate) of a 10 degree pitch at refinement
//                       level 0 and 1
//   BM_DeformerCreate   Deformer::Create (once per reference revision and boundary in the server)
#include <cmath>
#include <cstdlib>
#include <string>

#include "benchmark/benchmark.h"
#include "core/deform/deform_quality.h"
#include "core/deform/deformer.h"
#include "core/fit/grid_fit.h"
#include "core/io/planar_view.h"
#include "core/io/plot3d.h"
#include "tests/core/test_data.h"

namespace splinegrid::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct PitchGrid {
  std::vector<FittedBlock> blocks;
  BoundaryKinds kinds;
  int64_t controls = 0;
};

// The pitch grid fitted once (about half a second), or null if it cannot be read.
const PitchGrid* FittedPitchGrid() {
  static const PitchGrid* grid = []() -> const PitchGrid* {
    absl::StatusOr<MultiBlockGrid> read =
        ReadPlot3dFile(SharedDataPath("grids/n0012_pitch_257x129.fmt"));
    if (!read.ok()) return nullptr;
    absl::StatusOr<MultiBlockGrid> planar = PlanarView(*read);
    if (!planar.ok()) return nullptr;
    GridFitOptions options;
    options.boundary_tolerances = BoundaryTolerances();
    absl::StatusOr<GridFit> fit = FitGrid(*planar, options);
    if (!fit.ok()) return nullptr;
    auto* out = new PitchGrid;
    for (BlockFit& b : fit->blocks) {
      out->controls += b.fitted.spline.num_control_points();
      out->blocks.push_back(std::move(b.fitted));
    }
    out->kinds = std::move(fit->kinds);
    return out;
  }();
  return grid;
}

RigidMotion Pitch(double degrees) {
  RigidMotion m;
  m.center = {0.25, 0.0, 0.0};
  m.angle = degrees * kPi / 180.0;
  return m;
}

void BM_DeformPitching(benchmark::State& state) {
  const PitchGrid* grid = FittedPitchGrid();
  if (grid == nullptr) return state.SkipWithError("cannot read or fit the pitch grid");
  const absl::StatusOr<Deformer> deformer =
      Deformer::Create(grid->blocks, grid->kinds, DeformOptions());
  if (!deformer.ok()) return state.SkipWithError(std::string(deformer.status().message()).c_str());
  int64_t n = 0;
  for (auto _ : state) {
    absl::StatusOr<std::vector<FittedBlock>> moved =
        deformer->Rigid(Pitch(10.0 * std::sin(0.0628 * static_cast<double>(++n))));
    if (!moved.ok()) return state.SkipWithError("Rigid failed");
    benchmark::DoNotOptimize(moved->front().spline.control().data());
  }
  state.counters["controls"] = static_cast<double>(grid->controls);
  state.counters["moved"] = static_cast<double>(deformer->moved_controls().size());
}
BENCHMARK(BM_DeformPitching)->Unit(benchmark::kMicrosecond);

void BM_DeformCheck(benchmark::State& state) {
  const int level = static_cast<int>(state.range(0));
  const PitchGrid* grid = FittedPitchGrid();
  if (grid == nullptr) return state.SkipWithError("cannot read or fit the pitch grid");
  const absl::StatusOr<Deformer> deformer =
      Deformer::Create(grid->blocks, grid->kinds, DeformOptions());
  if (!deformer.ok()) return state.SkipWithError(std::string(deformer.status().message()).c_str());
  const std::vector<FittedBlock> moved = deformer->Rigid(Pitch(10.0)).value();
  DeformationCheck check;
  for (auto _ : state) {
    absl::StatusOr<DeformationCheck> checked =
        CheckDeformation(grid->blocks, moved, grid->kinds, level);
    if (!checked.ok()) return state.SkipWithError("CheckDeformation failed");
    check = *checked;
  }
  state.counters["cells"] = static_cast<double>(check.cells_checked);
  state.counters["folded"] = static_cast<double>(check.folded);
  state.counters["min_jacobian"] = check.min_jacobian_ratio;
  state.SetItemsProcessed(state.iterations() * check.cells_checked);
}
BENCHMARK(BM_DeformCheck)->Arg(0)->Arg(1)->ArgName("level")->Unit(benchmark::kMicrosecond);

void BM_DeformerCreate(benchmark::State& state) {
  const PitchGrid* grid = FittedPitchGrid();
  if (grid == nullptr) return state.SkipWithError("cannot read or fit the pitch grid");
  for (auto _ : state) {
    absl::StatusOr<Deformer> deformer =
        Deformer::Create(grid->blocks, grid->kinds, DeformOptions());
    if (!deformer.ok()) return state.SkipWithError("Create failed");
    benchmark::DoNotOptimize(deformer->decay_radius());
  }
}
BENCHMARK(BM_DeformerCreate)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace splinegrid::bench
