// Fitting every block of every Plot3D file in ../shared/data at several control counts, with
// the banded direction-by-direction solve checked against dense least squares on the small
// blocks.
//
// The dense oracles (Ceres' habit: the dense backend checks the fast one):
//  - free ends: the tensor fit is the least-squares solution of the Kronecker collocation system
//      (C (x) B (x) A) P = X,
//    solved here densely by column-pivoting Householder QR;
//  - interpolated ends: every 1D operator fixes the first and last control to the line's end
//    values and fits the interior controls by least squares, p = O x with
//      O = [e_0^T; A_I^+ (I - a_0 e_0^T - a_{n-1} e_{m-1}^T); e_{m-1}^T]
//    (A_I the interior columns, a_j column j of A), and the tensor fit is (O_w (x) O_v (x) O_u) X.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "Eigen/Dense"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "core/bspline/basis.h"
#include "core/bspline/evaluation.h"
#include "core/bspline/parametrization.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/io/planar_view.h"
#include "core/io/plot3d.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

// Interpolation (as many controls as points) reproduces the data up to rounding; relative to
// the block's bounding-box diagonal.
constexpr double kInterpolationRelTol = 1e-11;
// Rounding of one evaluated point (EvaluatePoint and the sum-factorised GridEvaluator sum in
// different orders), relative to the largest coordinate magnitude of the block.
constexpr double kRoundingRelTol = 1e-13;
// Nested spaces: the least-squares residual norm may only shrink, up to rounding (relative to
// the previous residual norm, plus the rounding of a residual norm near 0).
constexpr double kMonotoneRelSlack = 1e-10;
// Banded Givens QR vs dense Householder QR: control points relative to the largest control
// coordinate, residual norms relative to the dense residual norm.
constexpr double kOracleControlRelTol = 1e-11;
constexpr double kOracleResidualRelTol = 1e-12;
// A two-plane block and its planar view describe the same points.
constexpr double kPlanarAgreementRelTol = 1e-12;

// One block of a shared file, as fitted.
struct SharedBlock {
  std::string name;  // file, block number and view, for failure messages
  StructuredBlock block;
};

// Reads shared file `relative`, failing the test on error.
MultiBlockGrid ReadShared(const std::string& relative) {
  absl::StatusOr<MultiBlockGrid> grid = ReadPlot3dFile(SharedDataPath(relative));
  EXPECT_TRUE(grid.ok()) << grid.status();
  return grid.ok() ? *std::move(grid) : MultiBlockGrid{};
}

// Every Plot3D file in shared/data/grids and shared/data/surfaces (relative paths, sorted).
const std::vector<std::string>& SharedPlot3dFiles() {
  static const std::vector<std::string>* files = [] {
    auto* out = new std::vector<std::string>;
    for (const std::string dir : {"grids", "surfaces"}) {
      std::error_code error;
      for (const auto& entry : std::filesystem::directory_iterator(SharedDataPath(dir), error)) {
        const std::string ext = entry.path().extension().string();
        if (entry.is_regular_file() &&
            (ext == ".fmt" || ext == ".p2dfmt" || ext == ".x" || ext == ".xyz" || ext == ".p3d")) {
          out->push_back(dir + "/" + entry.path().filename().string());
        }
      }
      EXPECT_FALSE(error) << SharedDataPath(dir) << ": " << error.message();
    }
    std::sort(out->begin(), out->end());
    return out;
  }();
  return *files;
}

