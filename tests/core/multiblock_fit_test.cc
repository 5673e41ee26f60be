// FitMultiBlock: every point within its kind's tolerance and watertight shared boundaries
// (re-measured independently, multiblock_checks.h), the report, fairing to tolerance, option
// and data errors, cancellation and inconsistent touches, on small grids built here and on the
// shared C-grid and surfaces.
#include "core/fit/adaptive/multiblock_fit.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/io/planar_view.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/multiblock_checks.h"
#include "tests/core/synthetic_grids.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

MultiBlockFit Fit(const MultiBlockGrid& grid, const MultiBlockFitOptions& options) {
  absl::StatusOr<MultiBlockFit> fit = FitMultiBlock(grid, options);
  EXPECT_TRUE(fit.ok()) << fit.status();
  return fit.ok() ? *std::move(fit) : MultiBlockFit{};
}

// Tolerances for the unit-sized synthetic grids, tight enough to need knots.
MultiBlockFitOptions SyntheticOptions() {
  MultiBlockFitOptions options;
  options.tolerances.wall = 1e-6;
  options.tolerances.interface = 1e-5;
  options.tolerances.outer = 4e-5;
  return options;
}

// Two bent blocks sharing the upper half of A's right edge; A's bottom is a wall by override.
TEST(MultiBlockFitTest, PartialEdgeMeetsEveryKindsToleranceAndIsWatertight) {
  const MultiBlockGrid grid = SideBySide(17, 0.5);
  MultiBlockFitOptions options = SyntheticOptions();
  options.face_kinds = {{{0, 1, false}, BoundaryKind::kWall}};
  const MultiBlockFit fit = Fit(grid, options);
  ASSERT_EQ(fit.connectivity.matches.size(), 1u);
  ExpectTolerancesMet(grid, fit, options.tolerances);
  ExpectWatertight(grid, fit);
  const KindDeviation& a = fit.reports[0].max_deviation;
  EXPECT_GE(a.wall, 0.0);
  EXPECT_GE(a.interface, 0.0);
  EXPECT_GE(a.outer, 0.0);
  EXPECT_GE(a.interior, 0.0);
  EXPECT_LT(fit.reports[1].max_deviation.wall, 0.0);  // B has no wall
  EXPECT_LT(fit.num_control_points, fit.num_points);  // not an interpolation
  EXPECT_GT(fit.reports[0].quality.cells_checked, 0);
  EXPECT_GT(fit.wall_curvature.lines, 0);
  // Fitted block by block, the same blocks leave gaps: the check above can see them.
  options.watertight = false;
  const MultiBlockFit alone = Fit(grid, options);
  EXPECT_TRUE(alone.met) << alone.unmet_reason;
  EXPECT_GT(PointwiseGap(alone, 2), 1e-9);
}

TEST(MultiBlockFitTest, ReversedHangingNodeAndSelfMatchesAreWatertight) {
  const MultiBlockGrid reversed = SideBySide(13, 0.0, 0, /*reversed=*/true);
  const MultiBlockGrid hanging = SideBySide(9, 0.0, 17);
  const CGrid cgrid = MakeCGrid();
  for (const MultiBlockGrid* grid : {&reversed, &hanging, &cgrid.grid}) {
    MultiBlockFitOptions options = SyntheticOptions();
    // The fine side's j direction shares its knots with the coarse side, whose 9 points allow
    // at most 9 controls: the hanging nodes (and the fine block's other j lines) are only as
    // close to the data as a 9-control spline of the curved edge (7e-4 here).
    if (grid == &hanging) options.tolerances.interface = options.tolerances.outer = 1e-3;
    const MultiBlockFit fit = Fit(*grid, options);
    ASSERT_EQ(fit.connectivity.matches.size(), 1u);
    SCOPED_TRACE(fit.connectivity.matches[0].Describe());
    ExpectTolerancesMet(*grid, fit, options.tolerances);
    ExpectWatertight(*grid, fit);
  }
}

