// The tolerance mode of FitGrid by kind (grid_fit.h; internal::FitMultiBlock, multiblock_fit.h,
// where a test needs what only it returns): every point within its kind's tolerance and
// watertight shared boundaries (re-measured independently, multiblock_checks.h), the report,
// fairing to tolerance, option and data errors, cancellation and inconsistent touches, on small
// grids built here and on the shared C-grid and surfaces.
#include "core/fit/adaptive/multiblock_fit.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/bspline/evaluation.h"
#include "core/fit/grid_fit.h"
#include "core/fit/report/fit_report.h"
#include "core/grid/boundary_kinds.h"
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

GridFit Fit(const MultiBlockGrid& grid, const GridFitOptions& options) {
  absl::StatusOr<GridFit> fit = FitGrid(grid, options);
  EXPECT_TRUE(fit.ok()) << fit.status();
  return fit.ok() ? *std::move(fit) : GridFit{};
}

// The tolerance mode run directly, for what only it returns (the unfaired blocks), with the
// connectivity and kinds FitGrid would find, after FitGrid's validation of the options.
internal::MultiBlockRun RunToleranceMode(const MultiBlockGrid& grid,
                                         const GridFitOptions& options) {
  const absl::Status valid = options.Validate(grid);
  EXPECT_TRUE(valid.ok()) << valid;
  const absl::StatusOr<Connectivity> connectivity = FindConnectivity(grid, options.connectivity);
  EXPECT_TRUE(connectivity.ok()) << connectivity.status();
  if (!valid.ok() || !connectivity.ok()) return {};
  const absl::StatusOr<BoundaryKinds> kinds =
      ClassifyBoundaries(grid, *connectivity, options.face_kinds);
  EXPECT_TRUE(kinds.ok()) << kinds.status();
  if (!kinds.ok()) return {};
  absl::StatusOr<internal::MultiBlockRun> run = internal::FitMultiBlock(
      grid, *connectivity, *kinds, options, *options.boundary_tolerances, CancelCheck());
  EXPECT_TRUE(run.ok()) << run.status();
  return run.ok() ? *std::move(run) : internal::MultiBlockRun{};
}

// Tolerances for the unit-sized synthetic grids, tight enough to need knots.
GridFitOptions SyntheticOptions() {
  BoundaryTolerances tolerances;
  tolerances.wall = 1e-6;
  tolerances.interface = 1e-5;
  tolerances.outer = 4e-5;
  return KindToleranceOptions(tolerances);
}

std::vector<double> Controls(const FittedBlock& fitted) {
  return std::vector<double>(fitted.spline.control().begin(), fitted.spline.control().end());
}

// Two bent blocks sharing the upper half of A's right edge; A's bottom is a wall by override.
TEST(MultiBlockFitTest, PartialEdgeMeetsEveryKindsToleranceAndIsWatertight) {
  const MultiBlockGrid grid = SideBySide(17, 0.5);
  GridFitOptions options = SyntheticOptions();
  options.face_kinds = {{{0, 1, false}, BoundaryKind::kWall}};
  const GridFit fit = Fit(grid, options);
  ASSERT_EQ(fit.connectivity.matches.size(), 1u);
  EXPECT_EQ(fit.report.num_matches, 1);
  ExpectTolerancesMet(grid, fit, *options.boundary_tolerances);
  ExpectWatertight(grid, fit);
  const KindDeviation& a = fit.blocks[0].deviation_by_kind;
  EXPECT_GE(a.wall, 0.0);
  EXPECT_GE(a.interface, 0.0);
  EXPECT_GE(a.outer, 0.0);
  EXPECT_GE(a.interior, 0.0);
  EXPECT_LT(fit.blocks[1].deviation_by_kind.wall, 0.0);             // B has no wall
  EXPECT_LT(fit.report.num_control_points, fit.report.num_points);  // not an interpolation
  EXPECT_GT(fit.blocks[0].quality.cells_checked, 0);
  EXPECT_GT(fit.report.wall_curvature.lines, 0);
  // Fitted block by block, the same blocks leave gaps: the check above can see them, and the
  // report measures them too (max_gap is measured whether or not the fit is watertight).
  options.watertight = false;
  const GridFit alone = Fit(grid, options);
  EXPECT_TRUE(alone.report.tolerance_met) << alone.report.unmet_reason;
  const double gap = PointwiseGap(alone, 2);
  EXPECT_GT(gap, 1e-9);
  EXPECT_NEAR(alone.report.max_gap, gap, kGapRounding * CoordinateScale(grid));
}