// Every block of every shared file; two-plane files contribute their planar view (the grid
// as the solver means it) and once the raw 3D two-plane block. Read once per test binary.
const std::vector<SharedBlock>& SharedBlocks() {
  static const std::vector<SharedBlock>* blocks = [] {
    auto* out = new std::vector<SharedBlock>;
    for (const std::string& file : SharedPlot3dFiles()) {
      const MultiBlockGrid grid = ReadShared(file);
      if (IsTwoPlaneGrid(grid)) {
        absl::StatusOr<MultiBlockGrid> planar = PlanarView(grid);
        EXPECT_TRUE(planar.ok()) << planar.status();
        if (!planar.ok()) continue;
        for (size_t b = 0; b < planar->blocks.size(); ++b) {
          out->push_back({absl::StrCat(file, " block ", b, " (planar view)"), planar->blocks[b]});
          out->push_back({absl::StrCat(file, " block ", b, " (raw two-plane 3D)"), grid.blocks[b]});
        }
      } else {
        for (size_t b = 0; b < grid.blocks.size(); ++b) {
          out->push_back({absl::StrCat(file, " block ", b), grid.blocks[b]});
        }
      }
    }
    return out;
  }();
  return *blocks;
}

// The diagonal of the bounding box of `block`'s points.
double BoxDiagonal(const StructuredBlock& block) {
  const int s = block.spatial_dim();
  double sum = 0.0;
  for (int c = 0; c < s; ++c) {
    double lo = block.coords()[c], hi = lo;
    for (int64_t p = 0; p < block.num_points(); ++p) {
      lo = std::min(lo, block.coords()[s * p + c]);
      hi = std::max(hi, block.coords()[s * p + c]);
    }
    sum += (hi - lo) * (hi - lo);
  }
  return std::sqrt(sum);
}

// The sub-block [lo, hi] (inclusive index ranges) of `block`.
StructuredBlock SubBlock(const StructuredBlock& block, const Extents& lo, const Extents& hi) {
  StructuredBlock sub({hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1},
                      block.spatial_dim());
  for (int k = lo[2]; k <= hi[2]; ++k) {
    for (int j = lo[1]; j <= hi[1]; ++j) {
      for (int i = lo[0]; i <= hi[0]; ++i) {
        std::copy_n(block.Point(i, j, k), block.spatial_dim(),
                    sub.Point(i - lo[0], j - lo[1], k - lo[2]));
      }
    }
  }
  return sub;
}

// The largest coordinate magnitude of `block`: the scale of rounding errors.
double MaxAbsCoordinate(const StructuredBlock& block) {
  double m = 0.0;
  for (double x : block.coords()) m = std::max(m, std::abs(x));
  return m;
}

// The rounding level of a residual norm over all points of `block`.
double ResidualRoundingFloor(const StructuredBlock& block) {
  return kRoundingRelTol * MaxAbsCoordinate(block) *
         std::sqrt(static_cast<double>(block.num_points()));
}

// Euclidean distance between the first `s` coordinates of a and b.
double Distance(const double* a, const double* b, int s) {
  double sum = 0.0;
  for (int c = 0; c < s; ++c) sum += (a[c] - b[c]) * (a[c] - b[c]);
  return std::sqrt(sum);
}

// The control counts of one fitting level: `divisor` 0 means interpolation (FitOptions'
// control_counts 0), 1 the minimum (the order), else about points / divisor, clamped to
// [order, points].
Extents ControlCounts(const Extents& points, int order, int divisor) {
  Extents counts = {0, 0, 0};
  for (int d = 0; d < 3; ++d) {
    if (points[d] == 1 || divisor == 0) continue;
    const int minimum = std::min(order, points[d]);
    counts[d] = divisor == 1 ? minimum : std::clamp(points[d] / divisor, minimum, points[d]);
  }
  return counts;
}

std::string Describe(const Extents& e) { return absl::StrCat(e[0], " x ", e[1], " x ", e[2]); }

TEST(SharedGridFitTest, ReadsEverySharedBlock) {
  // Guards the loops below against silently testing nothing: the seven files of the data
  // README, 1 + 1 + 2 + 2 + 9 + 6 + 1 blocks (two-plane files twice).
  const std::vector<std::string>& files = SharedPlot3dFiles();
  for (const std::string known :
       {"grids/n0012_113-33.p2dfmt", "grids/n0012_225-65.p2dfmt", "grids/rae2822_257x97.fmt",
        "grids/n0012_pitch_257x129.fmt", "surfaces/m6_small.fmt", "surfaces/even_sphere.fmt",
        "surfaces/ffd_box_6x2x6.fmt"}) {
    EXPECT_NE(std::find(files.begin(), files.end(), known), files.end()) << known;
  }
  EXPECT_GE(SharedBlocks().size(), 22u);
}

