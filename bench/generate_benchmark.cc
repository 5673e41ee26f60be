// Grid generation around a profile (core/generate/profile_grid.h), from the coordinates file:
//   BM_GenerateOGrid/<airfoil>/<method>   GenerateProfileGrid at 257 x 129 points (first layer
//                                         1e-5 chords, far field 50 chords): the whole chain,
//                                         outline fit, wall loop, layers and the quality
//                                         measurement, with each stage's milliseconds
#include <cstdlib>
#include <string>

#include "benchmark/benchmark.h"
#include "core/generate/profile_grid.h"
#include "core/io/airfoil.h"

namespace splinegrid::bench {
namespace {

constexpr const char* kAirfoils[] = {"naca0012", "rae2822", "sc20714"};

std::string AirfoilPath(const std::string& name) {
  const std::string relative = "airfoils/" + name + ".dat";
  if (const char* dir = std::getenv("SPLINEGRID_SHARED_DATA")) {
    return std::string(dir) + "/" + relative;
  }
  return std::string(SPLINEGRID_SOURCE_DIR) + "/../shared/data/" + relative;
}

void BM_GenerateOGrid(benchmark::State& state) {
  const std::string name = kAirfoils[state.range(0)];
  absl::StatusOr<AirfoilCoordinates> coordinates = ReadAirfoilFile(AirfoilPath(name));
  if (!coordinates.ok()) return state.SkipWithError(coordinates.status().ToString().c_str());
  ProfileGridOptions options;  // 257 x 129, first 1e-5, far 50
  options.method = state.range(1) == 0 ? LayerMethod::kOffsets : LayerMethod::kTransfinite;
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
}
BENCHMARK(BM_GenerateOGrid)
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->ArgNames({"airfoil", "method"})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace splinegrid::bench
