// Deformation of fitted grids: rigid pitching of the shared NACA 0012 grids, given boundary
// displacements and points, watertightness across blocks, the quality gate, and errors.
#include "core/deform/deformer.h"

#include <cmath>

#include "core/bspline/evaluation.h"
#include "core/deform/deform_motion.h"
#include "core/deform/deform_quality.h"
#include "core/fit/grid_fit.h"
#include "core/grid/sampling.h"
#include "core/io/planar_view.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

constexpr double kPi = 3.14159265358979323846;

struct Fitted {
  MultiBlockGrid grid;
  std::vector<FittedBlock> blocks;
  BoundaryKinds kinds;
};

// A shared grid (2D view for two-plane files) fitted to the paper's tolerances by kind.
Fitted FitShared(const std::string& relative) {
  Fitted f;
  f.grid = ReadPlot3dFile(SharedDataPath(relative)).value();
  if (IsTwoPlaneGrid(f.grid)) f.grid = PlanarView(f.grid).value();
  GridFitOptions options;
  options.boundary_tolerances = BoundaryTolerances();
  GridFit fit = FitGrid(f.grid, options).value();
  for (BlockFit& b : fit.blocks) f.blocks.push_back(std::move(b.fitted));
  f.kinds = std::move(fit.kinds);
  return f;
}

RigidMotion Pitch(double degrees) {
  RigidMotion m;
  m.center = {0.25, 0.0, 0.0};
  m.angle = degrees * kPi / 180.0;
  return m;
}

// The largest distance between `deformed` and `motion` applied to `reference`, at refinement
// level 1, over the points whose kind is in `mask`.
double KindError(const Fitted& f, const std::vector<FittedBlock>& deformed, uint8_t mask,
                 const RigidMotion& motion) {
  double worst = 0.0;
  for (size_t b = 0; b < f.blocks.size(); ++b) {
    std::array<std::vector<double>, 3> p;
    for (int d = 0; d < 3; ++d) {
      p[d] = f.blocks[b].distribution.Refined(d, 0, f.blocks[b].distribution.num_points(d) - 1, 1);
    }
    const StructuredBlock was = EvaluateGrid(f.blocks[b].spline, p);
    const StructuredBlock now = EvaluateGrid(deformed[b].spline, p);
    const StructuredBlock& source = f.grid.blocks[b];
    for (int j = 0; j < source.extent(1); ++j) {
      for (int i = 0; i < source.extent(0); ++i) {
        if (!(f.kinds.point_kinds[b][source.Index(i, j, 0)] & mask)) continue;
        const double* x = was.Point(2 * i, 2 * j, 0);
        const double* y = now.Point(2 * i, 2 * j, 0);
        const Point3 want = motion.Apply({x[0], x[1], 0.0});
        worst = std::max(worst, std::hypot(want[0] - y[0], want[1] - y[1]));
      }
    }
  }
  return worst;
}

class PitchTest : public ::testing::TestWithParam<std::tuple<std::string, double>> {};

TEST_P(PitchTest, WallTurnsExactlyOuterStaysNoCellFolds) {
  const auto& [file, degrees] = GetParam();
  const Fitted f = FitShared(file);
  const Deformer deformer = Deformer::Create(f.blocks, f.kinds, DeformOptions()).value();
  const RigidMotion motion = Pitch(degrees);
  const std::vector<FittedBlock> moved = deformer.Rigid(motion).value();
  const auto wall = static_cast<uint8_t>(BoundaryKind::kWall);
  const auto outer = static_cast<uint8_t>(BoundaryKind::kOuter);
  EXPECT_LT(KindError(f, moved, wall, motion), 1e-12);
  EXPECT_EQ(KindError(f, moved, outer, RigidMotion()), 0.0);  // outer: bitwise where it was
  for (int level : {0, 1}) {
    const DeformationCheck check = CheckDeformation(f.blocks, moved, f.kinds, level).value();
    EXPECT_EQ(check.folded, 0) << "level " << level;
    EXPECT_GT(check.min_jacobian_ratio, 0.5);
    // The cells at the wall turn with it.
    EXPECT_LT(check.max_orthogonality_change_degrees, 1.0);
    EXPECT_GT(check.wall_samples, 60);
  }
}