// FitBlock on every shared block at minimal, ~1/8, ~1/3 and full control counts, with both end
// conditions: the summary is consistent, the reported worst point really is that far off, and
// interpolation reproduces the data.
TEST(SharedGridFitTest, EveryBlockFitsAtSeveralControlCounts) {
  for (const SharedBlock& shared : SharedBlocks()) {
    const StructuredBlock& block = shared.block;
    const double diagonal = BoxDiagonal(block);
    const double rounding = kRoundingRelTol * MaxAbsCoordinate(block);
    for (int divisor : {1, 8, 3, 0}) {
      for (bool interpolate_ends : {true, false}) {
        FitOptions options;
        options.control_counts = ControlCounts(block.extents(), options.order, divisor);
        options.interpolate_ends = interpolate_ends;
        SCOPED_TRACE(absl::StrCat(shared.name, ", controls ", Describe(options.control_counts),
                                  interpolate_ends ? ", interpolated ends" : ", free ends"));
        absl::StatusOr<FittedBlock> fitted = FitBlock(block, options);
        ASSERT_TRUE(fitted.ok()) << fitted.status();
        const FitSummary& summary = fitted->summary;
        const Deviation& dev = summary.deviation;
        EXPECT_TRUE(std::isfinite(dev.max) && std::isfinite(dev.rms));
        EXPECT_GE(dev.max, dev.rms);
        EXPECT_GE(dev.rms, 0.0);
        EXPECT_EQ(dev.num_points, block.num_points());
        EXPECT_EQ(summary.num_points, block.num_points());
        Extents expected = options.control_counts;
        for (int d = 0; d < 3; ++d) {
          if (expected[d] == 0) expected[d] = block.extent(d);
        }
        EXPECT_EQ(fitted->spline.control_extents(), expected);
        EXPECT_EQ(summary.num_control_points, NumPoints(expected));
        EXPECT_DOUBLE_EQ(summary.compression_ratio,
                         static_cast<double>(block.num_points()) / NumPoints(expected));
        for (int d = 0; d < 3; ++d) {
          EXPECT_EQ(fitted->distribution.num_points(d), block.extent(d));
        }
        if (divisor == 0) {
          EXPECT_LE(dev.max, kInterpolationRelTol * diagonal);
        }

        // The worst point, re-evaluated on its own, is exactly that far from its data point,
        // and no point is farther (checked on a few others as well).
        const Extents at = dev.max_at;
        const PointDistribution& dist = fitted->distribution;
        const Point3 p = EvaluatePoint(
            fitted->spline, {dist.params(0)[at[0]], dist.params(1)[at[1]], dist.params(2)[at[2]]});
        EXPECT_NEAR(Distance(p.data(), block.Point(at[0], at[1], at[2]), block.spatial_dim()),
                    dev.max, rounding)
            << "max_at " << Describe(at);
        for (int i : {0, block.extent(0) / 2, block.extent(0) - 1}) {
          for (int j : {0, block.extent(1) / 3, block.extent(1) - 1}) {
            const int k = block.extent(2) - 1;
            const Point3 q = EvaluatePoint(
                fitted->spline, {dist.params(0)[i], dist.params(1)[j], dist.params(2)[k]});
            EXPECT_LE(Distance(q.data(), block.Point(i, j, k), block.spatial_dim()),
                      dev.max + rounding);
          }
        }
      }
    }
  }
}

