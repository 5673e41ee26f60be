// CheckCellQuality: the cell measures against independent oracles, exact and smooth fits (ok),
// deliberately folded, oversized and flipped fits (detected at the right cell), surfaces in any
// two active directions, volumes, collapsed edges, the shared C-grid, errors and cancellation.
#include "core/fit/report/grid_quality.h"

#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/bspline/evaluation.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::Contains;
using ::testing::HasSubstr;

constexpr double kPi = std::numbers::pi;
// Closed-form cell measures against exact quadrature: rounding of a few dozen operations,
// relative to the measure.
constexpr double kMeasureRelTol = 1e-13;
// Fits that reproduce the mapping exactly (polynomial reproduction): ratio 1 up to rounding.
constexpr double kExactRatioTol = 1e-9;

// A block of `n` points with spatial_dim `s` from the mapping f(u, v, w) -> Point3 on the unit
// cube (u = i / (ni - 1), ...; a direction with one point has parameter 0).
template <typename F>
StructuredBlock MakeBlock(const Extents& n, int s, F&& f) {
  StructuredBlock block(n, s);
  auto param = [&](int q, int d) { return n[d] == 1 ? 0.0 : static_cast<double>(q) / (n[d] - 1); };
  for (int k = 0; k < n[2]; ++k) {
    for (int j = 0; j < n[1]; ++j) {
      for (int i = 0; i < n[0]; ++i) {
        const Point3 x = f(param(i, 0), param(j, 1), param(k, 2));
        for (int c = 0; c < s; ++c) block.Point(i, j, k)[c] = x[c];
      }
    }
  }
  return block;
}

FittedBlock Fit(const StructuredBlock& block, const Extents& controls = {0, 0, 0}) {
  FitOptions options;
  options.control_counts = controls;
  absl::StatusOr<FittedBlock> fitted = FitBlock(block, options);
  EXPECT_TRUE(fitted.ok()) << fitted.status();
  return fitted.ok() ? *std::move(fitted) : FittedBlock{};
}

CellQuality Check(const FittedBlock& fitted, const StructuredBlock& block,
                  const CellQualityOptions& options = {}) {
  absl::StatusOr<CellQuality> q = CheckCellQuality(fitted, block, options);
  EXPECT_TRUE(q.ok()) << q.status();
  return q.ok() ? *std::move(q) : CellQuality{};
}

// Total (sub-)cells over levels 0..max_level of a block with `cells` cells in D directions.
int64_t CellsOverLevels(int64_t cells, int num_active, int max_level = 2) {
  int64_t total = 0;
  for (int l = 0; l <= max_level; ++l) total += cells << (l * num_active);
  return total;
}

// One line describing `q`, for failure messages.
std::string Describe(const CellQuality& q) {
  std::ostringstream os;
  os << "checked " << q.cells_checked << " skipped " << q.cells_skipped << " folded " << q.folded
     << " out_of_size " << q.out_of_size << " ratios [" << q.min_ratio << ", " << q.max_ratio
     << "] worst (" << q.worst_cell[0] << ", " << q.worst_cell[1] << ", " << q.worst_cell[2]
     << ") level " << q.worst_level << " bad cells " << q.num_bad_cells;
  return os.str();
}

// Evaluating in chunks of two points in i (the smallest evaluator budget) changes nothing: each
// refined point is evaluated the same way, whatever chunk it is in.
void ExpectSameWithTinyBudget(const FittedBlock& fitted, const StructuredBlock& block,
                              const CellQuality& q) {
  CellQualityOptions tiny;
  tiny.evaluator_budget = 1;
  const CellQuality c = Check(fitted, block, tiny);
  EXPECT_EQ(c.cells_checked, q.cells_checked);
  EXPECT_EQ(c.cells_skipped, q.cells_skipped);
  EXPECT_EQ(c.folded, q.folded);
  EXPECT_EQ(c.out_of_size, q.out_of_size);
  EXPECT_NEAR(c.min_ratio, q.min_ratio, kExactRatioTol);
  EXPECT_NEAR(c.max_ratio, q.max_ratio, kExactRatioTol);
  EXPECT_EQ(c.worst_cell, q.worst_cell);
  EXPECT_EQ(c.bad_cells, q.bad_cells);
}

// ---------------------------------------------------------------------------------------------
// Cell measures.

// The trilinear map of a hexahedron with corners x (binary order) and its Jacobian determinant.
double TrilinearJacobian(const std::array<Point3, 8>& x, double u, double v, double w) {
  double J[3][3] = {};
  for (int n = 0; n < 8; ++n) {
    const double a = n & 1 ? u : 1 - u, b = n & 2 ? v : 1 - v, c = n & 4 ? w : 1 - w;
    const double da = n & 1 ? 1 : -1, db = n & 2 ? 1 : -1, dc = n & 4 ? 1 : -1;
    for (int r = 0; r < 3; ++r) {
      J[r][0] += da * b * c * x[n][r];
      J[r][1] += a * db * c * x[n][r];
      J[r][2] += a * b * dc * x[n][r];
    }
  }
  return J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
         J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
         J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
}

// The volume of the trilinear hexahedron as the integral of det J over the unit cube by 2-point
// Gauss-Legendre per direction: det J has degree <= 2 in each of u, v, w (each column of J is
// bilinear in the other two parameters), and the 2-point rule is exact up to degree 3.
double GaussVolume(const std::array<Point3, 8>& x) {
  const double g[2] = {0.5 - 0.5 / std::sqrt(3.0), 0.5 + 0.5 / std::sqrt(3.0)};
  double sum = 0.0;
  for (double u : g) {
    for (double v : g) {
      for (double w : g) sum += TrilinearJacobian(x, u, v, w) / 8.0;
    }
  }
  return sum;
}

