// The knot tools of the fold repair (refinement.h: SingleDatumRun, BreakSingleDatumRuns) and the
// kernel's refusal of a folded fit to control counts (grid_fit.h).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/bspline/evaluation.h"
#include "core/fit/adaptive/refinement.h"
#include "core/fit/grid_fit.h"
#include "core/io/file_util.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/multiblock_checks.h"
#include "tests/core/quadrilateral_checks.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

// 11 data on [0, 1], uniform.
std::vector<double> Uniform(int n) {
  std::vector<double> u(n);
  for (int r = 0; r < n; ++r) u[r] = static_cast<double>(r) / (n - 1);
  return u;
}

// Knots midway between consecutive data r and r + 1 for every r in `at`.
std::vector<double> Midpoints(const std::vector<double>& u, const std::vector<int>& at) {
  std::vector<double> knots;
  for (int r : at) knots.push_back(0.5 * (u[r] + u[r + 1]));
  return knots;
}

TEST(FoldRepairTest, SingleDatumRunCountsSpansWithFewerThanTwoData) {
  const std::vector<double> u = Uniform(11);
  EXPECT_EQ(SingleDatumRun(u, {}), 0);  // one span, 11 data
  // Knots after data 1, 2, ..., 7: spans {0, 1}, {2}, {3}, ..., {7}, {8, 9, 10}.
  EXPECT_EQ(SingleDatumRun(u, Midpoints(u, {1, 2, 3, 4, 5, 6, 7})), 6);
}

TEST(FoldRepairTest, BreakingRunsBoundsThemAndOnlyRemovesKnotsOnRuns) {
  const std::vector<double> u = Uniform(11);
  const std::vector<double> knots = Midpoints(u, {1, 2, 3, 4, 5, 6, 7});
  for (int max_run : {1, 2, 4}) {
    const std::vector<double> kept = BreakSingleDatumRuns(u, knots, max_run);
    EXPECT_LE(SingleDatumRun(u, kept), max_run) << max_run;
    EXPECT_LT(kept.size(), knots.size());
    // Only removals: every kept knot was a knot.
    for (double t : kept) EXPECT_NE(std::find(knots.begin(), knots.end(), t), knots.end());
  }
  // Nothing to do where no run is too long.
  EXPECT_EQ(BreakSingleDatumRuns(u, knots, 6), knots);
}

// Folded sub-cells (quadrilateral_checks.h) of a 2D fitted block at refinement level `level`,
// its spline evaluated point by point here, not by the fit's own quality check.
int64_t FoldedSubCells(const StructuredBlock& data, const FittedBlock& fitted, int level) {
  const std::vector<double> u = fitted.distribution.Refined(0, 0, data.extent(0) - 1, level);
  const std::vector<double> v = fitted.distribution.Refined(1, 0, data.extent(1) - 1, level);
  StructuredBlock fine({static_cast<int>(u.size()), static_cast<int>(v.size()), 1}, 2);
  for (size_t j = 0; j < v.size(); ++j) {
    for (size_t i = 0; i < u.size(); ++i) {
      const Point3 x = EvaluatePoint(fitted.spline, {u[i], v[j], 0.0});
      std::copy_n(x.begin(), 2, fine.Point(static_cast<int>(i), static_cast<int>(j), 0));
    }
  }
  return FoldedSubCells(data, fine, level);
}

// Control counts that fold the NACA 0012 113 x 33 C-grid at levels 1-2: no repair is tried
// (that would change the counts), the fit fails naming the block, the levels and the cells,
// unless allow_folds, which returns it with quality_met = false. Interpolation folds it too, and
// is named as such, not as counts the caller never gave.
TEST(FoldRepairTest, ACountFitThatFoldsIsRefusedUnlessAllowed) {
  const std::string path = SharedDataPath("grids/n0012_113-33.p2dfmt");
  const MultiBlockGrid grid = ParsePlot3d(ReadFileToString(path).value(), path).value();
  GridFitOptions options;
  options.control_counts = {100, 30, 0};
  absl::StatusOr<GridFit> refused = FitGrid(grid, options);
  ASSERT_EQ(refused.status().code(), absl::StatusCode::kFailedPrecondition) << refused.status();
  const std::string message(refused.status().message());
  EXPECT_THAT(message, HasSubstr("block 0: "));
  EXPECT_THAT(message, HasSubstr("folded sub-cells ("));
  EXPECT_THAT(message, HasSubstr("the worst at cell ("));
  EXPECT_THAT(message, HasSubstr("A fit to control counts is not repaired"));
  EXPECT_THAT(message, HasSubstr("allow_folds"));

  // Without counts every block interpolates its points, and the message says so.
  GridFitOptions interpolating;
  interpolating.control_counts = {0, 0, 0};
  const absl::StatusOr<GridFit> interpolated = FitGrid(grid, interpolating);
  ASSERT_EQ(interpolated.status().code(), absl::StatusCode::kFailedPrecondition)
      << interpolated.status();
  EXPECT_THAT(std::string(interpolated.status().message()),
              HasSubstr("An interpolating fit (a control point per grid point"));

  options.allow_folds = true;
  absl::StatusOr<GridFit> allowed = FitGrid(grid, options);
  ASSERT_TRUE(allowed.ok()) << allowed.status();
  EXPECT_FALSE(allowed->report.quality_met);
  const CellQuality& q = allowed->blocks[0].quality;
  EXPECT_GT(q.folded, 0);
  ASSERT_EQ(q.folded_by_level.size(), 3u);
  EXPECT_EQ(q.folded_by_level[0] + q.folded_by_level[1] + q.folded_by_level[2], q.folded);
  EXPECT_GT(q.num_folded_cells, 0);
  EXPECT_LE(q.num_folded_cells, q.num_bad_cells);
  // The independent count sees them too (levels 1-2; the data cells themselves do not fold).
  EXPECT_GT(FoldedSubCells(grid.blocks[0], allowed->blocks[0].fitted, 2), 0);
}

// One absolute tolerance for every point of a C-grid (500 chords of far field) asks for a
// control per datum over much of the grid, where split knots leave the fit free to swing
// between its data: 16,000-29,000 folded sub-cells at 1e-3 on both NACA 0012 C-grids before the
// repairs of step 3b (adaptive_engine.h). Now every point is within the tolerance, and no
// sub-cell folds at levels 0..2, counted here.
TEST(FoldRepairTest, OneToleranceOnACGridFitsWithoutFolds) {
  const std::string path = SharedDataPath("grids/n0012_113-33.p2dfmt");
  const MultiBlockGrid grid = ParsePlot3d(ReadFileToString(path).value(), path).value();
  for (const double tolerance : {1e-2, 1e-3}) {
    GridFitOptions options;
    options.tolerance = tolerance;
    const absl::StatusOr<GridFit> fit = FitGrid(grid, options);
    ASSERT_TRUE(fit.ok()) << tolerance << ": " << fit.status();
    EXPECT_TRUE(fit->report.tolerance_met) << fit->report.unmet_reason;
    BoundaryTolerances held;
    held.wall = held.interface = held.outer = held.interior = tolerance;
    ExpectTolerancesMet(grid, *fit, held);
    EXPECT_LT(fit->report.num_control_points, grid.blocks[0].num_points());
    for (int level = 0; level <= 2; ++level) {
      EXPECT_EQ(FoldedSubCells(grid.blocks[0], fit->blocks[0].fitted, level), 0)
          << "tolerance " << tolerance << ", level " << level;
    }
  }
}

}  // namespace
}  // namespace splinegrid