// With uniform parameters and uniform knots of 2^j spans per direction the spline spaces are
// nested, so the free-end (true least-squares) residual norm cannot grow as j grows.
TEST(SharedGridFitTest, ResidualDoesNotGrowWithNestedUniformKnots) {
  for (const SharedBlock& shared : SharedBlocks()) {
    const StructuredBlock& block = shared.block;
    const double floor = ResidualRoundingFloor(block);
    const double sqrt_points = std::sqrt(static_cast<double>(block.num_points()));
    FitOptions options;
    options.parametrization = Parametrization::kUniform;
    options.knot_placement = KnotPlacement::kUniform;
    options.interpolate_ends = false;
    double previous = -1.0;
    int levels = 0;
    for (int j = 0;; ++j) {
      // 2^j spans: order + 2^j - 1 controls, held at the last count that fits the points.
      Extents counts = {0, 0, 0};
      bool grew = false;
      for (int d = 0; d < 3; ++d) {
        if (block.extent(d) == 1) continue;
        const int order = std::min(options.order, block.extent(d));
        int spans = 1 << j;
        while (spans > 1 && order + spans - 1 > block.extent(d)) spans /= 2;
        counts[d] = order + spans - 1;
        grew |= spans == (1 << j) && j > 0;
      }
      if (j > 0 && !grew) break;
      options.control_counts = counts;
      SCOPED_TRACE(absl::StrCat(shared.name, ", level ", j, ", controls ", Describe(counts)));
      absl::StatusOr<FittedBlock> fitted = FitBlock(block, options);
      ASSERT_TRUE(fitted.ok()) << fitted.status();
      const double residual = fitted->summary.deviation.rms * sqrt_points;
      if (previous >= 0.0) {
        EXPECT_LE(residual, previous * (1.0 + kMonotoneRelSlack) + floor);
      }
      previous = residual;
      ++levels;
    }
    EXPECT_GE(levels, 2) << shared.name;
  }
}

// A two-plane block fitted in 3D (linear between its planes) gives the same in-plane controls
// and deviation as its planar view: the parameters and knots of the other directions agree.
TEST(SharedGridFitTest, RawTwoPlaneBlockFitMatchesItsPlanarView) {
  int compared = 0;
  for (const std::string& file : SharedPlot3dFiles()) {
    const MultiBlockGrid grid = ReadShared(file);
    if (!IsTwoPlaneGrid(grid)) continue;
    const StructuredBlock& raw = grid.blocks[0];
    const TwoPlaneLayout layout = DetectTwoPlaneBlock(raw).value();
    ASSERT_EQ(layout.plane_direction, 0) << file;    // planar (i, j) = raw (j, k)
    ASSERT_EQ(layout.normal_coordinate, 1) << file;  // planar (x, y) = raw (x, z)
    const StructuredBlock planar = PlanarBlock(raw).value();
    FitOptions planar_options, raw_options;
    planar_options.control_counts = {planar.extent(0) / 3, planar.extent(1) / 3, 0};
    raw_options.control_counts = {0, planar.extent(0) / 3, planar.extent(1) / 3};
    const FittedBlock planar_fit = FitBlock(planar, planar_options).value();
    const FittedBlock raw_fit = FitBlock(raw, raw_options).value();
    ASSERT_EQ(raw_fit.spline.control_extents(),
              (Extents{2, planar_options.control_counts[0], planar_options.control_counts[1]}));
    const double diagonal = BoxDiagonal(planar);
    const double tol = kPlanarAgreementRelTol * diagonal;
    EXPECT_NEAR(raw_fit.summary.deviation.max, planar_fit.summary.deviation.max, tol) << file;
    for (int b = 0; b < planar_options.control_counts[1]; ++b) {
      for (int a = 0; a < planar_options.control_counts[0]; ++a) {
        const double* p = planar_fit.spline.ControlPoint(a, b, 0);
        for (int plane = 0; plane < 2; ++plane) {
          const double* q = raw_fit.spline.ControlPoint(plane, a, b);
          ASSERT_NEAR(q[0], p[0], tol) << file << " control " << a << ", " << b;
          ASSERT_NEAR(q[2], p[1], tol) << file << " control " << a << ", " << b;
          ASSERT_NEAR(q[1], layout.plane_values[plane], tol) << file;
        }
      }
    }
    ++compared;
  }
  EXPECT_EQ(compared, 2);
}

