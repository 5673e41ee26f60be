// No silent changes (issue 12, point 7): requests that FitGrid cannot honour as asked are
// refused naming the field, value, block and limit; degenerate grids are refused naming the
// block and what is degenerate, while collapsed edges (polar axes, caps) still fit; and the
// report never claims a tolerance or a quality that was not measured.
#include <cmath>
#include <numbers>
#include <string>

#include "core/fit/adaptive/adaptive_fit.h"
#include "core/fit/grid_fit.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/synthetic_grids.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

// A gently curved planar block of ni x nj points.
MultiBlockGrid Curved(int ni, int nj) {
  MultiBlockGrid grid;
  grid.blocks.push_back(BentRectangle(0.0, 1.0 / (ni - 1), ni, 0.0, 1.0 / (nj - 1), nj));
  return grid;
}

GridFitOptions Counts(int ci, int cj, int order = 4) {
  GridFitOptions options;
  options.order = order;
  options.control_counts = {ci, cj, 0};
  return options;
}

TEST(GridFitValidationTest, FewerControlsThanTheOrderAreRefusedNotFittedAtALowerOrder) {
  const MultiBlockGrid grid = Curved(30, 12);
  const absl::Status status = FitGrid(grid, Counts(2, 2)).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(),
              AllOf(HasSubstr("control_counts[0] = 2 is below order = 4"),
                    HasSubstr("give at least 4 (block 0 has 30 points in i), or order <= 2")));
  // Asked for explicitly, the same fit is fine: order 2, 2 x 2 controls.
  absl::StatusOr<GridFit> fit = FitGrid(grid, Counts(2, 2, /*order=*/2));
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_EQ(fit->blocks[0].fitted.spline.knots(0).order(), 2);
  EXPECT_EQ(fit->blocks[0].fitted.spline.knots(0).num_controls(), 2);
}

TEST(GridFitValidationTest, MoreControlsThanPointsAreRefusedNamingTheBlockAndLimit) {
  MultiBlockGrid grid = Curved(30, 12);
  grid.blocks.push_back(BentRectangle(1.0, 0.05, 21, 0.0, 0.1, 11));
  // Grid-wide counts that suit block 0 but not block 1 (once clamped to 21 there).
  absl::Status status = FitGrid(grid, Counts(25, 10)).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(),
              HasSubstr("control_counts[0] = 25 exceeds the 21 points of block 1 in i; give at "
                        "most 21 (0: as many as points)"));
  EXPECT_THAT(FitGrid(grid, Counts(1000, 1000)).status().message(),
              HasSubstr("control_counts[0] = 1000 exceeds the 30 points of block 0 in i"));
  // A per-block override is named as such.
  GridFitOptions options = Counts(20, 10);
  options.block_control_counts = {{1, {15, 50, 0}}};
  EXPECT_THAT(
      FitGrid(grid, options).status().message(),
      HasSubstr("block_control_counts[0].control_counts[1] = 50 exceeds the 11 points of block 1"));
  options.block_control_counts = {{1, {15, 8, 0}}, {1, {16, 8, 0}}};
  EXPECT_THAT(FitGrid(grid, options).status().message(),
              HasSubstr("block_control_counts[1].block = 1 repeats block_control_counts[0]"));
  options.block_control_counts = {{1, {15, 8, 0}}};
  absl::StatusOr<GridFit> fit = FitGrid(grid, options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_EQ(fit->blocks[1].fitted.spline.knots(0).num_controls(), 15);
  // Counts for a direction of one point.
  GridFitOptions in_k = Counts(10, 10);
  in_k.control_counts[2] = 4;
  EXPECT_THAT(FitGrid(grid, in_k).status().message(),
              HasSubstr("control_counts[2] = 4 but block 0 has a single point in k"));
}