// Blocks whose shared (hanging-node) edge has a kink at y = 0.25: both sides detect it and it
// becomes a split of both, kept where the coarse side has room for it. Where it has not (coarse
// index 2 of 9) the feature is dropped and the fit, still watertight, reports the tolerance it
// misses; it used to fail with FAILED_PRECONDITION.
TEST(MultiBlockFitTest, KinkOnAHangingNodeEdge) {
  auto kinked = [](int coarse) {
    auto at = [](double x, double y) -> std::array<double, 2> {
      return {x + 0.8 * std::abs(y - 0.25), y};
    };
    MultiBlockGrid grid;
    grid.blocks.push_back(
        PlanarBlock(9, coarse, [&](int i, int j) { return at(i / 8.0, j / (coarse - 1.0)); }));
    grid.blocks.push_back(PlanarBlock(9, 2 * coarse - 1, [&](int i, int j) {
      return at(1.0 + i / 8.0, j / (2.0 * coarse - 2));
    }));
    return grid;
  };
  const MultiBlockGrid room = kinked(17);
  const MultiBlockFitOptions options;
  const MultiBlockFit fit = Fit(room, options);
  ASSERT_EQ(fit.connectivity.matches.size(), 1u);
  EXPECT_EQ(fit.connectivity.matches[0].step, 2);
  ExpectTolerancesMet(room, fit, options.tolerances);
  ExpectWatertight(room, fit);
  EXPECT_EQ(fit.blocks[0].distribution.breaks(1), std::vector<int>{4});
  EXPECT_EQ(fit.blocks[1].distribution.breaks(1), std::vector<int>{8});

  const MultiBlockGrid cramped = kinked(9);
  const MultiBlockFit tight = Fit(cramped, options);
  EXPECT_TRUE(tight.blocks[0].distribution.breaks(1).empty());
  EXPECT_FALSE(tight.met);
  EXPECT_THAT(tight.unmet_reason, HasSubstr("interface point"));
  ExpectWatertight(cramped, tight);
}

TEST(MultiBlockFitTest, VolumeSplitInTwoSharesItsFace) {
  const MultiBlockGrid grid = SplitBox(7);
  const MultiBlockFitOptions options = SyntheticOptions();
  const MultiBlockFit fit = Fit(grid, options);
  ASSERT_EQ(fit.connectivity.matches.size(), 1u);
  ExpectTolerancesMet(grid, fit, options.tolerances);
  // The whole shared face: a 2D box of controls.
  const Extents n = fit.blocks[0].spline.control_extents();
  EXPECT_EQ(ExpectSharedControlsBitwiseEqual(fit), n[1] * n[2]);
  EXPECT_LE(fit.max_gap, kGapRounding * CoordinateScale(grid));
}

// Faired to tolerance: the largest weight that keeps every tolerance; the same knots unfaired
// are returned to compare, and fairing smooths the wall.
TEST(MultiBlockFitTest, FairingToToleranceKeepsTolerances) {
  const CGrid c = MakeCGrid();
  MultiBlockFitOptions options = SyntheticOptions();
  options.fairing.mode = FairingMode::kToTolerance;
  const MultiBlockFit fit = Fit(c.grid, options);
  ExpectTolerancesMet(c.grid, fit, options.tolerances);
  ExpectWatertight(c.grid, fit);
  EXPECT_GT(fit.fairing_weight, 0.0);
  EXPECT_LE(fit.fairing_weight, options.fairing.weight);
  ASSERT_EQ(fit.unfaired.size(), 1u);
  EXPECT_EQ(fit.unfaired[0].spline.all_knots(), fit.blocks[0].spline.all_knots());
  EXPECT_NE(std::vector<double>(fit.unfaired[0].spline.control().begin(),
                                fit.unfaired[0].spline.control().end()),
            std::vector<double>(fit.blocks[0].spline.control().begin(),
                                fit.blocks[0].spline.control().end()));
  EXPECT_GT(fit.wall_curvature.lines, 0);
  EXPECT_LE(fit.wall_curvature.sum_squared_differences,
            fit.unfaired_wall_curvature.sum_squared_differences);

  // A fixed weight is used as given, whether or not the tolerances then hold (a weight that
  // is too large for them is reported, not an error).
  options.fairing.mode = FairingMode::kWeight;
  options.fairing.weight = 1e-6;
  const MultiBlockFit weighted = Fit(c.grid, options);
  EXPECT_EQ(weighted.fairing_weight, 1e-6);
  EXPECT_TRUE(weighted.unfaired.empty());
  ASSERT_EQ(weighted.reports.size(), 1u);
  EXPECT_EQ(weighted.met, weighted.reports[0].tolerance_met);
  EXPECT_EQ(weighted.met, weighted.unmet_reason.empty()) << weighted.unmet_reason;
}