// ----- Dense oracles on the small blocks -------------------------------------------------------

// The dense collocation matrix A(q, j) = N_j(u_q) of one direction.
Eigen::MatrixXd DenseCollocation(const KnotVector& knots, const std::vector<double>& params) {
  const SampledBasis b = SampleBasis(knots, params);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(params.size(), knots.num_controls());
  for (int q = 0; q < b.num_samples(); ++q) {
    for (int t = 0; t < b.order; ++t) a(q, b.first[q] + t) = b.Row(q)[t];
  }
  return a;
}

// kron(x, y)(r_x rows(y) + r_y, c_x cols(y) + c_y) = x(r_x, c_x) y(r_y, c_y).
Eigen::MatrixXd Kron(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y) {
  Eigen::MatrixXd out(x.rows() * y.rows(), x.cols() * y.cols());
  for (int i = 0; i < x.rows(); ++i) {
    for (int j = 0; j < x.cols(); ++j) {
      out.block(i * y.rows(), j * y.cols(), y.rows(), y.cols()) = x(i, j) * y;
    }
  }
  return out;
}

// The matrix of direction operators mapping the data (point index i + m0 (j + m1 k), i fastest)
// to the controls (same layout): kron(M_2, kron(M_1, M_0)).
Eigen::MatrixXd Kron3(const std::array<Eigen::MatrixXd, 3>& m) {
  return Kron(m[2], Kron(m[1], m[0]));
}

// The 1D fit with interpolated ends as a dense matrix O (n x m), see the file comment.
Eigen::MatrixXd DenseInterpolatedEndsOperator(const Eigen::MatrixXd& a) {
  const int m = a.rows(), n = a.cols();
  if (n == 1) return Eigen::MatrixXd::Identity(1, 1);  // an unused direction (m == 1)
  Eigen::MatrixXd op = Eigen::MatrixXd::Zero(n, m);
  op(0, 0) = 1.0;
  op(n - 1, m - 1) = 1.0;
  if (n > 2) {
    // Column r: the interior right-hand side for the unit data vector e_r, i.e.
    // e_r - a_0 [r == 0] - a_{n-1} [r == m - 1].
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Identity(m, m);
    rhs.col(0) -= a.col(0);
    rhs.col(m - 1) -= a.col(n - 1);
    op.middleRows(1, n - 2) = a.middleCols(1, n - 2).colPivHouseholderQr().solve(rhs);
  }
  return op;
}

// The data as an (N x s) matrix and the controls of `spline` as an (N_c x s) matrix.
Eigen::MatrixXd DataMatrix(const StructuredBlock& block) {
  const int s = block.spatial_dim();
  Eigen::MatrixXd x(block.num_points(), s);
  for (int64_t p = 0; p < block.num_points(); ++p) {
    for (int c = 0; c < s; ++c) x(p, c) = block.coords()[s * p + c];
  }
  return x;
}
Eigen::MatrixXd ControlMatrix(const TensorSpline& spline) {
  const int s = spline.spatial_dim();
  Eigen::MatrixXd x(spline.num_control_points(), s);
  for (int64_t p = 0; p < spline.num_control_points(); ++p) {
    for (int c = 0; c < s; ++c) x(p, c) = spline.control()[s * p + c];
  }
  return x;
}