TEST(GridFitValidationTest, ADirectionWithFewerPointsThanTheOrderInterpolatesThemAndSaysSo) {
  // Three points in j at order 4: the only fit there is interpolates them at order 3; the
  // spline states it. Asking for 3 controls there is the same request.
  const MultiBlockGrid grid = Curved(20, 3);
  for (int cj : {0, 3}) {
    absl::StatusOr<GridFit> fit = FitGrid(grid, Counts(8, cj));
    ASSERT_TRUE(fit.ok()) << fit.status();
    const TensorSpline& spline = fit->blocks[0].fitted.spline;
    EXPECT_EQ(spline.knots(0).order(), 4);
    EXPECT_EQ(spline.knots(1).order(), 3);
    EXPECT_EQ(spline.knots(1).num_controls(), 3);
    EXPECT_THAT(fit->report.adjustments,
                ::testing::ElementsAre(
                    "block 0 direction j: 3 points, fitted through them at order 3 instead of 4"));
  }
  // As asked: nothing stated.
  absl::StatusOr<GridFit> cubic = FitGrid(Curved(20, 5), Counts(8, 4));
  ASSERT_TRUE(cubic.ok()) << cubic.status();
  EXPECT_TRUE(cubic->report.adjustments.empty());
  EXPECT_THAT(FitGrid(grid, Counts(8, 2)).status().message(),
              HasSubstr("control_counts[1] = 2 is below order = 4"));
}

TEST(GridFitValidationTest, MaxControlsBelowTheOrderIsRefused) {
  GridFitOptions options;
  options.tolerance = 1e-3;
  options.max_controls_per_direction = 3;
  const absl::Status status = FitGrid(Curved(30, 12), options).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(),
              HasSubstr("max_controls_per_direction = 3 is below order = 4: a direction of "
                        "order k starts with k control points; give at least 4"));
}

TEST(GridFitValidationTest, TheKernelsToleranceFitsRefuseACapBelowTheOrderToo) {
  const MultiBlockGrid grid = Curved(30, 12);
  // Tolerances by kind (the multi-block tolerance fit) refuse it as the one tolerance does.
  GridFitOptions multi;
  BoundaryTolerances tolerances;
  tolerances.wall = tolerances.interface = tolerances.outer = 1e-3;
  multi.boundary_tolerances = tolerances;
  multi.relative_kinds = 0;
  multi.max_controls_per_direction = 2;
  const absl::Status status = FitGrid(grid, multi).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("max_controls_per_direction = 2 is below order = 4"));
  ToleranceFitOptions single;
  single.max_controls_per_direction = 3;
  single.order = 5;
  const double tolerance = 1e-3;
  EXPECT_THAT(FitToTolerance(grid.blocks[0], {&tolerance, 1}, single).status().message(),
              HasSubstr("max_controls_per_direction = 3 is below order = 5"));
}

