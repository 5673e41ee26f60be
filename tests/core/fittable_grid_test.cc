// FitGrid with a known connectivity (the service finds it once, at import): the same fit as
// finding it again, in both modes, and the given connectivity is the one used.
#include <algorithm>
#include <span>

#include "core/fit/grid_fit.h"
#include "core/grid/connectivity.h"
#include "core/io/plot3d.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

// The NACA 0012 C-grid: one block whose wake cut is a match with itself.
MultiBlockGrid Naca() {
  return ReadPlot3dFile(SharedDataPath("grids/n0012_225-65.p2dfmt")).value();
}

void ExpectSameFit(const GridFit& a, const GridFit& b) {
  ASSERT_EQ(a.blocks.size(), b.blocks.size());
  for (size_t k = 0; k < a.blocks.size(); ++k) {
    const std::span<const double> x = a.blocks[k].fitted.spline.control();
    const std::span<const double> y = b.blocks[k].fitted.spline.control();
    EXPECT_TRUE(std::equal(x.begin(), x.end(), y.begin(), y.end()))
        << "block " << k << ": control nets differ";
  }
  EXPECT_EQ(a.report.num_matches, b.report.num_matches);
  EXPECT_EQ(a.report.max_gap, b.report.max_gap);
}

TEST(GridFitConnectivityTest, AGivenConnectivityFitsLikeAFoundOne) {
  const MultiBlockGrid grid = Naca();
  const Connectivity found = FindConnectivity(grid).value();
  ASSERT_EQ(found.matches.size(), 1u);

  GridFitOptions tolerances;
  tolerances.boundary_tolerances = BoundaryTolerances();  // the paper's, relative
  const GridFit a = FitGrid(grid, tolerances).value();
  const GridFit b = FitGrid(grid, found, tolerances).value();
  ExpectSameFit(a, b);
  EXPECT_EQ(b.report.num_matches, 1);
  EXPECT_LT(b.report.max_gap, 1e-9);  // watertight across the wake cut (rounding only)

  GridFitOptions counts;
  counts.control_counts = {40, 14, 0};
  counts.allow_folds = true;  // few controls fold this grid; the fit is compared, not judged
  ExpectSameFit(FitGrid(grid, counts).value(), FitGrid(grid, found, counts).value());
}

TEST(GridFitConnectivityTest, TheGivenConnectivityIsTheOneUsed) {
  const MultiBlockGrid grid = Naca();
  GridFitOptions counts;
  counts.control_counts = {40, 14, 0};
  counts.allow_folds = true;
  const GridFit fit = FitGrid(grid, Connectivity{}, counts).value();
  EXPECT_EQ(fit.report.num_matches, 0);
  EXPECT_TRUE(fit.connectivity.matches.empty());
}

}  // namespace
}  // namespace splinegrid