// The small blocks for the dense oracle: every shared block of at most ~1300 points (the
// sphere, the ffd box, the small M6 patches) and a wall-adjacent 33 x 17 sub-block of the
// NACA 0012 113 x 33 C-grid (a 2D block).
std::vector<SharedBlock> SmallBlocks() {
  std::vector<SharedBlock> small;
  for (const SharedBlock& shared : SharedBlocks()) {
    if (shared.block.num_points() <= 1300) small.push_back(shared);
  }
  const MultiBlockGrid naca = ReadShared("grids/n0012_113-33.p2dfmt");
  if (!naca.blocks.empty()) {
    small.push_back({"grids/n0012_113-33.p2dfmt i 40..72, j 0..16",
                     SubBlock(naca.blocks[0], {40, 0, 0}, {72, 16, 0})});
  }
  return small;
}

// Control counts for the oracle: minimal, ~1/3, and interpolation for the tiny blocks (the
// dense solve costs O(points controls^2)).
std::vector<Extents> OracleCounts(const Extents& points, int order) {
  std::vector<Extents> counts = {ControlCounts(points, order, 1), ControlCounts(points, order, 3)};
  if (NumPoints(points) <= 300) counts.push_back(points);
  for (Extents& c : counts) {
    for (int d = 0; d < 3; ++d) c[d] = std::max(c[d], 1);
  }
  counts.erase(std::unique(counts.begin(), counts.end()), counts.end());
  return counts;
}

// The parameters and averaged knots of `block` at `counts`, as FitBlock chooses them.
void ParamsAndKnots(const StructuredBlock& block, const Extents& counts, int order,
                    std::array<std::vector<double>, 3>& params, std::array<KnotVector, 3>& knots) {
  params = ParametrizeBlock(block, Parametrization::kChordLength);
  for (int d = 0; d < 3; ++d) {
    knots[d] = KnotVector();
    if (block.extent(d) == 1) continue;
    knots[d] = KnotVector::Averaged(std::min(order, counts[d]), counts[d], params[d]).value();
  }
}

// Sphere 6 x 2 (4 x 4 and 5 x 5; ~1/3 is the minimum), ffd box 2 (likewise), M6 17 x 17 patches 2 x
// 3, the other M6 patches of <= 1300 points 5 x 2, NACA sub-block 2.
constexpr int kOracleCases = 12 + 2 + 6 + 10 + 2;

TEST(SharedGridDenseOracleTest, FreeEndsEqualDenseKroneckerLeastSquares) {
  int cases = 0;
  for (const SharedBlock& shared : SmallBlocks()) {
    const StructuredBlock& block = shared.block;
    for (const Extents& counts : OracleCounts(block.extents(), 4)) {
      SCOPED_TRACE(absl::StrCat(shared.name, ", controls ", Describe(counts)));
      std::array<std::vector<double>, 3> params;
      std::array<KnotVector, 3> knots;
      ParamsAndKnots(block, counts, 4, params, knots);
      const TensorSpline spline = FitTensor(block, params, knots, EndCondition::kFree).value();
      std::array<Eigen::MatrixXd, 3> a;
      for (int d = 0; d < 3; ++d) a[d] = DenseCollocation(knots[d], params[d]);
      const Eigen::MatrixXd kron = Kron3(a);
      const Eigen::MatrixXd x = DataMatrix(block);
      const Eigen::MatrixXd dense = kron.colPivHouseholderQr().solve(x);
      const Eigen::MatrixXd banded = ControlMatrix(spline);
      ASSERT_EQ(banded.rows(), dense.rows());
      const double scale = dense.cwiseAbs().maxCoeff();
      EXPECT_LE((banded - dense).cwiseAbs().maxCoeff(), kOracleControlRelTol * scale);
      const double dense_residual = (kron * dense - x).norm();
      const Deviation dev = MeasureDeviation(spline, params, block).value();
      const double residual = dev.rms * std::sqrt(static_cast<double>(block.num_points()));
      EXPECT_NEAR(residual, dense_residual,
                  kOracleResidualRelTol * dense_residual + ResidualRoundingFloor(block));
      ++cases;
    }
  }
  EXPECT_EQ(cases, kOracleCases);
}