// A gate made once checks every step like CheckDeformation: the same figures, bitwise, for
// motions that keep the grid valid and for one that tears it, at levels 0 and 1.
TEST(DeformationGateTest, AKeptGateChecksEveryStepLikeAFreshCheck) {
  const Fitted f = FitShared("grids/n0012_225-65.p2dfmt");
  DeformOptions tearing;
  tearing.decay_radius = 0.3;  // everything a third of a chord away stays
  const Deformer blend = Deformer::Create(f.blocks, f.kinds, DeformOptions()).value();
  const Deformer tear = Deformer::Create(f.blocks, f.kinds, tearing).value();
  const std::vector<std::vector<FittedBlock>> steps = {blend.Rigid(Pitch(2.0)).value(),
                                                       blend.Rigid(Pitch(-5.0)).value(),
                                                       tear.Rigid(Pitch(60.0)).value()};
  for (int level : {0, 1}) {
    const DeformationGate gate = DeformationGate::Create(f.blocks, f.kinds, level).value();
    EXPECT_EQ(gate.level(), level);
    EXPECT_EQ(gate.num_cells(), int64_t{224 << level} * (64 << level));
    for (size_t s = 0; s < steps.size(); ++s) {
      const DeformationCheck kept = gate.Check(steps[s]).value();
      const DeformationCheck fresh = CheckDeformation(f.blocks, steps[s], f.kinds, level).value();
      SCOPED_TRACE(::testing::Message() << "level " << level << ", step " << s);
      EXPECT_EQ(kept.cells_checked, fresh.cells_checked);
      EXPECT_EQ(kept.folded, fresh.folded);
      EXPECT_EQ(kept.min_jacobian_ratio, fresh.min_jacobian_ratio);
      EXPECT_EQ(kept.max_jacobian_ratio, fresh.max_jacobian_ratio);
      EXPECT_EQ(kept.worst_cell, fresh.worst_cell);
      EXPECT_EQ(kept.max_orthogonality_change_degrees, fresh.max_orthogonality_change_degrees);
      EXPECT_EQ(kept.wall_samples, fresh.wall_samples);
    }
    EXPECT_EQ(gate.Check(steps[0]).value().folded, 0);
    EXPECT_GT(gate.Check(steps[2]).value().folded, 0);  // checks leave no trace in the gate
    EXPECT_EQ(gate.Check(steps[0]).value().folded, 0);
  }
  EXPECT_THAT(
      DeformationGate::Create(f.blocks, f.kinds, kMaxRefinementLevel + 1).status().message(),
      HasSubstr("is outside [0, "));
  const DeformationGate gate = DeformationGate::Create(f.blocks, f.kinds, 0).value();
  EXPECT_THAT(gate.Check({}).status().message(), HasSubstr("the deformed grid has 0 blocks"));
}

// Control displacements named by block and control index reach the deformer in its order; a
// non-finite value is refused naming its entry, not the deformer's internal index.
TEST(DeformMotionTest, ControlDisplacementsAreMappedAndChecked) {
  const Fitted f = FitShared("grids/n0012_225-65.p2dfmt");
  const Deformer deformer = Deformer::Create(f.blocks, f.kinds, DeformOptions()).value();
  ASSERT_GE(deformer.moved_controls().size(), 2u);
  const auto [block, control] = deformer.moved_controls()[1];
  const std::vector<BlockControlDisplacements> given = {{block, {control}, {0.5, -0.25}}};
  const std::vector<double> ordered = DisplacementsInDeformerOrder(deformer, given).value();
  ASSERT_EQ(ordered.size(), 2 * deformer.moved_controls().size());
  EXPECT_EQ(ordered[2], 0.5);
  EXPECT_EQ(ordered[3], -0.25);
  EXPECT_EQ(ordered[0], 0.0);  // not given: stays
  const std::vector<BlockControlDisplacements> nan = {{block, {control}, {0.5, std::nan("")}}};
  EXPECT_THAT(DisplacementsInDeformerOrder(deformer, nan).status().message(),
              HasSubstr("blocks[0].values[1] = nan is not finite"));
  const std::vector<BlockControlDisplacements> odd = {{block, {control}, {0.5}}};
  EXPECT_THAT(DisplacementsInDeformerOrder(deformer, odd).status().message(),
              HasSubstr("blocks[0]: 1 values for 1 controls of 2 coordinates"));
  EXPECT_TRUE(ApplyMotion(deformer, DeformMotion(given)).ok());
}

INSTANTIATE_TEST_SUITE_P(SharedGrids, PitchTest,
                         ::testing::Combine(::testing::Values("grids/n0012_pitch_257x129.fmt",
                                                              "grids/n0012_225-65.p2dfmt"),
                                            ::testing::Values(10.0, -10.0, 20.0, -20.0)));