TEST(MultiBlockFitTest, OptionErrorsNameTheField) {
  const MultiBlockGrid grid = SideBySide(5);
  struct Case {
    void (*set)(MultiBlockFitOptions&);
    const char* field;
  };
  const Case cases[] = {
      {[](MultiBlockFitOptions& o) { o.order = 1; }, "order = 1"},
      {[](MultiBlockFitOptions& o) { o.order = kMaxOrder + 1; }, "order = 11"},
      {[](MultiBlockFitOptions& o) { o.max_controls_per_direction = -1; },
       "max_controls_per_direction = -1"},
      {[](MultiBlockFitOptions& o) { o.max_iterations = -2; }, "max_iterations = -2"},
      {[](MultiBlockFitOptions& o) { o.tolerances.wall = 0.0; }, "tolerances.wall"},
      {[](MultiBlockFitOptions& o) { o.tolerances.edge = 2.0; }, "tolerances.edge"},
      {[](MultiBlockFitOptions& o) { o.quality.max_size_ratio = 0.5; }, "max_size_ratio"},
      {[](MultiBlockFitOptions& o) { o.quality.max_level = -1; }, "max_level"},
      {[](MultiBlockFitOptions& o) {
         o.fairing.mode = FairingMode::kWeight;
         o.fairing.weight = -1.0;
       },
       "weight"},
  };
  for (const Case& c : cases) {
    MultiBlockFitOptions options;
    c.set(options);
    const absl::StatusOr<MultiBlockFit> fit = FitMultiBlock(grid, options);
    EXPECT_EQ(fit.status().code(), absl::StatusCode::kInvalidArgument) << c.field;
    EXPECT_THAT(fit.status().message(), HasSubstr(c.field));
  }
}