TEST(SharedGridDenseOracleTest, InterpolatedEndsEqualKroneckerOfConstrainedOperators) {
  int cases = 0;
  for (const SharedBlock& shared : SmallBlocks()) {
    const StructuredBlock& block = shared.block;
    for (const Extents& counts : OracleCounts(block.extents(), 4)) {
      SCOPED_TRACE(absl::StrCat(shared.name, ", controls ", Describe(counts)));
      std::array<std::vector<double>, 3> params;
      std::array<KnotVector, 3> knots;
      ParamsAndKnots(block, counts, 4, params, knots);
      const TensorSpline spline =
          FitTensor(block, params, knots, EndCondition::kInterpolate).value();
      std::array<Eigen::MatrixXd, 3> a, op;
      for (int d = 0; d < 3; ++d) {
        a[d] = DenseCollocation(knots[d], params[d]);
        op[d] = DenseInterpolatedEndsOperator(a[d]);
      }
      const Eigen::MatrixXd x = DataMatrix(block);
      const Eigen::MatrixXd dense = Kron3(op) * x;
      const Eigen::MatrixXd banded = ControlMatrix(spline);
      ASSERT_EQ(banded.rows(), dense.rows());
      const double scale = dense.cwiseAbs().maxCoeff();
      EXPECT_LE((banded - dense).cwiseAbs().maxCoeff(), kOracleControlRelTol * scale);
      const double dense_residual = (Kron3(a) * dense - x).norm();
      const Deviation dev = MeasureDeviation(spline, params, block).value();
      const double residual = dev.rms * std::sqrt(static_cast<double>(block.num_points()));
      EXPECT_NEAR(residual, dense_residual,
                  kOracleResidualRelTol * dense_residual + ResidualRoundingFloor(block));
      ++cases;
    }
  }
  EXPECT_EQ(cases, kOracleCases);
}

// ----- Corners ------------------------------------------------------------------------------

// The corner indices of `block` (duplicates removed for unused directions).
std::vector<Extents> Corners(const StructuredBlock& block) {
  std::vector<Extents> corners;
  for (int k : {0, block.extent(2) - 1}) {
    for (int j : {0, block.extent(1) - 1}) {
      for (int i : {0, block.extent(0) - 1}) {
        const Extents c = {i, j, k};
        if (std::find(corners.begin(), corners.end(), c) == corners.end()) corners.push_back(c);
      }
    }
  }
  return corners;
}

// Interpolated ends pin the corner control points to the data corners: bit for bit.
TEST(SharedGridCornerTest, CornerControlPointsAreTheDataCorners) {
  for (const SharedBlock& shared : SharedBlocks()) {
    for (int divisor : {1, 3, 0}) {
      FitOptions options;
      options.control_counts = ControlCounts(shared.block.extents(), options.order, divisor);
      const FittedBlock fitted = FitBlock(shared.block, options).value();
      const Extents n = fitted.spline.control_extents();
      for (const Extents& c : Corners(shared.block)) {
        const double* control = fitted.spline.ControlPoint(
            c[0] == 0 ? 0 : n[0] - 1, c[1] == 0 ? 0 : n[1] - 1, c[2] == 0 ? 0 : n[2] - 1);
        const double* data = shared.block.Point(c[0], c[1], c[2]);
        for (int x = 0; x < shared.block.spatial_dim(); ++x) {
          EXPECT_EQ(control[x], data[x]) << shared.name << " corner " << Describe(c);
        }
      }
    }
  }
}