// The block's error from ValidateFittable and FitGrid (which says FAILED_PRECONDITION).
void ExpectUnfittable(const StructuredBlock& block, const std::string& fragment) {
  const absl::Status direct = ValidateFittable(block, "block 0");
  EXPECT_EQ(direct.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(direct.message(), HasSubstr(fragment));
  MultiBlockGrid grid;
  grid.blocks.push_back(block);
  const absl::Status fit = FitGrid(grid, GridFitOptions()).status();
  EXPECT_EQ(fit.code(), absl::StatusCode::kFailedPrecondition) << fit;
  EXPECT_THAT(fit.message(), AllOf(HasSubstr("block 0: "), HasSubstr(fragment)));
}

TEST(GridFitValidationTest, DegenerateBlocksAreRefusedNamingWhatIsDegenerate) {
  // All points equal.
  ExpectUnfittable(PlanarBlock(10, 20, [](int, int) { return std::array<double, 2>{3.0, -1.0}; }),
                   "all 200 points are equal (3, -1): a grid collapsed to a point");
  // A volume whose k-planes coincide: direction k has zero length.
  ExpectUnfittable(SpaceBlock(6, 5, 3,
                              [](int i, int j, int) {
                                return std::array<double, 3>{double(i), double(j * j), 0.5};
                              }),
                   "direction k has zero length: each of its k-lines of 3 points is a single "
                   "repeated point");
  // A surface whose points lie on one line (its cells have no area).
  ExpectUnfittable(SpaceBlock(6, 5, 1,
                              [](int i, int j, int) {
                                const double t = i + 0.3 * j * j;
                                return std::array<double, 3>{t, 2 * t, -t};
                              }),
                   "its points lie on one line: the surface block of 6 x 5 x 1 points has cells "
                   "of zero area");
  // A volume in a plane (not a coordinate plane): every point is i u + j v + k (u + v / 2).
  ExpectUnfittable(SpaceBlock(4, 4, 4,
                              [](int i, int j, int k) {
                                const double a = i + k, b = j + 0.5 * k;
                                return std::array<double, 3>{0.3 * a + 0.8 * b, 0.7 * a - 0.1 * b,
                                                             -0.2 * a + 0.6 * b};
                              }),
                   "its points lie on one plane: the volume block of 4 x 4 x 4 points has cells "
                   "of zero volume");
  // A volume with two coordinates.
  ExpectUnfittable(StructuredBlock({3, 3, 3}, 2), "a volume block needs 3 (x, y, z) coordinates");
  // Non-finite coordinates.
  StructuredBlock nan = BentRectangle(0.0, 0.1, 11, 0.0, 0.1, 11);
  nan.Point(4, 7, 0)[1] = std::nan("");
  ExpectUnfittable(nan, "point (4, 7, 0) coordinate y is nan");
}

TEST(GridFitValidationTest, CollapsedEdgesStillFit) {
  using std::numbers::pi;
  // A polar disc: the j = 0 line is the centre, one point.
  const StructuredBlock disc = PlanarBlock(17, 9, [](int i, int j) {
    const double a = 2 * pi * i / 16, r = j / 8.0;
    return std::array<double, 2>{r * std::cos(a), r * std::sin(a)};
  });
  // A volume around a polar axis: the j = 0 face collapses to the z axis.
  const StructuredBlock axis = SpaceBlock(9, 6, 5, [](int i, int j, int k) {
    const double a = pi * i / 8, r = j / 5.0;
    return std::array<double, 3>{r * std::cos(a), r * std::sin(a), 0.25 * k};
  });
  // A wing-tip cap: the i = 0 face collapses to a line along k (every j-line there is a point).
  const StructuredBlock cap = SpaceBlock(7, 6, 4, [](int i, int j, int k) {
    const double s = i / 6.0, w = 0.1 + 0.3 * k;
    return std::array<double, 3>{s, w * s * (j / 5.0 - 0.5) + 0.05 * s * s, 0.2 * k};
  });
  for (const StructuredBlock* block : {&disc, &axis, &cap}) {
    EXPECT_TRUE(ValidateFittable(*block, "block 0").ok())
        << ValidateFittable(*block, "block 0");
    MultiBlockGrid grid;
    grid.blocks.push_back(*block);
    absl::StatusOr<GridFit> fit = FitGrid(grid, GridFitOptions());
    EXPECT_TRUE(fit.ok()) << fit.status();
  }
}

TEST(GridFitValidationTest, SharedGridsAreFittable) {
  for (const char* file : {"grids/n0012_113-33.p2dfmt", "grids/rae2822_257x97.fmt",
                           "grids/n0012_pitch_257x129.fmt", "surfaces/m6_small.fmt",
                           "surfaces/even_sphere.fmt", "surfaces/ffd_box_6x2x6.fmt"}) {
    absl::StatusOr<MultiBlockGrid> grid = ReadPlot3dFile(SharedDataPath(file));
    ASSERT_TRUE(grid.ok()) << file << ": " << grid.status();
    for (size_t b = 0; b < grid->blocks.size(); ++b) {
      EXPECT_TRUE(ValidateFittable(grid->blocks[b], "block").ok())
          << file << " block " << b << ": " << ValidateFittable(grid->blocks[b], "block");
    }
  }
}

TEST(GridFitValidationTest, TheReportClaimsOnlyWhatWasMeasured) {
  const MultiBlockGrid grid = Curved(30, 12);
  // Control counts: no tolerance was given, so none was met.
  absl::StatusOr<GridFit> counts = FitGrid(grid, Counts(6, 4));
  ASSERT_TRUE(counts.ok()) << counts.status();
  EXPECT_FALSE(counts->report.tolerance_met);
  EXPECT_THAT(counts->report.unmet_reason, HasSubstr("no tolerance was given"));
  EXPECT_TRUE(counts->report.quality_met);
  // Tolerances: met when measured within them.
  GridFitOptions tolerance;
  tolerance.tolerance = 1e-3;
  absl::StatusOr<GridFit> met = FitGrid(grid, tolerance);
  ASSERT_TRUE(met.ok()) << met.status();
  EXPECT_TRUE(met->report.tolerance_met) << met->report.unmet_reason;
  EXPECT_LE(met->report.max_deviation, 1e-3);
  // A cell check that skipped every cell measured nothing; a curve has no cells to measure.
  CellQuality skipped;
  skipped.cells_skipped = 12;
  EXPECT_TRUE(skipped.ok());
  EXPECT_FALSE(skipped.measured());
  EXPECT_TRUE(CellQuality().measured());
}

}  // namespace
}  // namespace splinegrid