// Options of the connectivity are not validated: a NaN relative tolerance silently finds no
// match at all, and the "watertight" fit then shares nothing (max_gap 0, every block alone).
TEST(MultiBlockFitTest, ConnectivityOptionErrorsNameTheField) {
  MultiBlockFitOptions options;
  options.connectivity.relative_tolerance = std::nan("");
  const absl::StatusOr<MultiBlockFit> fit = FitMultiBlock(SideBySide(9, 0.5), options);
  EXPECT_EQ(fit.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(fit.status().message(), HasSubstr("relative_tolerance"));
}

TEST(MultiBlockFitTest, DataErrors) {
  absl::StatusOr<MultiBlockFit> fit = FitMultiBlock(MultiBlockGrid{}, MultiBlockFitOptions{});
  EXPECT_EQ(fit.status().code(), absl::StatusCode::kInvalidArgument);
  MultiBlockGrid nan = SideBySide(5);
  nan.blocks[1].Point(3, 2, 0)[0] = std::nan("");
  fit = FitMultiBlock(nan, MultiBlockFitOptions{});
  EXPECT_EQ(fit.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(fit.status().message(), HasSubstr("block 1"));
  EXPECT_THAT(fit.status().message(), HasSubstr("(3, 2, 0)"));
  MultiBlockFitOptions missing_face;
  missing_face.face_kinds = {{{2, 0, false}, BoundaryKind::kWall}};
  fit = FitMultiBlock(SideBySide(5), missing_face);
  EXPECT_EQ(fit.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(fit.status().message(), HasSubstr("block 2"));
}

TEST(MultiBlockFitTest, CancellationIsHonouredBetweenWorkUnits) {
  const MultiBlockGrid grid = SideBySide(17, 0.5);
  MultiBlockFitOptions options = SyntheticOptions();
  options.cancel = [] { return true; };
  EXPECT_EQ(FitMultiBlock(grid, options).status().code(), absl::StatusCode::kCancelled);
  // Fired after some polls: the fit polls again later and stops.
  int polls = 0;
  options.cancel = [&polls] { return ++polls > 5; };
  EXPECT_EQ(FitMultiBlock(grid, options).status().code(), absl::StatusCode::kCancelled);
  EXPECT_GT(polls, 5);
  // Never fired: polled, and the fit completes.
  polls = 0;
  options.cancel = [&polls] {
    ++polls;
    return false;
  };
  EXPECT_TRUE(FitMultiBlock(grid, options).ok());
  EXPECT_GT(polls, 5);
}

TEST(MultiBlockFitTest, InconsistentTouchesAreFailedPreconditions) {
  // The Moebius strip: its j directions are linked forwards and reversed.
  const MultiBlockGrid strip = MoebiusStrip();
  absl::StatusOr<MultiBlockFit> fit = FitMultiBlock(strip, SyntheticOptions());
  EXPECT_EQ(fit.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(fit.status().message(), HasSubstr("contradicts the other matches"));
  EXPECT_THAT(fit.status().message(), HasSubstr("block 0"));
  // Fitted block by block, the strip is no problem.
  MultiBlockFitOptions separate = SyntheticOptions();
  separate.watertight = false;
  const MultiBlockFit alone = Fit(strip, separate);
  EXPECT_TRUE(alone.met) << alone.unmet_reason;
  EXPECT_EQ(alone.connectivity.matches.size(), 2u);  // still classified: interface seams
  // Blocks overlapping in fewer points than a cubic needs.
  fit = FitMultiBlock(SideBySide(5, 0.5), SyntheticOptions());
  EXPECT_EQ(fit.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(fit.status().message(), HasSubstr("block 0 direction j"));
}

// ----- Shared surfaces and C-grid -------------------------------------------------------------

MultiBlockGrid ReadShared(const std::string& relative) {
  absl::StatusOr<MultiBlockGrid> grid = ReadPlot3dFile(SharedDataPath(relative));
  EXPECT_TRUE(grid.ok()) << grid.status();
  if (!grid.ok()) return {};
  if (!IsTwoPlaneGrid(*grid)) return *std::move(grid);
  return AsPlanarGrid(*grid).value();
}

// The cube sphere and the M6 wing: watertight at the paper's tolerances, every point a wall
// point within 0.15e-3, and the cells valid.
TEST(MultiBlockFitSharedGridTest, SurfacesAreWatertight) {
  for (const char* file : {"surfaces/even_sphere.fmt", "surfaces/m6_small.fmt"}) {
    SCOPED_TRACE(file);
    const MultiBlockGrid grid = ReadShared(file);
    ASSERT_FALSE(grid.blocks.empty());
    const MultiBlockFitOptions options;
    const MultiBlockFit fit = Fit(grid, options);
    ExpectTolerancesMet(grid, fit, options.tolerances);
    ExpectWatertight(grid, fit);
    EXPECT_TRUE(fit.quality_met);
    for (const BlockFitReport& r : fit.reports) {
      EXPECT_LE(r.max_deviation.wall, options.tolerances.wall * (1.0 + kToleranceRounding));
    }
  }
}

// The NACA 0012 C-grid: the wake cut is shared, every point within its kind's tolerance.
TEST(MultiBlockFitSharedGridTest, NacaCGridWakeIsWatertight) {
  const MultiBlockGrid grid = ReadShared("grids/n0012_113-33.p2dfmt");
  ASSERT_EQ(grid.blocks.size(), 1u);
  const MultiBlockFitOptions options;
  const MultiBlockFit fit = Fit(grid, options);
  ASSERT_EQ(fit.connectivity.matches.size(), 1u);
  ExpectTolerancesMet(grid, fit, options.tolerances);
  ExpectWatertight(grid, fit);
  EXPECT_LT(fit.num_control_points, fit.num_points);
}

}  // namespace
}  // namespace splinegrid
