// The knot tools of the fold repair (refinement.h: SingleDatumRun, BreakSingleDatumRuns) and the
// kernel's refusal of a folded fit to control counts (grid_fit.h).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/fit/adaptive/refinement.h"
#include "core/fit/grid_fit.h"
#include "core/io/file_util.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
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
}

}  // namespace
}  // namespace splinegrid