// The mapping passes through the corners exactly: evaluated at the corner parameters (0 or 1)
// the spline gives the data corner bit for bit, point-wise and on a grid. Exact corners are
// what lets neighbouring blocks, fitted with different knots, meet at identical points.
TEST(SharedGridCornerTest, EvaluatedCornersAreBitwiseTheDataCorners) {
  int corners = 0;
  std::vector<std::string> mismatches;
  for (const SharedBlock& shared : SharedBlocks()) {
    for (int divisor : {1, 3, 0}) {
      FitOptions options;
      options.control_counts = ControlCounts(shared.block.extents(), options.order, divisor);
      const FittedBlock fitted = FitBlock(shared.block, options).value();
      const PointDistribution& dist = fitted.distribution;
      const StructuredBlock grid =
          EvaluateGrid(fitted.spline, {dist.params(0), dist.params(1), dist.params(2)});
      for (const Extents& c : Corners(shared.block)) {
        const Point3 p = EvaluatePoint(
            fitted.spline, {dist.params(0)[c[0]], dist.params(1)[c[1]], dist.params(2)[c[2]]});
        const double* data = shared.block.Point(c[0], c[1], c[2]);
        for (int x = 0; x < shared.block.spatial_dim(); ++x) {
          const double on_grid = grid.Point(c[0], c[1], c[2])[x];
          if (p[x] != data[x] || on_grid != data[x]) {
            mismatches.push_back(absl::StrFormat(
                "%s, controls %s, corner %s, coordinate %d: data %.17g, EvaluatePoint %.17g, "
                "EvaluateGrid %.17g",
                shared.name, Describe(fitted.spline.control_extents()), Describe(c), x, data[x],
                p[x], on_grid));
          }
        }
        ++corners;
      }
    }
  }
  EXPECT_GT(corners, 100);
  EXPECT_TRUE(mismatches.empty()) << mismatches.size() << " corner coordinates differ, e.g.\n"
                                  << absl::StrJoin(mismatches.begin(),
                                                   mismatches.begin() +
                                                       std::min<size_t>(mismatches.size(), 5),
                                                   "\n");
}

// The root cause checked directly: at a clamped end only the end basis function is nonzero and
// it is exactly 1 (partition of unity), for any knots; likewise at an interior knot of
// multiplicity order - 1. Point and grid evaluation both rely on it for exact corners.
TEST(SharedGridCornerTest, BasisIsExactlyAUnitVectorAtClampedEndsAndFeatureKnots) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  int inexact = 0, cases = 0;
  std::string example;
  for (int trial = 0; trial < 200; ++trial) {
    const int order = 2 + trial % 5;
    std::vector<double> interior(3 + trial % 4);
    for (double& t : interior) t = uniform(rng);
    std::sort(interior.begin(), interior.end());
    const double feature = interior[interior.size() / 2];
    std::vector<double> t(order, 0.0);
    for (double x : interior) {
      t.insert(t.end(), x == feature ? order - 1 : 1, x);
    }
    t.insert(t.end(), order, 1.0);
    const KnotVector knots = KnotVector::Create(order, t).value();
    const SampledBasis basis =
        SampleBasis(knots, std::vector<double>{0.0, feature, 1.0}, /*max_derivative=*/1);
    const SampledBasis plain = SampleBasis(knots, std::vector<double>{0.0, feature, 1.0});
    // The nonzero function: first at 0, the pinned one at the feature, last at 1.
    const int one[3] = {0, knots.FindSpan(feature) - order + 1, knots.num_controls() - 1};
    for (int q = 0; q < 3; ++q) {
      for (const SampledBasis* b : {&basis, &plain}) {
        for (int x = 0; x < order; ++x) {
          const double expected = b->first[q] + x == one[q] ? 1.0 : 0.0;
          if (b->Row(q)[x] != expected) {
            ++inexact;
            if (example.empty()) {
              example = absl::StrFormat("order %d, knots %s, u = %.17g: N_%d = %.17g", order,
                                        absl::StrJoin(t, " "),
                                        q == 0   ? 0.0
                                        : q == 1 ? feature
                                                 : 1.0,
                                        b->first[q] + x, b->Row(q)[x]);
            }
          }
        }
      }
      ++cases;
    }
  }
  EXPECT_EQ(inexact, 0) << "of " << cases << " cases; e.g. " << example;
}

}  // namespace
}  // namespace splinegrid