// Signed volume of the tetrahedron a b c d.
double TetVolume(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  const Point3 u = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const Point3 v = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const Point3 w = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
          u[2] * (v[0] * w[1] - v[1] * w[0])) /
         6.0;
}

// The six tetrahedra around the main diagonal from corner c to corner c ^ 7: one per monotone
// edge path c -> c ^ bit p -> ... -> c ^ 7, signed by the parity of the axis order and by the
// reflection n -> n ^ c.
double SixTetVolume(const std::array<Point3, 8>& x, int c) {
  static constexpr int kOrders[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1},
                                        {1, 0, 2}, {0, 2, 1}, {2, 1, 0}};
  double sum = 0.0;
  for (int t = 0; t < 6; ++t) {
    const int v1 = 1 << kOrders[t][0], v2 = v1 | (1 << kOrders[t][1]);
    sum += (t < 3 ? 1 : -1) * TetVolume(x[c], x[v1 ^ c], x[v2 ^ c], x[7 ^ c]);
  }
  const bool mirrored = __builtin_popcount(c) % 2 == 1;
  return mirrored ? -sum : sum;
}

// The unit cube through the affine map y = A x + b.
std::array<Point3, 8> AffineCube(const double A[3][3], const Point3& b) {
  std::array<Point3, 8> x;
  for (int n = 0; n < 8; ++n) {
    const double p[3] = {double(n & 1), double((n >> 1) & 1), double((n >> 2) & 1)};
    for (int r = 0; r < 3; ++r) x[n][r] = b[r] + A[r][0] * p[0] + A[r][1] * p[1] + A[r][2] * p[2];
  }
  return x;
}

TEST(GridQualityMeasureTest, HexahedronVolumeOfCubeShearAndTwist) {
  const double identity[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  EXPECT_NEAR(HexahedronVolume(AffineCube(identity, {0.3, -2, 5})), 1.0, kMeasureRelTol);
  // Sheared and scaled: a parallelepiped, volume det A = 2 * 3 * 0.5.
  const double shear[3][3] = {{2, 0.7, -0.4}, {0, 3, 1.1}, {0, 0, 0.5}};
  EXPECT_NEAR(HexahedronVolume(AffineCube(shear, {1, 1, 1})), 3.0, 3.0 * kMeasureRelTol);
  // Left-handed (mirrored) cube: negative.
  const double mirror[3][3] = {{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  EXPECT_NEAR(HexahedronVolume(AffineCube(mirror, {0, 0, 0})), -1.0, kMeasureRelTol);

  // Twisted: the top face turned by 60 degrees about the vertical axis and one top corner lifted,
  // so the side faces and the top are warped. The straight edges between the turned squares cut
  // the corners: less than the prism's 1.
  std::array<Point3, 8> twisted = AffineCube(identity, {-0.5, -0.5, 0});
  const double c = std::cos(kPi / 3), s = std::sin(kPi / 3);
  for (int n = 4; n < 8; ++n) {
    const Point3 p = twisted[n];
    twisted[n] = {c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]};
  }
  twisted[7][2] += 0.3;
  const double exact = GaussVolume(twisted);
  EXPECT_LT(exact, 1.0);
  EXPECT_NEAR(HexahedronVolume(twisted), exact, kMeasureRelTol);
  // Tetrahedral oracle: one six-tetrahedra decomposition (Grandy's formula alone) splits every
  // warped face along one diagonal and misses the trilinear volume; the mean over the four main
  // diagonals uses both diagonals of every face equally, which is exact.
  double mean = 0.0;
  for (int corner = 0; corner < 4; ++corner) mean += SixTetVolume(twisted, corner) / 4;
  EXPECT_NEAR(mean, exact, kMeasureRelTol);
  EXPECT_GT(std::abs(SixTetVolume(twisted, 0) - exact), 1e-3);

  // Random perturbations of the unit cube (all corners moved, faces warped).
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  for (int trial = 0; trial < 100; ++trial) {
    std::array<Point3, 8> x = AffineCube(identity, {0, 0, 0});
    for (Point3& p : x) {
      for (double& v : p) v += jitter(rng);
    }
    EXPECT_NEAR(HexahedronVolume(x), GaussVolume(x), 4 * kMeasureRelTol) << "trial " << trial;
  }
}

TEST(GridQualityMeasureTest, QuadrilateralAreaAndAreaVector) {
  // Unit square counter-clockwise (corners in binary order: x0 x1 x3 x2 is the boundary).
  const std::array<Point3, 4> square = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}};
  EXPECT_NEAR(PlanarCellArea(square), 1.0, kMeasureRelTol);
  const Point3 a = CellAreaVector(square);
  EXPECT_NEAR(a[2], 1.0, kMeasureRelTol);
  // A non-convex quadrilateral: shoelace over x0 x1 x3 x2 by the explicit formula.
  const std::array<Point3, 4> dart = {{{0, 0, 0}, {2, 0.2, 0}, {-0.3, 1.5, 0}, {0.4, 0.5, 0}}};
  const int ring[4] = {0, 1, 3, 2};
  double shoelace = 0.0;
  for (int e = 0; e < 4; ++e) {
    const Point3& p = dart[ring[e]];
    const Point3& q = dart[ring[(e + 1) % 4]];
    shoelace += 0.5 * (p[0] * q[1] - q[0] * p[1]);
  }
  EXPECT_NEAR(PlanarCellArea(dart), shoelace, kMeasureRelTol);
  // The same quadrilateral rotated into 3D: the area vector is the rotated normal times the area.
  std::array<Point3, 4> rotated;
  for (int n = 0; n < 4; ++n) rotated[n] = {dart[n][0], 0.6 * dart[n][1], 0.8 * dart[n][1]};
  const Point3 r = CellAreaVector(rotated);
  EXPECT_NEAR(r[0], 0.0, kMeasureRelTol);
  EXPECT_NEAR(r[1], -0.8 * shoelace, kMeasureRelTol);
  EXPECT_NEAR(r[2], 0.6 * shoelace, kMeasureRelTol);
}

