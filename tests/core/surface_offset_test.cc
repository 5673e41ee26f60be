// OffsetSurface: a tilted plane offset exactly (both sides, and which handedness each gives), the
// shared sphere blocks outward and inward at the stacked radii, an inward offset past the centre
// refused or limited short of it, a polar cap whose collapsed edge stays one point on the axis,
// the shared M6 wing blocks, wedges marched into their concave crease, and every error path. Cells
// are checked with an independent oracle: the corner Jacobians and grid_quality's hexahedron
// volume.
#include "core/generate/surface_offset.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "core/fit/report/grid_quality.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"
#include "tests/core/wedge_surface.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

constexpr double kPi = std::numbers::pi;
// A plane is reproduced exactly by the fits and its normals are constant: rounding only.
constexpr double kPlaneTol = 1e-12;
// Layer radii on a sphere, relative to the offset distance (the acceptance bar of the issue).
constexpr double kRadiusRelTol = 0.01;
// Height of the first layer, relative to the request.
constexpr double kFirstHeightRelTol = 0.05;

MultiBlockGrid ReadShared(const std::string& relative) {
  absl::StatusOr<MultiBlockGrid> grid = ReadPlot3dFile(SharedDataPath(relative));
  EXPECT_TRUE(grid.ok()) << grid.status();
  return grid.ok() ? *std::move(grid) : MultiBlockGrid{};
}