TEST(DeformerTest, IdentityChangesNothing) {
  const Fitted f = FitShared("grids/n0012_113-33.p2dfmt");
  const Deformer deformer = Deformer::Create(f.blocks, f.kinds, DeformOptions()).value();
  const std::vector<FittedBlock> same = deformer.Rigid(RigidMotion()).value();
  ASSERT_EQ(same.size(), f.blocks.size());
  for (size_t b = 0; b < same.size(); ++b) {
    const auto a = same[b].spline.control(), r = f.blocks[b].spline.control();
    ASSERT_EQ(a.size(), r.size());
    EXPECT_TRUE(std::equal(a.begin(), a.end(), r.begin()));
  }
  const std::vector<double> zero(deformer.moved_controls().size() * 2, 0.0);
  const std::vector<FittedBlock> still = deformer.DisplaceControls(zero).value();
  EXPECT_TRUE(std::equal(still[0].spline.control().begin(), still[0].spline.control().end(),
                         f.blocks[0].spline.control().begin()));
}

TEST(DeformerTest, RolesSplitWallWakeAndFarField) {
  const Fitted f = FitShared("grids/n0012_113-33.p2dfmt");
  const Deformer deformer = Deformer::Create(f.blocks, f.kinds, DeformOptions()).value();
  const Extents n = f.blocks[0].spline.control_extents();
  const auto& roles = deformer.roles()[0];
  int moved = 0, fixed = 0;
  for (int a = 0; a < n[0]; ++a) {
    moved += roles[a] == ControlRole::kMoved;                               // row j = 0
    EXPECT_EQ(roles[a + int64_t{n[0]} * (n[1] - 1)], ControlRole::kFixed);  // far field
  }
  for (ControlRole r : roles) fixed += r == ControlRole::kFixed;
  // The airfoil's controls move, the wake cut's on either side do not (they are free).
  EXPECT_GT(moved, 10);
  EXPECT_LT(moved, n[0] - 4);
  EXPECT_EQ(roles[0], ControlRole::kFixed);  // the wake's outflow corner is on the outer boundary
  EXPECT_GT(fixed, n[0] + 2 * n[1] - 4);
  EXPECT_GT(deformer.decay_radius(), 100.0);  // the far field is 500 chords away
}

TEST(DeformerTest, TranslatedControlsTranslateTheWallExactly) {
  const Fitted f = FitShared("grids/n0012_113-33.p2dfmt");
  const Deformer deformer = Deformer::Create(f.blocks, f.kinds, DeformOptions()).value();
  std::vector<double> shift;
  for (size_t q = 0; q < deformer.moved_controls().size(); ++q) {
    shift.push_back(0.01);
    shift.push_back(-0.02);
  }
  const std::vector<FittedBlock> moved = deformer.DisplaceControls(shift).value();
  RigidMotion translation;
  translation.translation = {0.01, -0.02, 0.0};
  EXPECT_LT(KindError(f, moved, static_cast<uint8_t>(BoundaryKind::kWall), translation), 1e-15);
  EXPECT_EQ(CheckDeformation(f.blocks, moved, f.kinds, 1).value().folded, 0);
}

TEST(DeformerTest, BoundaryPointsAreFittedWithTheStoredBasis) {
  const Fitted f = FitShared("grids/n0012_113-33.p2dfmt");
  const Deformer deformer = Deformer::Create(f.blocks, f.kinds, DeformOptions()).value();
  // The wall of the 113 x 33 C-grid: j = 0 between the trailing-edge points (the wake cut's
  // match ends there), given rotated by 10 degrees at refinement level 1.
  const FittedBlock& block = f.blocks[0];
  const std::vector<int>& breaks = block.distribution.breaks(0);
  ASSERT_EQ(breaks.size(), 2u);
  BoundaryPoints wall;
  wall.range = FaceRange{Face{0, 1, false}, {breaks[0], 0, 0}, {breaks[1], 0, 0}};
  wall.level = 1;
  const std::vector<double> u = block.distribution.Refined(0, breaks[0], breaks[1], 1);
  const RigidMotion motion = Pitch(10.0);
  for (double t : u) {
    const Point3 x = EvaluatePoint(block.spline, {t, 0.0, 0.0});
    const Point3 y = motion.Apply(x);
    wall.coordinates.push_back(y[0]);
    wall.coordinates.push_back(y[1]);
  }
  const std::vector<FittedBlock> fitted = deformer.MoveBoundaryPoints({&wall, 1}).value();
  const std::vector<FittedBlock> rigid = deformer.Rigid(motion).value();
  // The rotated wall is in the span of the stored basis: least squares finds it again.
  for (const auto& [b, c] : deformer.moved_controls()) {
    const double* p = fitted[b].spline.control().data() + 2 * c;
    const double* q = rigid[b].spline.control().data() + 2 * c;
    EXPECT_NEAR(p[0], q[0], 1e-11);
    EXPECT_NEAR(p[1], q[1], 1e-11);
  }
  // The same as displacements.
  BoundaryPoints as_displacements = wall;
  as_displacements.displacements = true;
  for (size_t s = 0; s < u.size(); ++s) {
    const Point3 x = EvaluatePoint(block.spline, {u[s], 0.0, 0.0});
    as_displacements.coordinates[2 * s] -= x[0];
    as_displacements.coordinates[2 * s + 1] -= x[1];
  }
  const std::vector<FittedBlock> again =
      deformer.MoveBoundaryPoints({&as_displacements, 1}).value();
  EXPECT_NEAR(again[0].spline.control()[200], fitted[0].spline.control()[200], 1e-12);
}

