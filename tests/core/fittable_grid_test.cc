// FittableGrid: a grid checked and matched once (the service does it when a grid arrives) fits
// exactly like the same grid given as points, in both modes; the check refuses what FitGrid
// refuses, naming the block, and its connectivity options are the ones used.
#include "core/grid/fittable_grid.h"

#include <algorithm>
#include <span>

#include "core/fit/grid_fit.h"
#include "core/grid/connectivity.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

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
  EXPECT_EQ(a.report.max_deviation, b.report.max_deviation);
}

TEST(FittableGridTest, ACheckedGridFitsLikeItsPoints) {
  const MultiBlockGrid grid = Naca();
  const FittableGrid checked = FittableGrid::Check(grid).value();
  EXPECT_EQ(checked.connectivity(), FindConnectivity(grid).value());
  ASSERT_EQ(checked.connectivity().matches.size(), 1u);

  GridFitOptions tolerances;
  tolerances.boundary_tolerances = BoundaryTolerances();  // the paper's, relative
  const GridFit b = FitGrid(checked, tolerances).value();
  ExpectSameFit(FitGrid(grid, tolerances).value(), b);
  EXPECT_EQ(b.report.num_matches, 1);
  EXPECT_LT(b.report.max_gap, 1e-9);  // watertight across the wake cut (rounding only)

  GridFitOptions counts;
  counts.control_counts = {40, 14, 0};
  counts.allow_folds = true;  // few controls fold this grid; the fit is compared, not judged
  ExpectSameFit(FitGrid(grid, counts).value(), FitGrid(checked, counts).value());

  // Options are still checked, naming the field.
  counts.control_counts = {400, 14, 0};
  EXPECT_THAT(FitGrid(checked, counts).status().message(), HasSubstr("control_counts"));
}

TEST(FittableGridTest, TheCheckRefusesWhatCannotBeFittedNamingTheBlock) {
  MultiBlockGrid grid = Naca();
  StructuredBlock collapsed({4, 3, 1}, 2);
  std::fill(collapsed.coords().begin(), collapsed.coords().end(), 0.5);
  grid.blocks.push_back(collapsed);
  const absl::Status refused = FittableGrid::Check(grid).status();
  EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(refused.message(), HasSubstr("block 1: all 12 points are equal"));
  // FitGrid on the points says the same, as a precondition of the grid.
  const absl::Status fit = FitGrid(grid, GridFitOptions()).status();
  EXPECT_EQ(fit.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(fit.message(), HasSubstr("block 1: all 12 points are equal"));

  // Finite coordinates whose span overflows are not called "equal".
  MultiBlockGrid huge = Naca();
  huge.blocks[0].coords()[7] = 1e300;
  huge.blocks[0].coords()[9] = -1e300;
  EXPECT_THAT(FittableGrid::Check(huge).status().message(),
              HasSubstr("block 0: the coordinates are too large to measure the block"));
  // Nor a grid whose lengths' squares underflow (a valid grid in units of 1e-300).
  MultiBlockGrid tiny = Naca();
  for (double& v : tiny.blocks[0].coords()) v *= 1e-300;
  EXPECT_THAT(FittableGrid::Check(tiny).status().message(),
              HasSubstr("block 0: the coordinates are too small to measure the block"));

  EXPECT_THAT(FittableGrid::Check(MultiBlockGrid()).status().message(), HasSubstr("no blocks"));
  EXPECT_FALSE(FitGrid(FittableGrid(), GridFitOptions()).ok());
}

// A grid line repeated in the points (j = 6 a copy of j = 5) makes cells of no area that any
// spline through them folds: the refusal says the points cause it (it blamed the fit alone).
// A pole (a polar disk's collapsed edge) is no such cell; collapsed_edges_test.cc fits one.
TEST(FittableGridTest, AFoldFromARepeatedGridLineBlamesThePoints) {
  MultiBlockGrid grid = Naca();
  StructuredBlock& block = grid.blocks[0];
  for (int i = 0; i < block.extent(0); ++i) {
    std::copy_n(block.Point(i, 5, 0), 2, block.Point(i, 6, 0));
  }
  const absl::Status refused = FitGrid(grid, GridFitOptions()).status();
  EXPECT_EQ(refused.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(refused.message(),
              HasSubstr("The points themselves have 224 cells of no thickness (a grid line "
                        "repeated), the first block 0 cell (0, 5, 0)"));
  // Without the repeated line, a fold refusal does not mention it.
  GridFitOptions counts;
  counts.control_counts = {12, 8, 1};
  const absl::Status folded = FitGrid(Naca(), counts).status();
  ASSERT_EQ(folded.code(), absl::StatusCode::kFailedPrecondition) << folded;
  EXPECT_THAT(folded.message(), ::testing::Not(HasSubstr("no thickness")));
}

TEST(FittableGridTest, ItsConnectivityOptionsAreTheOnesUsed) {
  // Matches must join at least 1000 points: the wake cut (33) is ignored, so the checked grid
  // has no match, and a fit of it shares no boundary.
  ConnectivityOptions strict;
  strict.min_points = 1000;
  const FittableGrid checked = FittableGrid::Check(Naca(), strict).value();
  EXPECT_TRUE(checked.connectivity().matches.empty());
  GridFitOptions counts;
  counts.control_counts = {40, 14, 0};
  counts.allow_folds = true;
  const GridFit fit = FitGrid(checked, counts).value();
  EXPECT_EQ(fit.report.num_matches, 0);
  EXPECT_TRUE(fit.connectivity.matches.empty());
}

}  // namespace
}  // namespace splinegrid