// ---------------------------------------------------------------------------------------------
// Planar blocks.

// An affine grid with even spacing: chord-length parameters are even, the cubic spline
// reproduces the affine map, and every sub-cell is exactly its parent / 4^l.
TEST(GridQualityPlanarTest, AffineGridGivesRatioOneAtAllLevels) {
  const StructuredBlock block = MakeBlock({9, 7, 1}, 2, [](double u, double v, double) {
    return Point3{3 * u + 0.5 * v, -0.4 * u + 2 * v, 0};
  });
  const CellQuality q = Check(Fit(block), block);
  EXPECT_TRUE(q.ok()) << Describe(q);
  EXPECT_EQ(q.cells_checked, CellsOverLevels(8 * 6, 2));
  EXPECT_EQ(q.cells_skipped, 0);
  EXPECT_NEAR(q.min_ratio, 1.0, kExactRatioTol);
  EXPECT_NEAR(q.max_ratio, 1.0, kExactRatioTol);
}

// A smooth curved mapping, interpolated. Level 0 reproduces the grid (ratio 1); at level l a
// sub-cell's ratio is the mean Jacobian of the mapping over the sub-cell divided by its mean over
// the parent, so it stays within [1 / (1 + d), 1 + d], d = max over cells of J_max / J_min - 1
// (computed below from the analytic Jacobian), plus the interpolation error of the spline and of
// the refined parameters, O(h^2) relative (allowed: kSmoothSlack).
TEST(GridQualityPlanarTest, SmoothGridInterpolatedIsOk) {
  constexpr double kSmoothSlack = 0.02;
  auto f = [](double u, double v, double) {
    return Point3{u + 0.12 * std::sin(kPi * v), v + 0.1 * std::sin(kPi * u) * (1 + u), 0};
  };
  auto jacobian = [](double u, double v) {
    const double xu = 1, xv = 0.12 * kPi * std::cos(kPi * v);
    const double yu = 0.1 * (kPi * std::cos(kPi * u) * (1 + u) + std::sin(kPi * u)), yv = 1;
    return xu * yv - xv * yu;
  };
  const Extents n = {17, 13, 1};
  const StructuredBlock block = MakeBlock(n, 2, f);
  double d = 0.0;
  for (int j = 0; j + 1 < n[1]; ++j) {
    for (int i = 0; i + 1 < n[0]; ++i) {
      double lo = 1e300, hi = 0;
      for (int a = 0; a <= 8; ++a) {
        for (int b = 0; b <= 8; ++b) {
          const double J = jacobian((i + a / 8.0) / (n[0] - 1), (j + b / 8.0) / (n[1] - 1));
          lo = std::min(lo, J);
          hi = std::max(hi, J);
        }
      }
      d = std::max(d, hi / lo - 1);
    }
  }
  const FittedBlock fitted = Fit(block);
  const CellQuality q = Check(fitted, block);
  EXPECT_TRUE(q.ok()) << Describe(q);
  EXPECT_GE(q.min_ratio, 1 / (1 + d) - kSmoothSlack) << Describe(q);
  EXPECT_LE(q.max_ratio, 1 + d + kSmoothSlack) << Describe(q);
  ExpectSameWithTinyBudget(fitted, block, q);
}

// Samples per active direction for JacobianRange: 9 in 2D, 5 in 3D (test time).
int SamplesFor(int num_active) { return num_active == 3 ? 5 : 9; }

// Range of the fitted block's Jacobian over the parameter box of original cell `cell`, sampled
// at `samples` points per active direction (ends included): det(X_u, X_v) for planar blocks,
// (X_u x X_v) . normal for surfaces, det(X_u, X_v, X_w) for volumes. The active directions must
// be the first num_active. An independent oracle for the discrete cell measures.
std::pair<double, double> JacobianRange(const FittedBlock& fitted, const Extents& cell,
                                        int num_active, const Point3& normal, int samples) {
  const PointDistribution& dist = fitted.distribution;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  const int count[3] = {samples, samples, num_active == 3 ? samples : 1};
  for (int c = 0; c < count[2]; ++c) {
    for (int b = 0; b < count[1]; ++b) {
      for (int a = 0; a < count[0]; ++a) {
        const int q[3] = {a, b, c};
        Point3 uvw;
        for (int d = 0; d < 3; ++d) {
          const std::vector<double>& u = dist.params(d);
          uvw[d] = d < num_active
                       ? u[cell[d]] + (u[cell[d] + 1] - u[cell[d]]) * q[d] / (samples - 1)
                       : u[0];
        }
        const PartialDerivatives D = EvaluateDerivatives(fitted.spline, uvw, 1);
        const Point3 &xu = D(1, 0, 0), &xv = D(0, 1, 0), &xw = D(0, 0, 1);
        const Point3 n = {xu[1] * xv[2] - xu[2] * xv[1], xu[2] * xv[0] - xu[0] * xv[2],
                          xu[0] * xv[1] - xu[1] * xv[0]};
        double J;
        if (num_active == 3) {
          J = n[0] * xw[0] + n[1] * xw[1] + n[2] * xw[2];
        } else if (fitted.spline.spatial_dim() == 2) {
          J = n[2];
        } else {
          J = n[0] * normal[0] + n[1] * normal[1] + n[2] * normal[2];
        }
        lo = std::min(lo, J);
        hi = std::max(hi, J);
      }
    }
  }
  return {lo, hi};
}