Point3 At(const StructuredBlock& b, int i, int j, int k) {
  const double* x = b.Point(i, j, k);
  return {x[0], x[1], x[2]};
}
Point3 Sub(const Point3& a, const Point3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double Dot(const Point3& a, const Point3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double Norm(const Point3& a) { return std::sqrt(Dot(a, a)); }
Point3 Cross(const Point3& a, const Point3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// The cells of a volume block seen with orientation `side`: the smallest side det[e_i, e_j, e_k]
// / (|e_i| |e_j| |e_k|) over all corners whose three edges are not collapsed (edges leaving the
// corner, each pointing in +i, +j or +k), how many corners were skipped, and the smallest
// side * volume of the trilinear hexahedron relative to the cell's longest edge cubed.
struct CellSigns {
  double min_scaled_jacobian = 1.0;
  int skipped_corners = 0;
  double min_relative_volume = HUGE_VAL;
};

CellSigns CheckCells(const StructuredBlock& b, int side) {
  CellSigns out;
  const Extents n = b.extents();
  for (int k = 0; k + 1 < n[2]; ++k) {
    for (int j = 0; j + 1 < n[1]; ++j) {
      for (int i = 0; i + 1 < n[0]; ++i) {
        std::array<Point3, 8> x;
        for (int c = 0; c < 8; ++c) x[c] = At(b, i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1));
        double longest = 0.0;
        for (int c = 0; c < 8; ++c) {
          for (int bit : {1, 2, 4}) longest = std::max(longest, Norm(Sub(x[c | bit], x[c & ~bit])));
        }
        for (int c = 0; c < 8; ++c) {
          const Point3 ei = Sub(x[c | 1], x[c & ~1]), ej = Sub(x[c | 2], x[c & ~2]),
                       ek = Sub(x[c | 4], x[c & ~4]);
          const double len = Norm(ei) * Norm(ej) * Norm(ek);
          if (std::min({Norm(ei), Norm(ej), Norm(ek)}) <= 1e-9 * longest) {
            ++out.skipped_corners;
            continue;
          }
          out.min_scaled_jacobian =
              std::min(out.min_scaled_jacobian, side * Dot(ei, Cross(ej, ek)) / len);
        }
        out.min_relative_volume = std::min(
            out.min_relative_volume, side * HexahedronVolume(x) / (longest * longest * longest));
      }
    }
  }
  return out;
}

// Largest | |P(i, j, 1) - P(i, j, 0)| / first_height - 1 |.
double FirstHeightError(const StructuredBlock& b, double first_height) {
  double worst = 0.0;
  for (int j = 0; j < b.extent(1); ++j) {
    for (int i = 0; i < b.extent(0); ++i) {
      const double h = Norm(Sub(At(b, i, j, 1), At(b, i, j, 0)));
      worst = std::max(worst, std::abs(h / first_height - 1.0));
    }
  }
  return worst;
}

// Largest | |P(i, j, k)| - expected[k] | over the block, for a sphere about the origin.
double RadiusError(const StructuredBlock& b, const std::vector<double>& expected) {
  double worst = 0.0;
  for (int k = 0; k < b.extent(2); ++k) {
    for (int j = 0; j < b.extent(1); ++j) {
      for (int i = 0; i < b.extent(0); ++i) {
        worst = std::max(worst, std::abs(Norm(At(b, i, j, k)) - expected[k]));
      }
    }
  }
  return worst;
}

// Radius of layer k on a sphere of radius r0 offset by `sign` (+1 out, -1 in) with `steps`.
std::vector<double> StackedRadii(double r0, const std::vector<double>& steps, int sign) {
  std::vector<double> radii = {r0};
  for (double h : steps) radii.push_back(radii.back() + sign * h);
  return radii;
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// A tilted plane through `origin` spanned by a, b (normal a x b), unevenly spaced.
StructuredBlock TiltedPlane(const Point3& origin, const Point3& a, const Point3& b) {
  StructuredBlock plane({9, 7, 1}, 3);
  for (int j = 0; j < 7; ++j) {
    for (int i = 0; i < 9; ++i) {
      const double s = std::pow(i / 8.0, 1.5), t = j / 6.0 + 0.05 * std::sin(3.0 * i);
      double* x = plane.Point(i, j, 0);
      for (int c = 0; c < 3; ++c) x[c] = origin[c] + s * a[c] + t * b[c];
    }
  }
  return plane;
}

class SurfaceOffsetPlaneTest : public testing::TestWithParam<int> {};

TEST_P(SurfaceOffsetPlaneTest, LayersAreExactlyAtTheStackedHeights) {
  const int side = GetParam();
  const Point3 origin = {0.3, -1.2, 0.7}, a = {1.0, 0.2, -0.3}, b = {-0.1, 0.8, 0.4};
  const StructuredBlock plane = TiltedPlane(origin, a, b);
  const Point3 c = Cross(a, b);
  const Point3 normal = {c[0] / Norm(c), c[1] / Norm(c), c[2] / Norm(c)};
  SurfaceOffsetOptions options;
  options.layers = 12;
  options.first_height = 0.01;
  options.distance = 1.5;
  options.side = side;
  const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurface(plane, options);
  ASSERT_TRUE(grid.ok()) << grid.status();
  ASSERT_EQ(grid->blocks[0].extents(), Extents({9, 7, 13}));
  ASSERT_EQ(grid->steps.size(), 12u);
  EXPECT_NEAR(grid->steps.front(), 0.01, kPlaneTol);
  double height = 0.0;
  for (int k = 0; k <= 12; ++k) {
    for (int j = 0; j < 7; ++j) {
      for (int i = 0; i < 9; ++i) {
        EXPECT_NEAR(Dot(Sub(At(grid->blocks[0], i, j, k), origin), normal), side * height,
                    kPlaneTol)
            << "point (" << i << ", " << j << ", " << k << ")";
      }
    }
    if (k < 12) height += grid->steps[k];
  }
  EXPECT_NEAR(height, 1.5, kPlaneTol);
  EXPECT_EQ(grid->limited_steps, 0);
  EXPECT_EQ(grid->shortfall, 0.0);
  // Handedness: det[x_i, x_j, x_k] has the sign of `side` at every corner.
  const CellSigns signs = CheckCells(grid->blocks[0], side);
  EXPECT_GT(signs.min_scaled_jacobian, 0.0);
  EXPECT_GT(signs.min_relative_volume, 0.0);
  EXPECT_EQ(signs.skipped_corners, 0);
  EXPECT_LT(CheckCells(grid->blocks[0], -side).min_scaled_jacobian, 0.0);
  EXPECT_NEAR(grid->min_scaled_jacobian, signs.min_scaled_jacobian, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(BothSides, SurfaceOffsetPlaneTest, testing::Values(+1, -1));

TEST(SurfaceOffsetTest, SphereBlocksOutwardStayAtTheStackedRadius) {
  const MultiBlockGrid sphere = ReadShared("surfaces/even_sphere.fmt");
  ASSERT_EQ(sphere.blocks.size(), 6u);
  SurfaceOffsetOptions options;
  options.layers = 32;
  options.first_height = 1e-3;
  options.distance = 0.5;
  for (size_t n = 0; n < sphere.blocks.size(); ++n) {
    SCOPED_TRACE(testing::Message() << "block " << n);
    const auto start = std::chrono::steady_clock::now();
    const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurface(sphere.blocks[n], options);
    const double seconds = Seconds(start);
    ASSERT_TRUE(grid.ok()) << grid.status();
    // The shared blocks' normals point outward.
    const double radius_error = RadiusError(grid->blocks[0], StackedRadii(1.0, grid->steps, +1));
    const double first_error = FirstHeightError(grid->blocks[0], options.first_height);
    const CellSigns signs = CheckCells(grid->blocks[0], +1);
    EXPECT_LT(radius_error, kRadiusRelTol * options.distance);
    EXPECT_LT(first_error, kFirstHeightRelTol);
    EXPECT_GT(signs.min_scaled_jacobian, 0.0);
    EXPECT_GT(signs.min_relative_volume, 0.0);
    EXPECT_EQ(grid->limited_steps, 0);  // convex: nothing to limit
    std::cout << "sphere block " << n << " outward: radius error "
              << radius_error / options.distance << " of the distance, first layer error "
              << first_error << ", min scaled Jacobian " << signs.min_scaled_jacobian
              << ", retries " << grid->retries << ", " << seconds << " s\n";
  }
}

TEST(SurfaceOffsetTest, SphereBlockInwardWithinReachStaysAtTheStackedRadius) {
  const MultiBlockGrid sphere = ReadShared("surfaces/even_sphere.fmt");
  ASSERT_FALSE(sphere.blocks.empty());
  SurfaceOffsetOptions options;
  options.layers = 32;
  options.first_height = 1e-3;
  options.distance = 0.5;
  options.side = -1;
  const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurface(sphere.blocks[0], options);
  ASSERT_TRUE(grid.ok()) << grid.status();
  const double radius_error = RadiusError(grid->blocks[0], StackedRadii(1.0, grid->steps, -1));
  EXPECT_LT(radius_error, kRadiusRelTol * options.distance);
  EXPECT_LT(FirstHeightError(grid->blocks[0], options.first_height), kFirstHeightRelTol);
  const CellSigns signs = CheckCells(grid->blocks[0], -1);
  EXPECT_GT(signs.min_scaled_jacobian, 0.0);
  EXPECT_GT(signs.min_relative_volume, 0.0);
  EXPECT_LE(grid->shortfall, options.max_shortfall * options.distance);
  std::cout << "sphere block 0 inward 0.5: radius error " << radius_error / options.distance
            << " of the distance, limited steps " << grid->limited_steps << ", min scaled Jacobian "
            << signs.min_scaled_jacobian << "\n";
}

// Layer after layer, every point of a sphere block offset inward moves towards the centre
// and keeps more than 1 - ratio of the radius it had (the curvature limit, with 5% slack for
// curvature measured on the fitted layer), never reaching the centre.
void ExpectApproachesTheCentre(const StructuredBlock& b, double ratio) {
  for (int k = 1; k < b.extent(2); ++k) {
    for (int j = 0; j < b.extent(1); ++j) {
      for (int i = 0; i < b.extent(0); ++i) {
        const double before = Norm(At(b, i, j, k - 1)), now = Norm(At(b, i, j, k));
        ASSERT_LT(now, before) << "point (" << i << ", " << j << ", " << k << ")";
        ASSERT_GT(now, (1.0 - 1.05 * ratio) * before)
            << "point (" << i << ", " << j << ", " << k << ")";
      }
    }
  }
}

TEST(SurfaceOffsetTest, SphereBlockInwardPastTheCentreIsRefused) {
  const MultiBlockGrid sphere = ReadShared("surfaces/even_sphere.fmt");
  ASSERT_FALSE(sphere.blocks.empty());
  SurfaceOffsetOptions options;
  options.layers = 24;
  options.first_height = 0.01;
  options.distance = 1.5;  // the centre is at 1
  options.side = -1;
  const absl::StatusOr<SurfaceOffsetGrid> refused = OffsetSurface(sphere.blocks[0], options);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(refused.status().message(),
              HasSubstr("distance = 1.5 cannot be reached on the concave side"));
  EXPECT_THAT(refused.status().message(), HasSubstr("max_curvature_step = 0.5"));
  EXPECT_THAT(refused.status().message(), HasSubstr("max_shortfall = 0.01"));
}

TEST(SurfaceOffsetTest, SphereBlockInwardIsCurvatureLimitedNearTheCentre) {
  const MultiBlockGrid sphere = ReadShared("surfaces/even_sphere.fmt");
  ASSERT_FALSE(sphere.blocks.empty());
  SurfaceOffsetOptions options;
  options.layers = 12;
  options.first_height = 0.05;
  options.distance = 0.9;  // the last steps would cross half the radius left
  options.side = -1;
  options.normal_smoothing = 10;  // more sweeps make the normals converge less
  EXPECT_EQ(OffsetSurface(sphere.blocks[0], options).status().code(),
            absl::StatusCode::kFailedPrecondition);
  options.max_shortfall = 0.1;
  const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurface(sphere.blocks[0], options);
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_GT(grid->limited_steps, 0);
  EXPECT_GT(grid->shortfall, 0.01 * options.distance);
  EXPECT_LE(grid->shortfall, options.max_shortfall * options.distance);
  ExpectApproachesTheCentre(grid->blocks[0], options.max_curvature_step);
  const CellSigns signs = CheckCells(grid->blocks[0], -1);
  EXPECT_GT(signs.min_scaled_jacobian, 0.0);
  EXPECT_GT(signs.min_relative_volume, 0.0);
  std::cout << "sphere block 0 inward 0.9: shortfall " << grid->shortfall << ", limited steps "
            << grid->limited_steps << ", innermost radius "
            << Norm(At(grid->blocks[0], 2, 2, options.layers)) << ", min scaled Jacobian "
            << signs.min_scaled_jacobian << "\n";
}

TEST(SurfaceOffsetTest, PolarCapKeepsItsCollapsedEdgeOnePointOnTheAxis) {
  // Latitude-longitude cap of the unit sphere: i = 0 is the pole (the whole edge one point).
  StructuredBlock cap({9, 7, 1}, 3);
  for (int j = 0; j < 7; ++j) {
    for (int i = 0; i < 9; ++i) {
      const double theta = (kPi / 3.0) * i / 8.0, phi = (kPi / 2.0) * j / 6.0;
      double* x = cap.Point(i, j, 0);
      x[0] = std::sin(theta) * std::cos(phi);
      x[1] = std::sin(theta) * std::sin(phi);
      x[2] = std::cos(theta);
    }
  }
  SurfaceOffsetOptions options;
  options.layers = 20;
  options.first_height = 2e-3;
  options.distance = 0.4;
  // The rim (z = 0.5, the cap above it, normals 30 degrees out of the plane) would pass for a
  // symmetry plane, as a swept wing's root does; here it is a cut.
  options.symmetry_planes = false;
  const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurface(cap, options);
  ASSERT_TRUE(grid.ok()) << grid.status();
  const StructuredBlock& b = grid->blocks[0];
  const std::vector<double> radii = StackedRadii(1.0, grid->steps, +1);
  for (int k = 0; k < b.extent(2); ++k) {
    for (int j = 1; j < b.extent(1); ++j) {
      EXPECT_EQ(At(b, 0, j, k), At(b, 0, 0, k)) << "layer " << k << ", pole point " << j;
    }
    const Point3 pole = At(b, 0, 0, k);
    EXPECT_NEAR(pole[2], radii[k], kRadiusRelTol * options.distance) << "layer " << k;
    EXPECT_NEAR(std::hypot(pole[0], pole[1]), 0.0, kRadiusRelTol * options.distance)
        << "layer " << k;
  }
  EXPECT_LT(RadiusError(b, radii), kRadiusRelTol * options.distance);
  EXPECT_LT(FirstHeightError(b, options.first_height), kFirstHeightRelTol);
  const CellSigns signs = CheckCells(b, +1);
  EXPECT_GT(signs.min_scaled_jacobian, 0.0);
  EXPECT_GT(signs.min_relative_volume, 0.0);
  std::cout << "polar cap: radius error " << RadiusError(b, radii) / options.distance
            << " of the distance, min scaled Jacobian " << signs.min_scaled_jacobian << "\n";
  // Exactly the corners on the pole are skipped: two per cell touching it.
  EXPECT_EQ(signs.skipped_corners, 2 * 2 * (b.extent(1) - 1) * (b.extent(2) - 1));
}

// Every point pair that a match of the surface's connectivity joins is one point in every layer
// of the volume blocks (bitwise: the marcher moves each shared vertex once); the number of
// pairs checked.
int64_t ExpectWatertight(const Connectivity& connectivity, const SurfaceOffsetGrid& grid) {
  int64_t pairs = 0;
  for (const BoundaryMatch& match : connectivity.matches) {
    const StructuredBlock& a = grid.blocks[match.a.face.block];
    const StructuredBlock& b = grid.blocks[match.b.face.block];
    for (int j = match.a.begin[1]; j <= match.a.end[1]; ++j) {
      for (int i = match.a.begin[0]; i <= match.a.end[0]; ++i) {
        const Extents y = match.MapToB({i, j, 0});
        for (int k = 0; k < a.extent(2); ++k) {
          EXPECT_EQ(At(a, i, j, k), At(b, y[0], y[1], k)) << match.Describe() << " layer " << k;
          ++pairs;
        }
      }
    }
  }
  return pairs;
}

TEST(SurfaceOffsetTest, SphereOfSixBlocksOutwardIsWatertightAtTheStackedRadius) {
  MultiBlockGrid sphere = ReadShared("surfaces/even_sphere.fmt");
  ASSERT_EQ(sphere.blocks.size(), 6u);
  // Block 2 turned back to front: its normals point inwards, and the orientation must notice.
  StructuredBlock& flipped = sphere.blocks[2];
  StructuredBlock turned = flipped;
  for (int j = 0; j < flipped.extent(1); ++j) {
    for (int i = 0; i < flipped.extent(0); ++i) {
      const double* x = flipped.Point(flipped.extent(0) - 1 - i, j, 0);
      std::copy(x, x + 3, turned.Point(i, j, 0));
    }
  }
  flipped = turned;
  const absl::StatusOr<Connectivity> connectivity = FindConnectivity(sphere);
  ASSERT_TRUE(connectivity.ok()) << connectivity.status();
  SurfaceOffsetOptions options;
  options.layers = 16;
  options.first_height = 0.01;
  options.distance = 1.0;
  options.outward = true;
  const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurfaceGrid(sphere, *connectivity, options);
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_EQ(grid->components, 1);
  EXPECT_TRUE(grid->symmetry_planes.empty());
  const std::vector<double> radii = StackedRadii(1.0, grid->steps, +1);
  for (int b = 0; b < 6; ++b) {
    SCOPED_TRACE(testing::Message() << "block " << b);
    // The blocks are cube faces seen from outside, all alike but the turned one.
    EXPECT_EQ(grid->sides[b], b == 2 ? -grid->sides[0] : grid->sides[0]);
    EXPECT_LT(RadiusError(grid->blocks[b], radii), kRadiusRelTol * options.distance);
    const CellSigns signs = CheckCells(grid->blocks[b], grid->sides[b]);
    EXPECT_GT(signs.min_scaled_jacobian, 0.0);
    EXPECT_GT(signs.min_relative_volume, 0.0);
  }
  EXPECT_GT(ExpectWatertight(*connectivity, *grid), 0);
}

TEST(SurfaceOffsetTest, M6WingToTheFarFieldIsWatertightAndPositive) {
  const MultiBlockGrid m6 = ReadShared("surfaces/m6_small.fmt");
  ASSERT_EQ(m6.blocks.size(), 9u);
  const absl::StatusOr<Connectivity> connectivity = FindConnectivity(m6);
  ASSERT_TRUE(connectivity.ok()) << connectivity.status();
  SurfaceOffsetOptions options;
  options.layers = 32;
  options.first_height = 1e-4;
  options.distance = 5.0;  // about 7 root chords
  options.outward = true;
  const auto start = std::chrono::steady_clock::now();
  const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurfaceGrid(m6, *connectivity, options);
  const double seconds = Seconds(start);
  ASSERT_TRUE(grid.ok()) << grid.status();
  // The root is on z = 0, the only symmetry plane; the tip is closed.
  ASSERT_EQ(grid->symmetry_planes.size(), 1u);
  EXPECT_EQ(grid->symmetry_planes[0].axis, 2);
  EXPECT_EQ(grid->symmetry_planes[0].value, 0.0);
  double worst_first = 0.0, worst_jacobian = 1.0;
  int64_t root_points = 0;
  for (int b = 0; b < 9; ++b) {
    SCOPED_TRACE(testing::Message() << "block " << b);
    const StructuredBlock& block = grid->blocks[b];
    ASSERT_EQ(block.extent(2), options.layers + 1);
    const CellSigns signs = CheckCells(block, grid->sides[b]);
    EXPECT_GT(signs.min_scaled_jacobian, 0.0);  // the tip blocks 4, 5 and 8 included
    EXPECT_GT(signs.min_relative_volume, 0.0);
    worst_jacobian = std::min(worst_jacobian, signs.min_scaled_jacobian);
    worst_first = std::max(worst_first, FirstHeightError(block, options.first_height));
    // Points of the root stay on it in every layer.
    for (int j = 0; j < block.extent(1); ++j) {
      for (int i = 0; i < block.extent(0); ++i) {
        if (At(block, i, j, 0)[2] != 0.0) continue;
        ++root_points;
        for (int k = 0; k < block.extent(2); ++k) EXPECT_EQ(At(block, i, j, k)[2], 0.0);
      }
    }
  }
  EXPECT_LT(worst_first, kFirstHeightRelTol);
  EXPECT_EQ(root_points, 17 + 73 + 17 + 73);  // the root edges of blocks 0-3
  // The outermost layer is about `distance` from the wing (measured: 0.96 to 1.0 of it):
  // every 7th of its points is farther than 0.9 of it from every surface point.
  double nearest = HUGE_VAL;
  for (const StructuredBlock& block : grid->blocks) {
    for (int64_t q = 0; q < block.extent(0) * block.extent(1); q += 7) {
      const Point3 outer = At(block, q % block.extent(0), q / block.extent(0), options.layers);
      for (const StructuredBlock& wall : m6.blocks) {
        for (int64_t w = 0; w < wall.num_points(); ++w) {
          nearest = std::min(nearest,
                             Norm(Sub(outer, At(wall, w % wall.extent(0), w / wall.extent(0), 0))));
        }
      }
    }
  }
  EXPECT_GT(nearest, 0.9 * options.distance);
  const int64_t pairs = ExpectWatertight(*connectivity, *grid);
  std::cout << "m6 to 5: " << pairs << " shared point pairs over all layers, outer layer "
            << nearest << " from the wing, first layer error " << worst_first
            << ", min scaled Jacobian " << worst_jacobian << ", retries " << grid->retries << ", "
            << seconds << " s\n";
}

// Distance of x inside the wedge from the nearer of its two faces' planes.
double DistanceFromWedge(const Point3& x, double degrees) {
  const double a = degrees * kPi / 180.0;
  return std::min(x[2], std::sin(a) * x[0] - std::cos(a) * x[2]);
}

// The crease tests' march: `layers` from 1e-3 to `distance`, no symmetry planes (the wedges'
// free edges lie on y = 0 and y = 1).
SurfaceOffsetOptions CreaseMarch(int layers, double distance) {
  SurfaceOffsetOptions options;
  options.layers = layers;
  options.first_height = 1e-3;
  options.distance = distance;
  options.symmetry_planes = false;
  return options;
}

TEST(SurfaceOffsetTest, RightAngleCreaseConvexSideFansOut) {
  const MultiBlockGrid l = Wedge(90.0);
  const absl::StatusOr<Connectivity> connectivity = FindConnectivity(l);
  ASSERT_TRUE(connectivity.ok());
  ASSERT_EQ(connectivity->matches.size(), 1u);
  SurfaceOffsetOptions options = CreaseMarch(16, 0.3);
  options.side = -1;  // away from the inside of the L: the convex side
  const absl::StatusOr<SurfaceOffsetGrid> convex = OffsetSurfaceGrid(l, *connectivity, options);
  ASSERT_TRUE(convex.ok()) << convex.status();
  EXPECT_EQ(convex->crease_vertices, 0);
  for (int b = 0; b < 2; ++b) {
    EXPECT_GT(CheckCells(convex->blocks[b], convex->sides[b]).min_scaled_jacobian, 0.0);
  }
  EXPECT_GT(ExpectWatertight(*connectivity, *convex), 0);
}

// Inside a wedge (a junction) every layer stays at its height above both faces, the crease on
// the bisector and the faces' points near it moved along their face, away from the crease; no
// cell folds, and the smallest corner is the half opening at the crease (measured: 1e-13 of the
// height, scaled Jacobians sin(opening / 2) for 45-150 degrees). Before the crease treatment the
// right angle folded at layer 12-15 of 16.
class ConcaveCreaseTest : public ::testing::TestWithParam<double> {};

TEST_P(ConcaveCreaseTest, EveryLayerStaysAtItsHeightAboveBothFaces) {
  const double degrees = GetParam();
  const MultiBlockGrid wedge = Wedge(degrees);
  const absl::StatusOr<Connectivity> connectivity = FindConnectivity(wedge);
  ASSERT_TRUE(connectivity.ok());
  const SurfaceOffsetOptions options = CreaseMarch(16, 0.3);
  const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurfaceGrid(wedge, *connectivity, options);
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_EQ(grid->crease_vertices, 33);
  double min_jacobian = 1.0;
  for (int b = 0; b < 2; ++b) {
    const CellSigns signs = CheckCells(grid->blocks[b], grid->sides[b]);
    EXPECT_GT(signs.min_scaled_jacobian, 0.99 * std::sin(degrees * kPi / 360.0)) << "block " << b;
    min_jacobian = std::min(min_jacobian, signs.min_scaled_jacobian);
  }
  const double a = degrees * kPi / 180.0;
  double height = 0.0, worst = 0.0;
  for (int k = 1; k <= options.layers; ++k) {
    height += grid->steps[k - 1];
    for (int b = 0; b < 2; ++b) {
      const StructuredBlock& block = grid->blocks[b];
      for (int j = 0; j < 33; ++j) {
        for (int i = 0; i < 33; ++i) {
          const double d = DistanceFromWedge(At(block, i, j, k), degrees);
          worst = std::max(worst, std::abs(d - height) / height);
          ASSERT_NEAR(d, height, 1e-9 * height)
              << "block " << b << " (" << i << ", " << j << ", " << k << ")";
        }
      }
      // The crease (block 0's i = 0) on the bisector, at the height above both faces.
      const Point3 crease = At(grid->blocks[0], 0, 16, k);
      EXPECT_NEAR(crease[2], height, 1e-12);
      EXPECT_NEAR(std::sin(a) * crease[0] - std::cos(a) * crease[2], height, 1e-12);
    }
  }
  EXPECT_GT(ExpectWatertight(*connectivity, *grid), 0);
  std::cout << degrees << " degrees: layers within " << worst
            << " of their height, min scaled Jacobian " << min_jacobian << "\n";
}

INSTANTIATE_TEST_SUITE_P(Openings, ConcaveCreaseTest,
                         ::testing::Values(45.0, 60.0, 90.0, 120.0, 150.0),
                         [](const ::testing::TestParamInfo<double>& info) {
                           return "opening_" + std::to_string(static_cast<int>(info.param));
                         });

// The same wedges as one block kinked along a grid line: the kink is found (the layers' splines
// are C0 there) and marched as the crease between two blocks is, to the same figures: every layer
// at its height above both faces, the crease on the bisector, the smallest corner the half
// opening. Before, the right angle folded at layer 15 of 16 ("cell (31, 0)").
TEST_P(ConcaveCreaseTest, ACreaseInsideOneBlockIsMarchedLikeOneBetweenBlocks) {
  const double degrees = GetParam();
  const MultiBlockGrid wedge = FoldedWedge(degrees);
  const SurfaceOffsetOptions options = CreaseMarch(16, 0.3);
  const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurface(wedge.blocks[0], options);
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_EQ(grid->crease_vertices, 33);
  EXPECT_GT(CheckCells(grid->blocks[0], grid->sides[0]).min_scaled_jacobian,
            0.99 * std::sin(degrees * kPi / 360.0));
  const double a = degrees * kPi / 180.0;
  double height = 0.0, worst = 0.0;
  for (int k = 1; k <= options.layers; ++k) {
    height += grid->steps[k - 1];
    for (int j = 0; j < 33; ++j) {
      for (int i = 0; i < 65; ++i) {
        const double d = DistanceFromWedge(At(grid->blocks[0], i, j, k), degrees);
        worst = std::max(worst, std::abs(d - height) / height);
        ASSERT_NEAR(d, height, 1e-9 * height) << "(" << i << ", " << j << ", " << k << ")";
      }
    }
    const Point3 crease = At(grid->blocks[0], 32, 16, k);
    EXPECT_NEAR(crease[2], height, 1e-12);
    EXPECT_NEAR(std::sin(a) * crease[0] - std::cos(a) * crease[2], height, 1e-12);
  }
  std::cout << degrees << " degrees in one block: layers within " << worst << " of their height\n";
}

// On its convex side the kinked block fans out as the two blocks do: the kink's points move
// along the mean of both faces' normals, the bisector (measured: scaled Jacobian sin 45 as
// before the kinks were found; with the C0 spline's one-sided normal instead, 0.55 and the
// edge pulled towards one face).
TEST(SurfaceOffsetTest, AKinkInsideOneBlockFansOutOnItsConvexSide) {
  const MultiBlockGrid l = FoldedWedge(90.0);
  SurfaceOffsetOptions options = CreaseMarch(16, 0.3);
  options.side = -1;
  const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurface(l.blocks[0], options);
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_EQ(grid->crease_vertices, 0);
  EXPECT_GT(CheckCells(grid->blocks[0], grid->sides[0]).min_scaled_jacobian, 0.99 * std::sqrt(0.5));
  for (int k = 1; k <= options.layers; ++k) {
    const Point3 edge = At(grid->blocks[0], 32, 16, k);
    EXPECT_LT(edge[0], 0.0) << k;
    EXPECT_NEAR(edge[0], edge[2], 1e-12) << k;
  }
}

// The inside corner of a box: three unit squares on the planes x = 0, y = 0 and z = 0 meet at
// the origin, where three concave creases meet. The corner goes to (H, H, H), the creases' points
// near it slide along their crease away from it, so every layer stays H above the nearest face:
// min(x, y, z) = H, to 0.3 and to 1.0 (the faces' length). Before, the creases' points were not
// moved along their crease and layer 1 folded at the corner cell (refused).
class InsideCornerTest : public ::testing::TestWithParam<double> {};

TEST_P(InsideCornerTest, EveryLayerStaysAtItsHeightAboveTheNearestFace) {
  const double distance = GetParam();
  MultiBlockGrid corner;
  for (int axis = 0; axis < 3; ++axis) {
    StructuredBlock block({17, 17, 1}, 3);
    for (int j = 0; j < 17; ++j) {
      for (int i = 0; i < 17; ++i) {
        double* x = block.Point(i, j, 0);
        x[axis] = 0.0;
        x[(axis + 1) % 3] = i / 16.0;
        x[(axis + 2) % 3] = j / 16.0;
      }
    }
    corner.blocks.push_back(std::move(block));
  }
  const absl::StatusOr<Connectivity> connectivity = FindConnectivity(corner);
  ASSERT_TRUE(connectivity.ok());
  ASSERT_EQ(connectivity->matches.size(), 3u);
  const SurfaceOffsetOptions options = CreaseMarch(16, distance);
  const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurfaceGrid(corner, *connectivity, options);
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_EQ(grid->crease_vertices, 3 * 16 + 1);
  double min_jacobian = 1.0;
  for (int b = 0; b < 3; ++b) {
    const CellSigns signs = CheckCells(grid->blocks[b], grid->sides[b]);
    EXPECT_GT(signs.min_relative_volume, 0.0) << "block " << b;
    min_jacobian = std::min(min_jacobian, signs.min_scaled_jacobian);
  }
  double height = 0.0, worst = 0.0;
  for (int k = 1; k <= options.layers; ++k) {
    height += grid->steps[k - 1];
    for (int b = 0; b < 3; ++b) {
      for (int j = 0; j < 17; ++j) {
        for (int i = 0; i < 17; ++i) {
          const Point3 x = At(grid->blocks[b], i, j, k);
          const double d = std::min({x[0], x[1], x[2]});
          worst = std::max(worst, std::abs(d - height) / height);
        }
      }
    }
    const Point3 apex = At(grid->blocks[0], 0, 0, k);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(apex[c], height, 1e-12) << "layer " << k;
  }
  EXPECT_LT(worst, 1e-9);
  // Measured: 0.41 to 0.3, 0.22 to 1.0 (the cells along the creases near the corner, squeezed
  // along the crease as the corner's slide decays).
  EXPECT_GT(min_jacobian, distance < 0.5 ? 0.35 : 0.2);
  EXPECT_GT(ExpectWatertight(*connectivity, *grid), 0);
  std::cout << "inside corner: layers within " << worst << " of their height, min scaled Jacobian "
            << min_jacobian << "\n";
}

INSTANTIATE_TEST_SUITE_P(Distances, InsideCornerTest, ::testing::Values(0.3, 1.0),
                         [](const ::testing::TestParamInfo<double>& info) {
                           return info.param < 0.5 ? "to_0_3" : "to_the_faces_length";
                         });

// A quarter of a band of the unit sphere: phi in [0, pi/2] (i), z from 0 up to a wavy top edge
// (j). Its edges phi = 0, phi = pi/2 and z = 0 lie on the planes y = 0, x = 0 and z = 0; the
// corners at z = 0 lie on two planes each and must stay on both.
TEST(SurfaceOffsetTest, CornersOnTwoSymmetryPlanesStayOnBoth) {
  StructuredBlock band({17, 9, 1}, 3);
  for (int j = 0; j < 9; ++j) {
    for (int i = 0; i < 17; ++i) {
      const double phi = (kPi / 2.0) * i / 16.0;
      const double z = (0.5 + 0.1 * std::sin(2.0 * phi)) * j / 8.0;
      const double r = std::sqrt(1.0 - z * z);
      double* x = band.Point(i, j, 0);
      x[0] = r * std::cos(phi);
      x[1] = r * std::sin(phi);
      x[2] = z;
    }
  }
  SurfaceOffsetOptions options;
  options.layers = 12;
  options.first_height = 0.01;
  options.distance = 0.5;
  options.outward = true;
  const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurface(band, options);
  ASSERT_TRUE(grid.ok()) << grid.status();
  ASSERT_EQ(grid->symmetry_planes.size(), 3u);
  const StructuredBlock& b = grid->blocks[0];
  EXPECT_GT(CheckCells(b, grid->sides[0]).min_scaled_jacobian, 0.0);
  for (int k = 0; k < b.extent(2); ++k) {
    for (int j = 0; j < b.extent(1); ++j) {
      EXPECT_EQ(At(b, 0, j, k)[1], 0.0) << "phi = 0, layer " << k;
      EXPECT_NEAR(At(b, 16, j, k)[0], 0.0, 1e-16) << "phi = pi/2 (cos = 6e-17), layer " << k;
    }
    for (int i = 0; i < b.extent(0); ++i) EXPECT_EQ(At(b, i, 0, k)[2], 0.0) << "z = 0, layer " << k;
  }
}

// A Moebius strip: its seam matches itself back to front, so no side is outward or along.
TEST(SurfaceOffsetTest, AMoebiusStripCannotBeOriented) {
  StructuredBlock strip({41, 5, 1}, 3);
  for (int j = 0; j < 5; ++j) {
    for (int i = 0; i < 41; ++i) {
      const double u = 2.0 * kPi * i / 40.0, v = -0.3 + 0.6 * j / 4.0;
      double* x = strip.Point(i, j, 0);
      x[0] = (1.0 + 0.5 * v * std::cos(u / 2.0)) * std::cos(u);
      x[1] = (1.0 + 0.5 * v * std::cos(u / 2.0)) * std::sin(u);
      x[2] = 0.5 * v * std::sin(u / 2.0);
    }
  }
  const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurface(strip, SurfaceOffsetOptions{});
  EXPECT_EQ(grid.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(grid.status().message(), HasSubstr("cannot be oriented alike"));
}

TEST(SurfaceOffsetTest, AConnectivityOfAnotherGridIsRefused) {
  const MultiBlockGrid l = Wedge(90.0);
  const MultiBlockGrid m6 = ReadShared("surfaces/m6_small.fmt");
  const absl::StatusOr<Connectivity> other = FindConnectivity(m6);
  ASSERT_TRUE(other.ok());
  const absl::StatusOr<SurfaceOffsetGrid> grid =
      OffsetSurfaceGrid(l, *other, SurfaceOffsetOptions{});
  EXPECT_EQ(grid.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(grid.status().message(), HasSubstr("does not fit the surface's blocks"));
}

TEST(SurfaceOffsetTest, OutwardNeedsAnEnclosedVolume) {
  MultiBlockGrid plane;
  plane.blocks.push_back(TiltedPlane({0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}));
  const absl::StatusOr<Connectivity> connectivity = FindConnectivity(plane);
  ASSERT_TRUE(connectivity.ok());
  SurfaceOffsetOptions options;
  options.outward = true;
  const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurfaceGrid(plane, *connectivity, options);
  EXPECT_EQ(grid.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(grid.status().message(), HasSubstr("enclose no volume"));
}

StructuredBlock SmallPlane() {
  return TiltedPlane({0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0});
}

struct BadOptionsCase {
  std::string field;
  void (*spoil)(SurfaceOffsetOptions&);
};

TEST(SurfaceOffsetTest, BadOptionsNameTheField) {
  const std::vector<BadOptionsCase> cases = {
      {"layers = 0", [](SurfaceOffsetOptions& o) { o.layers = 0; }},
      {"first_height = 0", [](SurfaceOffsetOptions& o) { o.first_height = 0.0; }},
      {"first_height = -1", [](SurfaceOffsetOptions& o) { o.first_height = -1.0; }},
      {"first_height = nan", [](SurfaceOffsetOptions& o) { o.first_height = std::nan(""); }},
      {"distance = -0.5", [](SurfaceOffsetOptions& o) { o.distance = -0.5; }},
      {"distance = nan", [](SurfaceOffsetOptions& o) { o.distance = std::nan(""); }},
      {"distance = 0.01 is below layers x first_height",
       [](SurfaceOffsetOptions& o) { o.distance = 0.01; }},
      {"side = 0", [](SurfaceOffsetOptions& o) { o.side = 0; }},
      {"normal_smoothing = -1", [](SurfaceOffsetOptions& o) { o.normal_smoothing = -1; }},
      {"fairing = -1", [](SurfaceOffsetOptions& o) { o.fairing = -1.0; }},
      {"surface_fairing = inf", [](SurfaceOffsetOptions& o) { o.surface_fairing = HUGE_VAL; }},
      {"max_curvature_step = 1", [](SurfaceOffsetOptions& o) { o.max_curvature_step = 1.0; }},
      {"max_shortfall = 2", [](SurfaceOffsetOptions& o) { o.max_shortfall = 2.0; }},
      {"max_retries = -1", [](SurfaceOffsetOptions& o) { o.max_retries = -1; }},
      {"normal_smoothing = 1001 is outside [0, 1000]",
       [](SurfaceOffsetOptions& o) { o.normal_smoothing = 1001; }},
      {"max_retries = 101", [](SurfaceOffsetOptions& o) { o.max_retries = 101; }},
      {"distance = 1e+300 needs a growth ratio of",
       [](SurfaceOffsetOptions& o) { o.distance = 1e300; }},
      {"layers = 1 with first_height = 0.001 cannot reach distance = 0.5",
       [](SurfaceOffsetOptions& o) { o.layers = 1; }},
  };
  for (const BadOptionsCase& c : cases) {
    SurfaceOffsetOptions options;
    c.spoil(options);
    const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurface(SmallPlane(), options);
    EXPECT_EQ(grid.status().code(), absl::StatusCode::kInvalidArgument) << c.field;
    EXPECT_THAT(grid.status().message(), HasSubstr(c.field));
  }
}

TEST(SurfaceOffsetTest, BadSurfacesAreRejected) {
  StructuredBlock nan_point = SmallPlane();
  nan_point.Point(2, 3, 0)[1] = std::nan("");
  StructuredBlock collapsed({5, 5, 1}, 3);  // all points at the origin
  const std::vector<std::pair<StructuredBlock, std::string>> cases = {
      {StructuredBlock({3, 8, 1}, 3), "surface: 3 x 8 points; at least 4 x 4"},
      {StructuredBlock({8, 3, 1}, 3), "surface: 8 x 3 points; at least 4 x 4"},
      {StructuredBlock({5, 5, 2}, 3), "surface: nk = 2"},
      {StructuredBlock({5, 5, 1}, 2), "surface: spatial_dim = 2"},
      {nan_point, "surface: point (2, 3, 0) coordinate y is nan"},
      {collapsed, "surface: all points coincide"},
  };
  for (const auto& [surface, message] : cases) {
    const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurface(surface, SurfaceOffsetOptions{});
    EXPECT_EQ(grid.status().code(), absl::StatusCode::kInvalidArgument) << message;
    EXPECT_THAT(grid.status().message(), HasSubstr(message));
  }
}

TEST(SurfaceOffsetTest, CancelledBetweenLayers) {
  SurfaceOffsetOptions options;
  int polls = 0;
  options.cancel = [&polls] { return ++polls > 5; };
  const absl::StatusOr<SurfaceOffsetGrid> grid = OffsetSurface(SmallPlane(), options);
  EXPECT_EQ(grid.status().code(), absl::StatusCode::kCancelled);
}

}  // namespace
}  // namespace splinegrid