TEST(DeformerTest, SharedFacesStayWatertight) {
  // The 113 x 33 C-grid cut at its leading edge into two blocks: the cut is an interface that
  // must move identically on both sides.
  const MultiBlockGrid whole = ReadPlot3dFile(SharedDataPath("grids/n0012_113-33.p2dfmt")).value();
  const StructuredBlock& b = whole.blocks[0];
  MultiBlockGrid two;
  for (auto [i0, i1] : {std::pair{0, 56}, std::pair{56, 112}}) {
    StructuredBlock part({i1 - i0 + 1, b.extent(1), 1}, 2);
    for (int j = 0; j < b.extent(1); ++j) {
      for (int i = i0; i <= i1; ++i) {
        std::copy(b.Point(i, j, 0), b.Point(i, j, 0) + 2, part.Point(i - i0, j, 0));
      }
    }
    two.blocks.push_back(std::move(part));
  }
  // The tolerance mode by kind, the paper's tolerances as lengths in the grid's unit (chords).
  GridFitOptions options;
  options.boundary_tolerances = BoundaryTolerances();
  options.relative_kinds = 0;
  const GridFit grid_fit = FitGrid(two, options).value();
  ASSERT_TRUE(grid_fit.report.tolerance_met) << grid_fit.report.unmet_reason;
  ASSERT_LT(grid_fit.report.max_gap, 1e-12);
  std::vector<FittedBlock> fitted;
  for (const BlockFit& block : grid_fit.blocks) fitted.push_back(block.fitted);
  const Deformer deformer = Deformer::Create(fitted, grid_fit.kinds, DeformOptions()).value();
  // The controls of the cut: column 56 of block 0 and column 0 of block 1, equal bitwise.
  const Extents n0 = fitted[0].spline.control_extents();
  const Extents n1 = fitted[1].spline.control_extents();
  ASSERT_EQ(n0[1], n1[1]);
  auto cut_equal = [&](const std::vector<FittedBlock>& blocks) {
    for (int j = 0; j < n0[1]; ++j) {
      const double* a = blocks[0].spline.ControlPoint(n0[0] - 1, j, 0);
      const double* c = blocks[1].spline.ControlPoint(0, j, 0);
      if (a[0] != c[0] || a[1] != c[1]) return false;
    }
    return true;
  };
  ASSERT_TRUE(cut_equal(fitted));
  for (double degrees : {15.0, -15.0}) {
    const std::vector<FittedBlock> moved = deformer.Rigid(Pitch(degrees)).value();
    EXPECT_TRUE(cut_equal(moved));
    EXPECT_LT(MaxBoundaryGap(grid_fit.connectivity, moved, 2), 1e-12);
    EXPECT_EQ(CheckDeformation(fitted, moved, grid_fit.kinds, 1).value().folded, 0);
  }
}