// Corners of original cell `cell` (active directions first) in binary order.
template <int kCorners>
std::array<Point3, kCorners> OriginalCorners(const StructuredBlock& block, const Extents& cell) {
  std::array<Point3, kCorners> x{};
  for (int n = 0; n < kCorners; ++n) {
    const double* p =
        block.Point(cell[0] + (n & 1), cell[1] + ((n >> 1) & 1), cell[2] + ((n >> 2) & 1));
    for (int c = 0; c < block.spatial_dim(); ++c) x[n][c] = p[c];
  }
  return x;
}

// Every original cell (lower corners) of a block whose active directions are the first D.
std::vector<Extents> AllCells(const StructuredBlock& block) {
  std::vector<Extents> cells;
  const Extents n = block.extents();
  for (int k = 0; k < std::max(1, n[2] - 1); ++k) {
    for (int j = 0; j < n[1] - 1; ++j) {
      for (int i = 0; i < n[0] - 1; ++i) cells.push_back({i, j, k});
    }
  }
  return cells;
}

// d = max over cells of J_max / J_min - 1 of the fitted Jacobian (JacobianRange, surfaces
// projected on the original cell's normal): how unevenly even a perfect refinement splits a cell.
// A sub-cell's ratio is its mean Jacobian over the parent's, within [1 / (1 + d), 1 + d] up to
// the curvature of the cell's edges and the unevenness of the refined parameters.
double JacobianSpread(const FittedBlock& fitted, const StructuredBlock& block, int num_active) {
  double d = 0.0;
  for (const Extents& cell : AllCells(block)) {
    Point3 normal = {0, 0, 1};
    if (num_active == 2 && block.spatial_dim() == 3) {
      normal = CellAreaVector(OriginalCorners<4>(block, cell));
    }
    const auto [lo, hi] = JacobianRange(fitted, cell, num_active, normal, SamplesFor(num_active));
    EXPECT_GT(lo, 0.0);
    d = std::max(d, hi / lo - 1);
  }
  return d;
}

// Whether original cell `cell` overlaps the support of control `control` in every active
// direction: only there can moving that control change the fitted grid.
bool InSupport(const FittedBlock& fitted, const Extents& cell, const Extents& control,
               int num_active) {
  for (int d = 0; d < num_active; ++d) {
    const KnotVector& kv = fitted.spline.knots(d);
    const std::vector<double>& u = fitted.distribution.params(d);
    if (u[cell[d] + 1] <= kv.knot(control[d]) || u[cell[d]] >= kv.knot(control[d] + kv.order())) {
      return false;
    }
  }
  return true;
}

// Checks a fold made by moving `control`: the worst cell has a negative Jacobian, the cell with
// the most negative sampled Jacobian is reported, and every reported cell is in the control's
// support.
void ExpectFoldAt(const FittedBlock& fitted, const StructuredBlock& block, const CellQuality& q,
                  const Extents& control, int num_active) {
  EXPECT_GT(q.folded, 0) << Describe(q);
  EXPECT_LT(q.min_ratio, 0.0) << Describe(q);
  EXPECT_LT(JacobianRange(fitted, q.worst_cell, num_active, {}, SamplesFor(num_active)).first, 0.0)
      << Describe(q);
  Extents most_negative = {0, 0, 0};
  double lowest = std::numeric_limits<double>::infinity();
  for (const Extents& cell : AllCells(block)) {
    const double J = JacobianRange(fitted, cell, num_active, {}, SamplesFor(num_active)).first;
    if (J < lowest) {
      lowest = J;
      most_negative = cell;
    }
  }
  EXPECT_THAT(q.bad_cells, Contains(most_negative)) << Describe(q);
  for (const Extents& cell : q.bad_cells) {
    EXPECT_TRUE(InSupport(fitted, cell, control, num_active))
        << cell[0] << " " << cell[1] << " " << cell[2];
  }
  EXPECT_EQ(q.num_bad_cells, static_cast<int64_t>(q.bad_cells.size()));
}

// The smooth test grid of the fold and size tests: 21 x 17 points on [0, 2] x [0, 1.6].
StructuredBlock EvenPlanarGrid() {
  return MakeBlock({21, 17, 1}, 2, [](double u, double v, double) {
    return Point3{2 * u + 0.1 * v * v, 1.6 * v, 0};
  });
}

