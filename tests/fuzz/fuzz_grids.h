// The small real grid the fuzz targets and their seeds share: the shared NACA 0012 C-grid
// (../shared/data/grids/n0012_113-33.p2dfmt) at every 4th point, 29 x 9, and its fit.
#ifndef SPLINEGRID_TESTS_FUZZ_FUZZ_GRIDS_H_
#define SPLINEGRID_TESTS_FUZZ_FUZZ_GRIDS_H_

#include <string>
#include <utility>
#include <vector>

#include "core/fit/grid_fit.h"
#include "core/io/plot3d.h"
#include "tests/fuzz/fuzz_util.h"

namespace splinegrid::fuzz {

// The 29 x 9 x 1 grid (spatial_dim 2); aborts when the shared file is missing.
inline MultiBlockGrid SmallNaca0012() {
  const std::string path =
      std::string(SPLINEGRID_SOURCE_DIR) + "/../shared/data/grids/n0012_113-33.p2dfmt";
  absl::StatusOr<MultiBlockGrid> full = ReadPlot3dFile(path);
  FUZZ_CHECK(full.ok(), full.status().ToString());
  const StructuredBlock& from = full->blocks.front();
  const int ni = (from.extent(0) - 1) / 4 + 1, nj = (from.extent(1) - 1) / 4 + 1;
  StructuredBlock to({ni, nj, 1}, from.spatial_dim());
  for (int j = 0; j < nj; ++j) {
    for (int i = 0; i < ni; ++i) {
      for (int s = 0; s < from.spatial_dim(); ++s) {
        to.Point(i, j, 0)[s] = from.Point(4 * i, 4 * j, 0)[s];
      }
    }
  }
  MultiBlockGrid grid;
  grid.blocks.push_back(std::move(to));
  return grid;
}

// FitGrid of `grid` with the default options (interpolation), folds accepted: the targets need
// a fitted reference, and interpolating the coarse grid folds cells at levels 1-2, which
// FitGrid refuses unless allow_folds is set. Aborts on failure.
inline GridFit FitSmall(const MultiBlockGrid& grid) {
  GridFitOptions options;
  options.allow_folds = true;
  absl::StatusOr<GridFit> fit = FitGrid(grid, options);
  FUZZ_CHECK(fit.ok(), fit.status().ToString());
  return std::move(*fit);
}

}  // namespace splinegrid::fuzz

#endif  // SPLINEGRID_TESTS_FUZZ_FUZZ_GRIDS_H_