TEST(MultiBlockFitTest, ReversedHangingNodeAndSelfMatchesAreWatertight) {
  const MultiBlockGrid reversed = SideBySide(13, 0.0, 0, /*reversed=*/true);
  const MultiBlockGrid hanging = SideBySide(9, 0.0, 17);
  const CGrid cgrid = MakeCGrid();
  for (const MultiBlockGrid* grid : {&reversed, &hanging, &cgrid.grid}) {
    GridFitOptions options = SyntheticOptions();
    // The fine side's j direction shares its knots with the coarse side, whose 9 points allow
    // at most 9 controls: the hanging nodes (and the fine block's other j lines) are only as
    // close to the data as a 9-control spline of the curved edge (7e-4 here).
    if (grid == &hanging) {
      options.boundary_tolerances->interface = options.boundary_tolerances->outer = 1e-3;
    }
    // The synthetic C-grid's cells at the trailing edge (i = 6 and 37, where its j lines turn
    // from the wake's vertical to the ellipse's near-horizontal normal) fold at levels 1-2 at
    // these tolerances; this test examines watertightness, not cells (FitGrid refuses folds
    // unless allowed).
    if (grid == &cgrid.grid) options.allow_folds = true;
    const GridFit fit = Fit(*grid, options);
    ASSERT_EQ(fit.connectivity.matches.size(), 1u);
    SCOPED_TRACE(fit.connectivity.matches[0].Describe());
    ExpectTolerancesMet(*grid, fit, *options.boundary_tolerances);
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
  const GridFitOptions options = KindToleranceOptions();
  const GridFit fit = Fit(room, options);
  ASSERT_EQ(fit.connectivity.matches.size(), 1u);
  EXPECT_EQ(fit.connectivity.matches[0].step, 2);
  ExpectTolerancesMet(room, fit, *options.boundary_tolerances);
  ExpectWatertight(room, fit);
  EXPECT_EQ(fit.blocks[0].fitted.distribution.breaks(1), std::vector<int>{4});
  EXPECT_EQ(fit.blocks[1].fitted.distribution.breaks(1), std::vector<int>{8});

  const MultiBlockGrid cramped = kinked(9);
  const GridFit tight = Fit(cramped, options);
  ASSERT_EQ(tight.blocks.size(), 2u);
  EXPECT_TRUE(tight.blocks[0].fitted.distribution.breaks(1).empty());
  EXPECT_FALSE(tight.report.tolerance_met);
  EXPECT_THAT(tight.report.unmet_reason, HasSubstr("interface point"));
  ExpectWatertight(cramped, tight);
}

TEST(MultiBlockFitTest, VolumeSplitInTwoSharesItsFace) {
  const MultiBlockGrid grid = SplitBox(7);
  const GridFitOptions options = SyntheticOptions();
  const GridFit fit = Fit(grid, options);
  ASSERT_EQ(fit.connectivity.matches.size(), 1u);
  ExpectTolerancesMet(grid, fit, *options.boundary_tolerances);
  // The whole shared face: a 2D box of controls.
  const Extents n = fit.blocks[0].fitted.spline.control_extents();
  EXPECT_EQ(ExpectSharedControlsBitwiseEqual(fit), n[1] * n[2]);
  EXPECT_LE(fit.report.max_gap, kGapRounding * CoordinateScale(grid));
}

// Faired to tolerance: the largest weight that keeps every tolerance; the same knots unfaired
// are returned to compare (by the tolerance mode itself: FitGrid reports only their wall
// curvature, and is checked to be that run), and fairing smooths the wall.
TEST(MultiBlockFitTest, FairingToToleranceKeepsTolerances) {
  const CGrid c = MakeCGrid();
  GridFitOptions options = SyntheticOptions();
  options.fairing.mode = FairingMode::kToTolerance;
  options.allow_folds = true;  // the C-grid's trailing-edge cells fold (see above)
  const internal::MultiBlockRun run = RunToleranceMode(c.grid, options);
  const GridFit& fit = run.fit;
  ExpectTolerancesMet(c.grid, fit, *options.boundary_tolerances);
  ExpectWatertight(c.grid, fit);
  EXPECT_GT(fit.report.fairing_weight, 0.0);
  EXPECT_LE(fit.report.fairing_weight, options.fairing.weight);
  ASSERT_EQ(run.unfaired.size(), 1u);
  ASSERT_EQ(fit.blocks.size(), 1u);
  EXPECT_EQ(run.unfaired[0].spline.all_knots(), fit.blocks[0].fitted.spline.all_knots());
  EXPECT_NE(Controls(run.unfaired[0]), Controls(fit.blocks[0].fitted));
  EXPECT_GT(fit.report.wall_curvature.lines, 0);
  EXPECT_LE(fit.report.wall_curvature.sum_squared_differences,
            fit.report.unfaired_wall_curvature.sum_squared_differences);
  // FitGrid is that run: the same weight, controls and curvatures.
  const GridFit public_fit = Fit(c.grid, options);
  ASSERT_EQ(public_fit.blocks.size(), 1u);
  EXPECT_EQ(public_fit.report.fairing_weight, fit.report.fairing_weight);
  EXPECT_EQ(Controls(public_fit.blocks[0].fitted), Controls(fit.blocks[0].fitted));
  EXPECT_EQ(public_fit.report.unfaired_wall_curvature.sum_squared_differences,
            fit.report.unfaired_wall_curvature.sum_squared_differences);
  EXPECT_EQ(public_fit.report.wall_curvature.sum_squared_differences,
            fit.report.wall_curvature.sum_squared_differences);

  // A fixed weight is used as given, whether or not the tolerances then hold (a weight that
  // is too large for them is reported, not an error).
  options.fairing.mode = FairingMode::kWeight;
  options.fairing.weight = 1e-6;
  const internal::MultiBlockRun weighted = RunToleranceMode(c.grid, options);
  EXPECT_EQ(weighted.fit.report.fairing_weight, 1e-6);
  EXPECT_TRUE(weighted.unfaired.empty());
  EXPECT_EQ(weighted.fit.report.unfaired_wall_curvature.lines, 0);
  ASSERT_EQ(weighted.fit.blocks.size(), 1u);
  EXPECT_EQ(weighted.fit.report.tolerance_met, weighted.fit.blocks[0].tolerance_met);
  EXPECT_EQ(weighted.fit.report.tolerance_met, weighted.fit.report.unmet_reason.empty())
      << weighted.fit.report.unmet_reason;
}

// Through FitGrid, which validates first: INVALID_ARGUMENT naming the field, the same status as
// GridFitOptions::Validate's.
TEST(MultiBlockFitTest, OptionErrorsNameTheField) {
  const MultiBlockGrid grid = SideBySide(5);
  struct Case {
    void (*set)(GridFitOptions&);
    const char* field;
  };
  const Case cases[] = {
      {[](GridFitOptions& o) { o.order = 1; }, "order = 1"},
      {[](GridFitOptions& o) { o.order = kMaxOrder + 1; }, "order = 11"},
      {[](GridFitOptions& o) { o.max_controls_per_direction = -1; },
       "max_controls_per_direction = -1"},
      {[](GridFitOptions& o) { o.max_iterations = -2; }, "max_iterations = -2"},
      {[](GridFitOptions& o) { o.boundary_tolerances->wall = 0.0; }, "tolerances.wall"},
      {[](GridFitOptions& o) { o.boundary_tolerances->edge = 2.0; }, "tolerances.edge"},
      {[](GridFitOptions& o) { o.tolerance = 1e-3; }, "tolerance and boundary_tolerances"},
      {[](GridFitOptions& o) { o.quality.max_size_ratio = 0.5; }, "max_size_ratio"},
      {[](GridFitOptions& o) { o.quality.max_level = -1; }, "max_level"},
      {[](GridFitOptions& o) { o.features.angle_degrees = 200.0; }, "features.angle_degrees"},
      {[](GridFitOptions& o) { o.features.spike_ratio = 0.5; }, "features.spike_ratio"},
      {[](GridFitOptions& o) {
         o.fairing.mode = FairingMode::kWeight;
         o.fairing.weight = -1.0;
       },
       "weight"},
  };
  // Valid as they are: each case alone makes them invalid.
  ASSERT_TRUE(SyntheticOptions().Validate(grid).ok()) << SyntheticOptions().Validate(grid);
  for (const Case& c : cases) {
    SCOPED_TRACE(c.field);
    GridFitOptions options = SyntheticOptions();
    c.set(options);
    const absl::StatusOr<GridFit> fit = FitGrid(grid, options);
    EXPECT_EQ(fit.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(fit.status().message(), HasSubstr(c.field));
    EXPECT_EQ(options.Validate(grid), fit.status());
  }
}

// The options of the connectivity are validated too: a NaN relative tolerance used to find no
// match at all, and the "watertight" fit then shared nothing (max_gap 0, every block alone).
TEST(MultiBlockFitTest, ConnectivityOptionErrorsNameTheField) {
  GridFitOptions options = SyntheticOptions();
  options.connectivity.relative_tolerance = std::nan("");
  const absl::StatusOr<GridFit> fit = FitGrid(SideBySide(9, 0.5), options);
  EXPECT_EQ(fit.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(fit.status().message(), HasSubstr("connectivity.relative_tolerance"));
}

// An empty grid and a bad face override are option errors (INVALID_ARGUMENT); a block that
// cannot be fitted (a NaN point) is FitGrid's FAILED_PRECONDITION, naming the block and point.
TEST(MultiBlockFitTest, DataErrors) {
  absl::StatusOr<GridFit> fit = FitGrid(MultiBlockGrid{}, SyntheticOptions());
  EXPECT_EQ(fit.status().code(), absl::StatusCode::kInvalidArgument);
  MultiBlockGrid nan = SideBySide(5);
  nan.blocks[1].Point(3, 2, 0)[0] = std::nan("");
  fit = FitGrid(nan, SyntheticOptions());
  EXPECT_EQ(fit.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(fit.status().message(), HasSubstr("block 1"));
  EXPECT_THAT(fit.status().message(), HasSubstr("(3, 2, 0)"));
  GridFitOptions missing_face = SyntheticOptions();
  missing_face.face_kinds = {{{2, 0, false}, BoundaryKind::kWall}};
  fit = FitGrid(SideBySide(5), missing_face);
  EXPECT_EQ(fit.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(fit.status().message(), HasSubstr("block 2"));
}

// A first layer to hold on a grid without walls would hold nothing, and the report would read
// as if it were held: it is refused, naming the field and how walls are named. With a wall
// named, the same request is a fit.
TEST(MultiBlockFitTest, AFirstLayerAskedOfAGridWithoutWallsIsRefused) {
  const MultiBlockGrid grid = SideBySide(9, 0.5);
  GridFitOptions options = SyntheticOptions();
  options.boundary_tolerances->first_layer = 0.05;
  const absl::StatusOr<GridFit> refused = FitGrid(grid, options);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(refused.status().message(), HasSubstr("tolerances.first_layer = 0.05 holds nothing"));
  EXPECT_THAT(refused.status().message(), HasSubstr("face_kinds"));
  options.face_kinds = {{{0, 1, false}, BoundaryKind::kWall}};
  const GridFit fit = Fit(grid, options);
  EXPECT_TRUE(fit.report.tolerance_met) << fit.report.unmet_reason;
  EXPECT_GE(fit.blocks[0].deviation_by_kind.first_layer, 0.0);
  EXPECT_LE(fit.blocks[0].deviation_by_kind.first_layer, 0.05);
}

TEST(MultiBlockFitTest, CancellationIsHonouredBetweenWorkUnits) {
  const MultiBlockGrid grid = SideBySide(17, 0.5);
  const GridFitOptions options = SyntheticOptions();
  EXPECT_EQ(FitGrid(grid, options, [] { return true; }).status().code(),
            absl::StatusCode::kCancelled);
  // Fired after some polls: the fit polls again later and stops.
  int polls = 0;
  EXPECT_EQ(FitGrid(grid, options, [&polls] { return ++polls > 5; }).status().code(),
            absl::StatusCode::kCancelled);
  EXPECT_GT(polls, 5);
  // Never fired: polled, and the fit completes.
  polls = 0;
  const absl::StatusOr<GridFit> fit = FitGrid(grid, options, [&polls] {
    ++polls;
    return false;
  });
  EXPECT_TRUE(fit.ok()) << fit.status();
  EXPECT_GT(polls, 5);
}

TEST(MultiBlockFitTest, InconsistentTouchesAreFailedPreconditions) {
  // The Moebius strip: its j directions are linked forwards and reversed.
  const MultiBlockGrid strip = MoebiusStrip();
  absl::StatusOr<GridFit> fit = FitGrid(strip, SyntheticOptions());
  EXPECT_EQ(fit.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(fit.status().message(), HasSubstr("contradicts the other matches"));
  EXPECT_THAT(fit.status().message(), HasSubstr("block 0"));
  // Fitted block by block, the strip is no problem.
  GridFitOptions separate = SyntheticOptions();
  separate.watertight = false;
  const GridFit alone = Fit(strip, separate);
  EXPECT_TRUE(alone.report.tolerance_met) << alone.report.unmet_reason;
  EXPECT_EQ(alone.connectivity.matches.size(), 2u);  // still classified: interface seams
  // Blocks overlapping in fewer points than a cubic needs.
  fit = FitGrid(SideBySide(5, 0.5), SyntheticOptions());
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
    const GridFitOptions options = KindToleranceOptions();
    const GridFit fit = Fit(grid, options);
    ExpectTolerancesMet(grid, fit, *options.boundary_tolerances);
    ExpectWatertight(grid, fit);
    EXPECT_TRUE(fit.report.quality_met);
    for (const BlockFit& block : fit.blocks) {
      EXPECT_LE(block.deviation_by_kind.wall,
                options.boundary_tolerances->wall * (1.0 + kToleranceRounding));
    }
  }
}

// The NACA 0012 C-grid: the wake cut is shared, every point within its kind's tolerance.
TEST(MultiBlockFitSharedGridTest, NacaCGridWakeIsWatertight) {
  const MultiBlockGrid grid = ReadShared("grids/n0012_113-33.p2dfmt");
  ASSERT_EQ(grid.blocks.size(), 1u);
  const GridFitOptions options = KindToleranceOptions();
  const GridFit fit = Fit(grid, options);
  ASSERT_EQ(fit.connectivity.matches.size(), 1u);
  ExpectTolerancesMet(grid, fit, *options.boundary_tolerances);
  ExpectWatertight(grid, fit);
  EXPECT_LT(fit.report.num_control_points, fit.report.num_points);
}

// The first layer at the walls, whose height a solver's y+ follows, is reported (no tolerance
// holds it): on the shared NACA 0012 225 x 65 at the default tolerances by kind the trial that
// found it measured changes of up to 34%. Measured again here from the fitted spline at the
// data parameters over the wall points' j = 1 neighbours; an interpolating fit keeps it.
TEST(MultiBlockFitTest, TheChangeOfTheFirstLayerAtTheWallsIsReported) {
  const MultiBlockGrid grid =
      ReadPlot3dFile(SharedDataPath("grids/n0012_225-65.p2dfmt")).value();
  GridFitOptions options;
  options.boundary_tolerances = BoundaryTolerances();  // the defaults, relative to the chord
  const GridFit fit = Fit(grid, options);
  ASSERT_EQ(fit.blocks.size(), 1u);
  const StructuredBlock& data = grid.blocks[0];
  const FittedBlock& fitted = fit.blocks[0].fitted;
  std::array<std::vector<double>, 3> params;
  for (int d = 0; d < 3; ++d) params[d] = fitted.distribution.params(d);
  const StructuredBlock eval = EvaluateGrid(fitted.spline, params);
  const std::vector<uint8_t>& kinds = fit.kinds.point_kinds[0];
  const auto is_wall = [&](int i, int j) {
    return (kinds[data.Index(i, j, 0)] & static_cast<uint8_t>(BoundaryKind::kWall)) != 0;
  };
  double largest = 0.0;
  int walls = 0;
  for (int i = 0; i < data.extent(0); ++i) {
    if (!is_wall(i, 0)) continue;
    ++walls;
    const double h = std::hypot(data.Point(i, 1, 0)[0] - data.Point(i, 0, 0)[0],
                                data.Point(i, 1, 0)[1] - data.Point(i, 0, 0)[1]);
    const double g = std::hypot(eval.Point(i, 1, 0)[0] - eval.Point(i, 0, 0)[0],
                                eval.Point(i, 1, 0)[1] - eval.Point(i, 0, 0)[1]);
    largest = std::max(largest, std::abs(g - h) / h);
  }
  EXPECT_EQ(walls, 129);
  EXPECT_NEAR(fit.blocks[0].deviation_by_kind.first_layer, largest, 1e-12);
  EXPECT_GT(largest, 0.05);  // measured 0.34
  options = GridFitOptions();  // interpolating: a control per point
  const GridFit exact = Fit(grid, options);
  EXPECT_GE(exact.blocks[0].deviation_by_kind.first_layer, 0.0);
  EXPECT_LT(exact.blocks[0].deviation_by_kind.first_layer, 1e-8);
}

// Held (BoundaryTolerances::first_layer), the change stays within it on the three shared
// C-grids, every other tolerance still met; a fit that does not hold it is reported as not
// within its tolerances, naming the point (measured at 0.05: 0.030, 0.0085, 0.0073; 3.3x,
// 7.1x, 9.3x compression against 6.5x, 15.4x, 22.2x unheld).
TEST(MultiBlockFitTest, AHeldFirstLayerKeepsEveryFirstLayerHeight) {
  for (const char* file : {"grids/n0012_225-65.p2dfmt", "grids/rae2822_257x97.fmt",
                           "grids/n0012_pitch_257x129.fmt"}) {
    MultiBlockGrid grid = ReadPlot3dFile(SharedDataPath(file)).value();
    if (IsTwoPlaneGrid(grid)) grid = PlanarView(grid).value();
    GridFitOptions options;
    options.boundary_tolerances = BoundaryTolerances();
    options.boundary_tolerances->first_layer = 0.05;
    const GridFit fit = Fit(grid, options);
    ASSERT_EQ(fit.blocks.size(), 1u) << file;
    EXPECT_TRUE(fit.report.tolerance_met) << file << ": " << fit.report.unmet_reason;
    EXPECT_GT(fit.blocks[0].deviation_by_kind.first_layer, 0.0) << file;
    EXPECT_LE(fit.blocks[0].deviation_by_kind.first_layer, 0.05) << file;
    EXPECT_EQ(fit.blocks[0].quality.folded, 0) << file;
    if (std::string(file) != "grids/n0012_225-65.p2dfmt") continue;
    // A fit that does not hold it (here: one made without it, reported against it) is not
    // within its tolerances, and the report says which.
    options.boundary_tolerances->first_layer = 0.0;
    GridFit unheld = Fit(grid, options);
    ASSERT_TRUE(unheld.report.tolerance_met);
    BoundaryTolerances asked = *unheld.report.tolerances;
    asked.first_layer = 0.05;
    ASSERT_TRUE(internal::ReportFit(grid, CellQualityOptions(), &asked, {}, unheld).ok());
    EXPECT_FALSE(unheld.report.tolerance_met);
    EXPECT_THAT(unheld.report.unmet_reason,
                HasSubstr("block 0 first-layer height at wall point ("));
    EXPECT_THAT(unheld.report.unmet_reason, HasSubstr(") changed by 0.34"));
    EXPECT_THAT(unheld.report.unmet_reason, HasSubstr("more than first_layer = 0.05"));
  }
}

}  // namespace
}  // namespace splinegrid