TEST(GridQualityPlanarTest, ControlMovedAcrossItsNeighbourIsFolded) {
  const StructuredBlock block = EvenPlanarGrid();
  FittedBlock fitted = Fit(block, {11, 9, 1});
  ASSERT_TRUE(Check(fitted, block).ok());
  // Control (5, 4) moved in x past control (6, 4), by three control spacings.
  const Extents control = {5, 4, 0};
  const Extents nc = fitted.spline.control_extents();
  double* p = fitted.spline.mutable_control().data() + 2 * (control[0] + nc[0] * control[1]);
  p[0] += 3 * (fitted.spline.ControlPoint(6, 4, 0)[0] - p[0]);
  const CellQuality q = Check(fitted, block);
  EXPECT_FALSE(q.ok());
  ExpectFoldAt(fitted, block, q, control, 2);
  // The list is capped, the count is not.
  CellQualityOptions capped;
  capped.max_reported_cells = 1;
  const CellQuality c = Check(fitted, block, capped);
  EXPECT_EQ(c.bad_cells.size(), 1u);
  EXPECT_EQ(c.num_bad_cells, q.num_bad_cells);
}

TEST(GridQualityPlanarTest, ControlMovedOutwardIsOutOfSize) {
  const StructuredBlock block = EvenPlanarGrid();
  FittedBlock fitted = Fit(block, {11, 9, 1});
  // A control of the top edge moved up by three control spacings: the cells below it stretch
  // without folding.
  const Extents nc = fitted.spline.control_extents();
  const Extents control = {5, nc[1] - 1, 0};
  double* p = fitted.spline.mutable_control().data() + 2 * (control[0] + nc[0] * control[1]);
  p[1] += 3 * 1.6 / (nc[1] - 1);
  const CellQuality q = Check(fitted, block);
  EXPECT_FALSE(q.ok());
  EXPECT_GT(q.out_of_size, 0);
  EXPECT_EQ(q.folded, 0);
  EXPECT_GT(q.max_ratio, 2.0);
  ASSERT_FALSE(q.bad_cells.empty());
  for (const Extents& cell : q.bad_cells) EXPECT_TRUE(InSupport(fitted, cell, control, 2));
}

// A quarter disc in polar coordinates: the j = 0 edge collapses to the centre. Its cells are
// triangles whose Jacobian vanishes at the centre; they are skipped, the rest pass.
TEST(GridQualityPlanarTest, CollapsedEdgeCellsAreSkipped) {
  const Extents n = {9, 7, 1};
  const StructuredBlock block = MakeBlock(n, 2, [](double u, double v, double) {
    return Point3{v * std::cos(0.5 * kPi * u), v * std::sin(0.5 * kPi * u), 0};
  });
  const CellQuality q = Check(Fit(block), block);
  EXPECT_TRUE(q.ok()) << Describe(q);
  EXPECT_EQ(q.cells_skipped, CellsOverLevels(n[0] - 1, 2));  // the cell row j = 0
  EXPECT_EQ(q.cells_checked, CellsOverLevels((n[0] - 1) * (n[1] - 2), 2));
}

// ---------------------------------------------------------------------------------------------
// Surfaces in 3D.

MultiBlockGrid ReadShared(const std::string& relative) {
  absl::StatusOr<MultiBlockGrid> grid = ReadPlot3dFile(SharedDataPath(relative));
  EXPECT_TRUE(grid.ok()) << grid.status();
  return grid.ok() ? *std::move(grid) : MultiBlockGrid{};
}

// The six 5 x 5 faces of a cube sphere, interpolated. Where three faces meet, grid lines cross
// at 120 instead of 90 degrees, so the Jacobian varies by up to 56 percent inside a corner cell
// (JacobianSpread) and the sub-cells are uneven accordingly. kSurfaceSlack covers the chordal
// parent quadrilateral vs the curved cell (sagitta of a 22.5-degree arc, 2 percent) and the
// refined parameters (within 1.5 percent of even here).
TEST(GridQualitySurfaceTest, SpherePatchesAreOk) {
  constexpr double kSurfaceSlack = 0.05;
  const MultiBlockGrid sphere = ReadShared("surfaces/even_sphere.fmt");
  ASSERT_EQ(sphere.blocks.size(), 6u);
  for (const StructuredBlock& block : sphere.blocks) {
    const FittedBlock fitted = Fit(block);
    const CellQuality q = Check(fitted, block);
    const double d = JacobianSpread(fitted, block, 2);
    EXPECT_TRUE(q.ok()) << Describe(q);
    EXPECT_EQ(q.cells_checked, CellsOverLevels(16, 2));
    EXPECT_GE(q.min_ratio, 1 / (1 + d) - kSurfaceSlack) << Describe(q);
    EXPECT_LE(q.max_ratio, 1 + d + kSurfaceSlack) << Describe(q);
  }
}

// Block `block` with its i direction reversed.
StructuredBlock ReversedInI(const StructuredBlock& block) {
  StructuredBlock out(block.extents(), block.spatial_dim());
  const Extents n = block.extents();
  for (int k = 0; k < n[2]; ++k) {
    for (int j = 0; j < n[1]; ++j) {
      for (int i = 0; i < n[0]; ++i) {
        std::copy_n(block.Point(n[0] - 1 - i, j, k), block.spatial_dim(), out.Point(i, j, k));
      }
    }
  }
  return out;
}

// A face written with its i direction reversed (a common Plot3D mix-up) has inward normals: its
// cell (i, j) is the original cell (3 - i, j) with the opposite orientation, within 90 degrees of
// the original (i, j), so every dot product is negative and every cell counts as folded.
TEST(GridQualitySurfaceTest, FlippedNormalIsFolded) {
  const MultiBlockGrid sphere = ReadShared("surfaces/even_sphere.fmt");
  ASSERT_FALSE(sphere.blocks.empty());
  const StructuredBlock& block = sphere.blocks[0];
  const CellQuality q = Check(Fit(ReversedInI(block)), block);
  EXPECT_EQ(q.folded, q.cells_checked);
  EXPECT_EQ(q.num_bad_cells, 16);
}

