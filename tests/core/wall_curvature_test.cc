// Wall lines of fitted blocks (runs of wall points, cut at distribution breaks), the curvature
// of a fitted circle arc (1 / R, signed in the plane) and the extremum count and fairness sum
// of known curvature sequences.
#include "core/fit/report/wall_curvature.h"

#include <cmath>
#include <numbers>
#include <vector>

#include "core/bspline/parametrization.h"
#include "core/grid/boundary_kinds.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/synthetic_grids.h"

namespace splinegrid {
namespace {

constexpr uint8_t kWall = static_cast<uint8_t>(BoundaryKind::kWall);

// A fitted block whose distribution has `block`'s chord-length parameters and `breaks`; its
// spline is a plain fit (FindWallLines looks at the distribution only).
FittedBlock WithDistribution(const StructuredBlock& block, std::array<std::vector<int>, 3> breaks) {
  const auto params = ParametrizeBlock(block, Parametrization::kChordLength);
  FittedBlock fitted;
  fitted.distribution = PointDistribution::Create(params, std::move(breaks)).value();
  return fitted;
}

bool SameLine(const WallLine& a, const WallLine& b) {
  return a.block == b.block && a.direction == b.direction && a.start == b.start &&
         a.length == b.length;
}

TEST(WallLinesTest, CGridWallLineStopsAtTheWakeAndAtBreaks) {
  const CGrid c = MakeCGrid();
  const BoundaryKinds kinds = ClassifyBoundaries(c.grid, FindConnectivity(c.grid).value()).value();
  // The wall: j = 0 without the wake cut, from trailing edge to trailing edge (those points
  // end the cut and begin the airfoil).
  const int first = c.wake_cells, last = c.ni - 1 - c.wake_cells;
  std::vector<WallLine> lines = FindWallLines({WithDistribution(c.grid.blocks[0], {})}, kinds);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_TRUE(SameLine(lines[0], {0, 0, {first, 0, 0}, last - first + 1}));
  // A break at the leading edge cuts it in two that share the leading edge point; breaks
  // outside the wall change nothing.
  lines = FindWallLines(
      {WithDistribution(c.grid.blocks[0], {std::vector<int>{2, c.leading_edge}, {5}, {}})}, kinds);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_TRUE(SameLine(lines[0], {0, 0, {first, 0, 0}, c.leading_edge - first + 1}));
  EXPECT_TRUE(SameLine(lines[1], {0, 0, {c.leading_edge, 0, 0}, last - c.leading_edge + 1}));
}

TEST(WallLinesTest, RunsShorterThanThreePointsAreNoLines) {
  const StructuredBlock block = SideBySide(9).blocks[0];
  BoundaryKinds kinds;
  kinds.point_kinds.assign(1, std::vector<uint8_t>(block.num_points(), 0));
  auto set = [&](int i, int j) { kinds.point_kinds[0][block.Index(i, j, 0)] = kWall; };
  set(0, 0);
  set(1, 0);                               // two points: too short
  for (int i = 3; i <= 5; ++i) set(i, 0);  // three: a line
  for (int j = 2; j <= 8; ++j) set(8, j);  // along j at i = 8
  kinds.point_kinds[0][block.Index(4, 0, 0)] |= static_cast<uint8_t>(BoundaryKind::kInterface);
  const std::vector<WallLine> lines = FindWallLines({WithDistribution(block, {})}, kinds);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_TRUE(SameLine(lines[0], {0, 0, {3, 0, 0}, 3}));
  EXPECT_TRUE(SameLine(lines[1], {0, 1, {8, 2, 0}, 7}));
}

// A quarter of a cylinder of radius 2 (angle along i, height along j): as a planar annular
// sector (spatial_dim 2, j radial) or as a surface in space (j along the axis).
constexpr double kRadius = 2.0;
StructuredBlock Arc(int ni, int nj, bool planar, bool clockwise = false) {
  auto angle = [=](int i) {
    const double t = 0.5 * std::numbers::pi * i / (ni - 1);
    return clockwise ? 0.5 * std::numbers::pi - t : t;
  };
  if (planar) {
    return PlanarBlock(ni, nj, [=](int i, int j) -> std::array<double, 2> {
      const double r = kRadius + 0.5 * j;
      return {r * std::cos(angle(i)), r * std::sin(angle(i))};
    });
  }
  return SpaceBlock(ni, nj, 1, [=](int i, int j, int) -> std::array<double, 3> {
    return {kRadius * std::cos(angle(i)), kRadius * std::sin(angle(i)), 0.3 * j};
  });
}

FittedBlock Interpolate(const StructuredBlock& block) {
  FitOptions options;  // control_counts 0: interpolation
  absl::StatusOr<FittedBlock> fitted = FitBlock(block, options);
  EXPECT_TRUE(fitted.ok()) << fitted.status();
  return fitted.ok() ? *std::move(fitted) : FittedBlock{};
}

// The interpolating cubic of a circle sampled every 2.8 degrees: curvature within 0.5% of
// 1 / R away from the ends, 3% at the (free-curvature) ends.
constexpr double kInteriorCurvatureRelTol = 5e-3;
constexpr double kEndCurvatureRelTol = 3e-2;

void ExpectCircle(const std::vector<CurvatureSample>& samples, double signed_curvature) {
  const int n = static_cast<int>(samples.size());
  EXPECT_EQ(samples[0].arc_length, 0.0);
  EXPECT_NEAR(samples[n - 1].arc_length, kRadius * 0.5 * std::numbers::pi, 1e-3);
  for (int q = 0; q < n; ++q) {
    const bool end = q < n / 16 || q > n - 1 - n / 16;
    const double tol = (end ? kEndCurvatureRelTol : kInteriorCurvatureRelTol) / kRadius;
    EXPECT_NEAR(samples[q].curvature, signed_curvature, tol) << q;
    EXPECT_NEAR(std::hypot(samples[q].point[0], samples[q].point[1]), kRadius, 1e-5) << q;
    if (q > 0) {
      EXPECT_GT(samples[q].arc_length, samples[q - 1].arc_length);
    }
  }
}

TEST(WallCurvatureTest, CircleArcHasCurvatureOneOverRadius) {
  const StructuredBlock planar = Arc(33, 3, /*planar=*/true);
  const FittedBlock fitted = Interpolate(planar);
  const WallLine line{0, 0, {0, 0, 0}, 33};
  for (int level : {0, 2}) {
    const std::vector<CurvatureSample> samples = SampleWallCurvature(fitted, line, level);
    ASSERT_EQ(samples.size(), 32u * (1 << level) + 1);
    ExpectCircle(samples, 1.0 / kRadius);  // counter-clockwise: turning left, positive
  }
  // Clockwise, the same circle turns right.
  ExpectCircle(SampleWallCurvature(Interpolate(Arc(33, 3, true, true)), line, 1), -1.0 / kRadius);
  // The outer arc (j = 2, radius 3) on its own line.
  const std::vector<CurvatureSample> outer = SampleWallCurvature(fitted, {0, 0, {0, 2, 0}, 33}, 1);
  EXPECT_NEAR(outer[32].curvature, 1.0 / 3.0, kInteriorCurvatureRelTol / 3.0);
}

TEST(WallCurvatureTest, SurfaceBlockInSpace) {
  const StructuredBlock surface = Arc(33, 5, /*planar=*/false);
  const FittedBlock fitted = Interpolate(surface);
  BoundaryKinds kinds;
  kinds.point_kinds.assign(1, std::vector<uint8_t>(surface.num_points(), kWall));
  const std::vector<WallLine> lines = FindWallLines({fitted}, kinds);
  // Every grid line of a wall surface: 5 around (i), then 33 along the axis (j).
  ASSERT_EQ(lines.size(), 5u + 33u);
  for (int j = 0; j < 5; ++j) EXPECT_TRUE(SameLine(lines[j], {0, 0, {0, j, 0}, 33}));
  for (int i = 0; i < 33; ++i) EXPECT_TRUE(SameLine(lines[5 + i], {0, 1, {i, 0, 0}, 5}));
  ExpectCircle(SampleWallCurvature(fitted, lines[2], 2), 1.0 / kRadius);  // unsigned in 3D
  for (const CurvatureSample& s : SampleWallCurvature(fitted, lines[20], 2)) {
    EXPECT_NEAR(s.curvature, 0.0, 1e-9);  // the straight generator
  }
  const CurvatureMetrics metrics = WallCurvatureMetrics({fitted}, kinds, 1);
  EXPECT_EQ(metrics.lines, 38);
  EXPECT_EQ(metrics.samples, 5 * 65 + 33 * 9);
  EXPECT_NEAR(metrics.max_abs_curvature, 1.0 / kRadius, kEndCurvatureRelTol / kRadius);
}

std::vector<CurvatureSample> Samples(const std::vector<double>& kappa) {
  std::vector<CurvatureSample> s(kappa.size());
  for (size_t q = 0; q < kappa.size(); ++q) s[q].curvature = kappa[q];
  return s;
}

TEST(WallCurvatureTest, AccumulateCountsExtremaAndSumsSquaredDifferences) {
  CurvatureMetrics m;
  AccumulateCurvature(Samples({0, 1, 2, 1, 0, 1, 2}), m);  // a maximum and a minimum
  EXPECT_EQ(m.lines, 1);
  EXPECT_EQ(m.samples, 7);
  EXPECT_EQ(m.extrema, 2);
  EXPECT_DOUBLE_EQ(m.sum_squared_differences, 6.0);
  EXPECT_EQ(m.max_abs_curvature, 2.0);
  // A plateau inside a rise is no extremum; one between a fall and a rise is (a minimum).
  AccumulateCurvature(Samples({0, 1, 1, 1, 2, 3}), m);
  EXPECT_EQ(m.extrema, 2);
  AccumulateCurvature(Samples({0, -1, -3, -3, -1}), m);
  EXPECT_EQ(m.extrema, 3);
  EXPECT_EQ(m.lines, 3);
  EXPECT_EQ(m.samples, 7 + 6 + 5);
  EXPECT_DOUBLE_EQ(m.sum_squared_differences, 6.0 + 1 + 1 + 1 + 1 + 4 + 4);
  EXPECT_EQ(m.max_abs_curvature, 3.0);
}

TEST(WallCurvatureTest, FlatNoiseIsNoExtremum) {
  // Wiggles of 1e-12 on a constant curvature of 0.5, and on a straight line, count nothing;
  // wiggles of 1e-6 on 0.5 do.
  std::vector<double> circle, straight, rough;
  for (int q = 0; q < 50; ++q) {
    circle.push_back(0.5 + (q % 2 ? 1e-12 : -1e-12));
    straight.push_back(0.0);
    rough.push_back(0.5 + (q % 2 ? 1e-6 : -1e-6));
  }
  CurvatureMetrics m;
  AccumulateCurvature(Samples(circle), m);
  AccumulateCurvature(Samples(straight), m);
  EXPECT_EQ(m.extrema, 0);
  EXPECT_LT(m.sum_squared_differences, 1e-20);
  AccumulateCurvature(Samples(rough), m);
  EXPECT_EQ(m.extrema, 48);
}

}  // namespace
}  // namespace splinegrid