TEST(DeformerTest, TransfiniteAndSmoothingKeepTheBoundariesAndCells) {
  const Fitted f = FitShared("grids/n0012_pitch_257x129.fmt");
  DeformOptions options;
  options.propagation = Propagation::kTransfinite;
  options.smoothing_iterations = 5;
  const Deformer deformer = Deformer::Create(f.blocks, f.kinds, options).value();
  const RigidMotion motion = Pitch(5.0);
  const std::vector<FittedBlock> moved = deformer.Rigid(motion).value();
  EXPECT_LT(KindError(f, moved, static_cast<uint8_t>(BoundaryKind::kWall), motion), 1e-12);
  const DeformationCheck check = CheckDeformation(f.blocks, moved, f.kinds, 1).value();
  EXPECT_EQ(check.folded, 0);
  // Coons carries the wall's displacement without turning it: the cells at the wall shear.
  const DeformationCheck blended =
      CheckDeformation(
          f.blocks,
          Deformer::Create(f.blocks, f.kinds, DeformOptions()).value().Rigid(motion).value(),
          f.kinds, 1)
          .value();
  EXPECT_GT(check.max_orthogonality_change_degrees, blended.max_orthogonality_change_degrees);
}

TEST(DeformerTest, TheGateFindsFolds) {
  const Fitted f = FitShared("grids/n0012_113-33.p2dfmt");
  DeformOptions options;
  options.decay_radius = 0.3;  // everything a third of a chord away stays: the nose tears
  const Deformer deformer = Deformer::Create(f.blocks, f.kinds, options).value();
  const std::vector<FittedBlock> moved = deformer.Rigid(Pitch(60.0)).value();
  const DeformationCheck check = CheckDeformation(f.blocks, moved, f.kinds, 1).value();
  EXPECT_GT(check.folded, 0);
  EXPECT_LT(check.min_jacobian_ratio, 0.0);
}

TEST(DeformerTest, BadInputIsAnErrorNamingIt) {
  const Fitted f = FitShared("grids/n0012_113-33.p2dfmt");
  DeformOptions unknown;
  unknown.moved.ranges = {FaceRange{Face{3, 1, false}, {0, 0, 0}, {5, 0, 0}}};
  absl::StatusOr<Deformer> d = Deformer::Create(f.blocks, f.kinds, unknown);
  EXPECT_EQ(d.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(d.status().message(), HasSubstr("block 3"));
  DeformOptions nothing;
  nothing.moved.kinds = 0;
  EXPECT_EQ(Deformer::Create(f.blocks, f.kinds, nothing).status().code(),
            absl::StatusCode::kFailedPrecondition);
  DeformOptions radii;
  radii.rigid_radius = 2.0;
  radii.decay_radius = 1.0;
  EXPECT_THAT(Deformer::Create(f.blocks, f.kinds, radii).status().message(),
              HasSubstr("decay_radius = 1"));

  const Deformer deformer = Deformer::Create(f.blocks, f.kinds, DeformOptions()).value();
  RigidMotion nan = Pitch(std::nan(""));
  EXPECT_THAT(deformer.Rigid(nan).status().message(), HasSubstr("angle = nan"));
  // The vector and its coordinate are named (a C API user saw "coordinate 0 is 0.25, 0, inf").
  RigidMotion far;
  far.center = {0.25, 0.0, 0.0};
  far.translation = {INFINITY, 0.0, 0.0};
  EXPECT_THAT(deformer.Rigid(far).status().message(),
              HasSubstr("motion: translation[0] = inf is not finite"));
  RigidMotion no_axis;
  no_axis.axis = {0, 0, 0};
  EXPECT_EQ(deformer.Rigid(no_axis).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(deformer.DisplaceControls(std::vector<double>(3, 0.0)).status().message(),
              HasSubstr("3 values for"));
  std::vector<double> bad(deformer.moved_controls().size() * 2, 0.0);
  bad[5] = INFINITY;
  EXPECT_THAT(deformer.DisplaceControls(bad).status().message(),
              HasSubstr("displacements[5] = inf"));
  BoundaryPoints off;  // the far field is not the moved boundary
  off.range = FaceRange{Face{0, 1, true}, {0, 32, 0}, {10, 32, 0}};
  off.coordinates.assign(22, 0.0);
  EXPECT_THAT(deformer.MoveBoundaryPoints({&off, 1}).status().message(),
              HasSubstr("boundary points 0: point (0, 32, 0) of block 0 is not on the moved "
                        "boundary (DeformOptions.moved, a request's boundary: the walls unless"));
  BoundaryPoints wrong_count;
  wrong_count.range = FaceRange{Face{0, 1, false}, {50, 0, 0}, {60, 0, 0}};
  wrong_count.coordinates.assign(7, 0.0);
  EXPECT_THAT(deformer.MoveBoundaryPoints({&wrong_count, 1}).status().message(),
              HasSubstr("7 values for 11 points"));
}

}  // namespace
}  // namespace splinegrid