// Block `block` (ni x nj x 1) laid out with i along `first` and j along `second`.
StructuredBlock Relaid(const StructuredBlock& block, int first, int second) {
  Extents n = {1, 1, 1};
  n[first] = block.extent(0);
  n[second] = block.extent(1);
  StructuredBlock out(n, block.spatial_dim());
  for (int j = 0; j < block.extent(1); ++j) {
    for (int i = 0; i < block.extent(0); ++i) {
      int at[3] = {0, 0, 0};
      at[first] = i;
      at[second] = j;
      std::copy_n(block.Point(i, j, 0), block.spatial_dim(), out.Point(at[0], at[1], at[2]));
    }
  }
  return out;
}

// The same surfaces in any two active directions give the same cells, ratios and indices. The
// fitted block interpolates a copy of a clustered wavy sheet with one point pushed past its
// neighbour, so there are folded and out-of-size cells to compare.
TEST(GridQualitySurfaceTest, AnyTwoActiveDirections) {
  auto sheet = [](double u, double v, double) {
    const double s = std::pow(u, 1.3);
    return Point3{2 * s, 1.5 * v + 0.2 * s, 0.3 * std::sin(2 * s) * std::cos(v)};
  };
  const StructuredBlock original = MakeBlock({11, 8, 1}, 3, sheet);
  StructuredBlock moved = original;
  for (int c = 0; c < 3; ++c) {
    moved.Point(6, 4, 0)[c] += 1.6 * (original.Point(7, 4, 0)[c] - original.Point(6, 4, 0)[c]);
  }
  const CellQuality reference = Check(Fit(moved), original);
  ASSERT_GT(reference.folded, 0);
  ASSERT_GT(reference.out_of_size, 0);
  for (const auto& [first, second] : {std::pair{0, 1}, std::pair{0, 2}, std::pair{1, 2}}) {
    const CellQuality q = Check(Fit(Relaid(moved, first, second)), Relaid(original, first, second));
    EXPECT_EQ(q.cells_checked, reference.cells_checked);
    EXPECT_EQ(q.folded, reference.folded);
    EXPECT_EQ(q.out_of_size, reference.out_of_size);
    EXPECT_NEAR(q.min_ratio, reference.min_ratio, kExactRatioTol);
    EXPECT_NEAR(q.max_ratio, reference.max_ratio, kExactRatioTol);
    EXPECT_EQ(q.worst_cell[first], reference.worst_cell[0]);
    EXPECT_EQ(q.worst_cell[second], reference.worst_cell[1]);
    ASSERT_EQ(q.bad_cells.size(), reference.bad_cells.size());
    for (size_t b = 0; b < q.bad_cells.size(); ++b) {
      EXPECT_EQ(q.bad_cells[b][first], reference.bad_cells[b][0]);
      EXPECT_EQ(q.bad_cells[b][second], reference.bad_cells[b][1]);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Volumes.

// A curved shell sector: radius 1..2, 60 degrees, height 1, with a twist growing in height.
Point3 ShellSector(double u, double v, double w) {
  const double r = 1 + u, theta = kPi / 3 * v + 0.3 * w;
  return Point3{r * std::cos(theta), r * std::sin(theta), w + 0.1 * std::sin(kPi * u)};
}

// Interpolated curvilinear volume: ok, ratios within the Jacobian spread (see JacobianSpread)
// plus kVolumeSlack for the curved cell edges and the refined parameters.
TEST(GridQualityVolumeTest, CurvilinearBlockIsOk) {
  constexpr double kVolumeSlack = 0.03;
  const StructuredBlock block = MakeBlock({9, 7, 5}, 3, ShellSector);
  const FittedBlock fitted = Fit(block);
  const CellQuality q = Check(fitted, block);
  const double d = JacobianSpread(fitted, block, 3);
  EXPECT_TRUE(q.ok()) << Describe(q);
  EXPECT_EQ(q.cells_checked, CellsOverLevels(8 * 6 * 4, 3));
  EXPECT_GE(q.min_ratio, 1 / (1 + d) - kVolumeSlack) << Describe(q);
  EXPECT_LE(q.max_ratio, 1 + d + kVolumeSlack) << Describe(q);
  ExpectSameWithTinyBudget(fitted, block, q);
}

// Level 0 against an oracle cell by cell: the fitted grid evaluated at the original parameters,
// each cell measured with the public single-cell formulas (PlanarCellArea, CellAreaVector,
// HexahedronVolume), ratio = m_fitted . m_original / |m_original|^2. The check measures whole rows
// of cells at once; this catches a corner or offset taken from the wrong cell there, which an
// affine block would not show.
TEST(GridQualityOracleTest, LevelZeroRatiosAreThoseOfTheEvaluatedCells) {
  struct Case {
    Extents n, controls;
    int spatial_dim;
  };
  auto shell_surface = [](double u, double v, double) { return ShellSector(u, v, 0.7); };
  auto planar = [](double u, double v, double) {
    return Point3{(1 + v) * std::cos(2 * u), (1 + v) * std::sin(2 * u) + 0.2 * u * u, 0};
  };
  for (const Case& c : {Case{{17, 9, 7}, {6, 5, 4}, 3}, Case{{21, 11, 1}, {7, 5, 0}, 3},
                        Case{{21, 11, 1}, {7, 5, 0}, 2}}) {
    const int num_active = c.n[2] > 1 ? 3 : 2;
    const StructuredBlock block =
        num_active == 3
            ? MakeBlock(c.n, 3, ShellSector)
            : (c.spatial_dim == 3 ? MakeBlock(c.n, 3, shell_surface) : MakeBlock(c.n, 2, planar));
    const FittedBlock fitted = Fit(block, c.controls);
    CellQualityOptions options;
    options.max_level = 0;
    options.max_size_ratio = 1e6;  // only the ratios matter here
    const CellQuality q = Check(fitted, block, options);
    std::array<std::vector<double>, 3> params;
    for (int d = 0; d < 3; ++d) params[d] = fitted.distribution.params(d);
    const StructuredBlock evaluated = EvaluateGrid(fitted.spline, params);
    double min_ratio = std::numeric_limits<double>::infinity(), max_ratio = 0;
    Extents worst = {0, 0, 0};
    auto point = [](const StructuredBlock& b, int i, int j, int k) {
      Point3 x = {0, 0, 0};
      for (int s = 0; s < b.spatial_dim(); ++s) x[s] = b.Point(i, j, k)[s];
      return x;
    };
    for (int k = 0; k + 1 < std::max(c.n[2], 2); ++k) {
      for (int j = 0; j + 1 < c.n[1]; ++j) {
        for (int i = 0; i + 1 < c.n[0]; ++i) {
          double ratio = 0;
          if (num_active == 3) {
            std::array<Point3, 8> xf, xo;
            for (int a = 0; a < 8; ++a) {
              xf[a] = point(evaluated, i + (a & 1), j + (a >> 1 & 1), k + (a >> 2));
              xo[a] = point(block, i + (a & 1), j + (a >> 1 & 1), k + (a >> 2));
            }
            ratio = HexahedronVolume(xf) / HexahedronVolume(xo);
          } else {
            std::array<Point3, 4> xf, xo;
            for (int a = 0; a < 4; ++a) {
              xf[a] = point(evaluated, i + (a & 1), j + (a >> 1), 0);
              xo[a] = point(block, i + (a & 1), j + (a >> 1), 0);
            }
            if (c.spatial_dim == 2) {
              ratio = PlanarCellArea(xf) / PlanarCellArea(xo);
            } else {
              const Point3 af = CellAreaVector(xf), ao = CellAreaVector(xo);
              ratio = (af[0] * ao[0] + af[1] * ao[1] + af[2] * ao[2]) /
                      (ao[0] * ao[0] + ao[1] * ao[1] + ao[2] * ao[2]);
            }
          }
          if (ratio < min_ratio) {
            min_ratio = ratio;
            worst = {i, j, k};
          }
          max_ratio = std::max(max_ratio, std::abs(ratio));
        }
      }
    }
    SCOPED_TRACE(testing::Message() << "extents " << c.n[0] << " x " << c.n[1] << " x " << c.n[2]
                                    << ", spatial_dim " << c.spatial_dim);
    EXPECT_NE(min_ratio, max_ratio);  // a fit that varies the ratios from cell to cell
    EXPECT_NEAR(q.min_ratio, min_ratio, 1e-12 * max_ratio);
    EXPECT_NEAR(q.max_ratio, max_ratio, 1e-12 * max_ratio);
    EXPECT_EQ(q.worst_cell, worst);
  }
}

// Affine volume with even spacing: exact at every level (sub-cells are parent / 8^l).
TEST(GridQualityVolumeTest, AffineBlockGivesRatioOne) {
  const StructuredBlock block = MakeBlock({5, 4, 6}, 3, [](double u, double v, double w) {
    return Point3{2 * u + 0.3 * w, v - 0.2 * u, 1.5 * w + 0.4 * v};
  });
  const CellQuality q = Check(Fit(block), block);
  EXPECT_EQ(q.cells_checked, CellsOverLevels(4 * 3 * 5, 3));
  EXPECT_NEAR(q.min_ratio, 1.0, kExactRatioTol);
  EXPECT_NEAR(q.max_ratio, 1.0, kExactRatioTol);
}

TEST(GridQualityVolumeTest, ControlMovedAcrossItsNeighbourIsFolded) {
  const StructuredBlock block = MakeBlock({9, 7, 5}, 3, ShellSector);
  FittedBlock fitted = Fit(block, {7, 6, 5});
  ASSERT_TRUE(Check(fitted, block).ok());
  // Control (3, 2, 2) moved in height far past control (3, 2, 3), by eight control spacings: a
  // cubic basis function weighs at most about 2/3 per direction, so in a volume its neighbours
  // hold the grid (three spacings still leave every ratio above 0.4).
  const Extents control = {3, 2, 2};
  const Extents nc = fitted.spline.control_extents();
  double* p = fitted.spline.mutable_control().data() +
              3 * (control[0] + nc[0] * (control[1] + nc[1] * control[2]));
  p[2] += 8 * (fitted.spline.ControlPoint(3, 2, 3)[2] - p[2]);
  const CellQuality q = Check(fitted, block);
  ExpectFoldAt(fitted, block, q, control, 3);
}

// A quarter cylinder of radius u around the z axis: the i = 0 points of every k-plane coincide
// (on the axis), so the cells at i = 0 have a collapsed edge in j and are skipped.
TEST(GridQualityVolumeTest, CollapsedEdgeCellsAreSkipped) {
  const Extents n = {6, 5, 4};
  const StructuredBlock block = MakeBlock(n, 3, [](double u, double v, double w) {
    return Point3{u * std::cos(0.5 * kPi * v), u * std::sin(0.5 * kPi * v), w};
  });
  const CellQuality q = Check(Fit(block), block);
  EXPECT_TRUE(q.ok()) << Describe(q);
  EXPECT_EQ(q.cells_skipped, CellsOverLevels((n[1] - 1) * (n[2] - 1), 3));
  EXPECT_EQ(q.cells_checked, CellsOverLevels((n[0] - 2) * (n[1] - 1) * (n[2] - 1), 3));
}

// ---------------------------------------------------------------------------------------------
// The shared NACA 0012 C-grid.

TEST(GridQualitySharedTest, CGridInterpolatedIsOkAndCoarseFitFails) {
  const MultiBlockGrid grid = ReadShared("grids/n0012_225-65.p2dfmt");
  ASSERT_EQ(grid.blocks.size(), 1u);
  const StructuredBlock& block = grid.blocks[0];
  const FittedBlock fitted = Fit(block);
  const auto start = std::chrono::steady_clock::now();
  const CellQuality q = Check(fitted, block);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::cout << "C-grid interpolated: " << Describe(q) << "; " << ms << " ms for levels 0..2\n";
  EXPECT_TRUE(q.ok()) << Describe(q);
  EXPECT_EQ(q.cells_checked + q.cells_skipped, CellsOverLevels(224 * 64, 2));

  const CellQuality coarse = Check(Fit(block, {8, 6, 1}), block);
  EXPECT_FALSE(coarse.ok());
  EXPECT_GT(coarse.folded + coarse.out_of_size, 0);
}

// ---------------------------------------------------------------------------------------------
// Curves, errors, cancellation.

TEST(GridQualityErrorTest, CurvesHaveNoCells) {
  const StructuredBlock curve = MakeBlock({7, 1, 1}, 3, [](double u, double, double) {
    return Point3{u, u * u, 0};
  });
  const CellQuality q = Check(Fit(curve), curve);
  EXPECT_TRUE(q.ok());
  EXPECT_EQ(q.cells_checked, 0);
  EXPECT_EQ(q.cells_skipped, 0);
}

TEST(GridQualityErrorTest, MismatchedBlocksAndBadOptions) {
  const StructuredBlock block = EvenPlanarGrid();
  const FittedBlock fitted = Fit(block);
  const StructuredBlock other = MakeBlock({21, 16, 1}, 2, [](double u, double v, double) {
    return Point3{u, v, 0};
  });
  absl::StatusOr<CellQuality> q = CheckCellQuality(fitted, other);
  EXPECT_EQ(q.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(q.status().message(), HasSubstr("21 x 17 x 1"));
  EXPECT_THAT(q.status().message(), HasSubstr("21 x 16 x 1"));

  const StructuredBlock in_3d = MakeBlock({21, 17, 1}, 3, [](double u, double v, double) {
    return Point3{u, v, 0};
  });
  q = CheckCellQuality(fitted, in_3d);
  EXPECT_EQ(q.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(q.status().message(), HasSubstr("spatial_dim 2"));
  EXPECT_THAT(q.status().message(), HasSubstr("spatial_dim 3"));

  StructuredBlock with_nan = block;
  with_nan.Point(3, 4, 0)[1] = std::nan("");
  EXPECT_EQ(CheckCellQuality(fitted, with_nan).status().code(), absl::StatusCode::kInvalidArgument);

  CellQualityOptions options;
  options.max_level = -1;
  q = CheckCellQuality(fitted, block, options);
  EXPECT_THAT(q.status().message(), HasSubstr("max_level"));
  options = {};
  options.max_size_ratio = 0.5;
  q = CheckCellQuality(fitted, block, options);
  EXPECT_THAT(q.status().message(), HasSubstr("max_size_ratio"));
  options = {};
  options.max_reported_cells = -3;
  q = CheckCellQuality(fitted, block, options);
  EXPECT_THAT(q.status().message(), HasSubstr("max_reported_cells"));
  options = {};
  options.evaluator_budget = 0;
  q = CheckCellQuality(fitted, block, options);
  EXPECT_THAT(q.status().message(), HasSubstr("evaluator_budget"));

  // A volume of points with two coordinates has no measure.
  StructuredBlock flat_volume({3, 3, 3}, 2);
  FittedBlock any;
  any.spline = fitted.spline;
  any.distribution =
      *PointDistribution::Create({std::vector<double>{0, 0.5, 1}, std::vector<double>{0, 0.5, 1},
                                  std::vector<double>{0, 0.5, 1}});
  q = CheckCellQuality(any, flat_volume);
  EXPECT_EQ(q.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(q.status().message(), HasSubstr("three active directions"));
}

TEST(GridQualityErrorTest, Cancelled) {
  const StructuredBlock block = EvenPlanarGrid();
  const FittedBlock fitted = Fit(block);
  int polls = 0;
  CellQualityOptions options;
  options.cancel = [&polls] { return ++polls > 20; };
  absl::StatusOr<CellQuality> q = CheckCellQuality(fitted, block, options);
  EXPECT_EQ(q.status().code(), absl::StatusCode::kCancelled);
}

}  // namespace
}  // namespace splinegrid
