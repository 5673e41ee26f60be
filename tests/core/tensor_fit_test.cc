#include "core/fit/solve/tensor_fit.h"

#include <random>

#include "Eigen/Dense"
#include "core/bspline/basis.h"
#include "core/bspline/evaluation.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

// Strictly increasing random parameters from 0 to 1 (clustered: not uniform).
std::vector<double> RandomParams(std::mt19937& rng, int count) {
  if (count == 1) return {0.0};
  std::uniform_real_distribution<double> step(0.2, 1.8);
  std::vector<double> p(count, 0.0);
  for (int i = 1; i < count; ++i) p[i] = p[i - 1] + step(rng) * step(rng);
  for (double& u : p) u /= p.back();
  p.back() = 1.0;
  return p;
}

// Sample of a polynomial of degree `degree` in each parameter (a different one per coordinate).
StructuredBlock PolynomialBlock(const std::array<std::vector<double>, 3>& params, int degree,
                                int s) {
  const Extents n = {static_cast<int>(params[0].size()), static_cast<int>(params[1].size()),
                     static_cast<int>(params[2].size())};
  StructuredBlock block(n, s);
  for (int k = 0; k < n[2]; ++k) {
    for (int j = 0; j < n[1]; ++j) {
      for (int i = 0; i < n[0]; ++i) {
        const double u = params[0][i], v = params[1][j], w = params[2][k];
        double* p = block.Point(i, j, k);
        const double pu = std::pow(u, degree), pv = std::pow(v, degree), pw = std::pow(w, degree);
        p[0] = 3.0 * pu * pv * pw + u - 2.0 * v * w + 0.5;
        p[1] = -pu + 4.0 * pv - pw * pu + 1.0;
        if (s == 3) p[2] = (1.0 + u) * std::pow(1.0 - v, degree) * (2.0 - w) + pw;
      }
    }
  }
  return block;
}

double MaxAbs(std::span<const double> values) {
  double m = 0.0;
  for (double x : values) m = std::max(m, std::abs(x));
  return m;
}

struct ReproductionCase {
  Extents points;
  Extents controls;
  int order;
};

// A polynomial of degree < k per direction lies in the spline space for any knots, so the
// least-squares fit reproduces it up to rounding (~1e-12 relative), for every end condition.
TEST(TensorFitTest, ReproducesPolynomialsExactly) {
  std::mt19937 rng(42);
  const std::vector<ReproductionCase> cases = {
      {{40, 1, 1}, {4, 1, 1}, 4},   {{40, 1, 1}, {12, 1, 1}, 4},    {{40, 1, 1}, {40, 1, 1}, 4},
      {{33, 21, 1}, {6, 5, 1}, 4},  {{33, 21, 1}, {17, 21, 1}, 4},  {{25, 19, 1}, {9, 8, 1}, 3},
      {{17, 13, 11}, {5, 6, 4}, 4}, {{17, 13, 11}, {11, 9, 11}, 4}, {{12, 10, 9}, {7, 7, 7}, 5},
      {{2, 30, 20}, {2, 8, 6}, 4},
  };
  for (const ReproductionCase& c : cases) {
    for (int s : {2, 3}) {
      for (EndCondition ends : {EndCondition::kFree, EndCondition::kInterpolate}) {
        std::array<std::vector<double>, 3> params;
        std::array<KnotVector, 3> knots;
        int degree = c.order - 1;
        for (int d = 0; d < 3; ++d) {
          params[d] = RandomParams(rng, c.points[d]);
          if (c.points[d] == 1) continue;
          const int k = std::min(c.order, c.controls[d]);
          degree = std::min(degree, k - 1);
          knots[d] = KnotVector::Averaged(k, c.controls[d], params[d]).value();
        }
        const StructuredBlock block = PolynomialBlock(params, degree, s);
        const TensorSpline spline = FitTensor(block, params, knots, ends).value();
        const Deviation dev = MeasureDeviation(spline, params, block).value();
        EXPECT_LT(dev.max, 1e-12 * MaxAbs(block.coords()))
            << c.points[0] << "x" << c.points[1] << "x" << c.points[2] << " -> " << c.controls[0]
            << "x" << c.controls[1] << "x" << c.controls[2] << " order " << c.order << " s " << s;
        // Also exact between the data: compare with the polynomial at random parameters.
        std::uniform_real_distribution<double> uniform(0.0, 1.0);
        for (int trial = 0; trial < 20; ++trial) {
          std::array<std::vector<double>, 3> at;
          for (int d = 0; d < 3; ++d) at[d] = {c.points[d] == 1 ? 0.0 : uniform(rng)};
          const StructuredBlock exact = PolynomialBlock(at, degree, s);
          const Point3 p = EvaluatePoint(spline, {at[0][0], at[1][0], at[2][0]});
          for (int x = 0; x < s; ++x) {
            EXPECT_NEAR(p[x], exact.coords()[x], 1e-12 * MaxAbs(block.coords()));
          }
        }
      }
    }
  }
}

// The dense oracle: the Kronecker collocation matrix (C (x) B (x) A), solved by dense QR.
// The tensor fit with free ends is that least-squares solution exactly.
Eigen::MatrixXd DenseCollocation(const KnotVector& knots, const std::vector<double>& params) {
  const SampledBasis b = SampleBasis(knots, params);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(params.size(), knots.num_controls());
  for (int q = 0; q < b.num_samples(); ++q) {
    for (int t = 0; t < b.order; ++t) a(q, b.first[q] + t) = b.Row(q)[t];
  }
  return a;
}

TEST(TensorFitTest, FreeEndsEqualDenseKroneckerLeastSquares) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> noise(-1.0, 1.0);
  const Extents points = {9, 8, 7}, controls = {5, 4, 5};
  std::array<std::vector<double>, 3> params;
  std::array<KnotVector, 3> knots;
  for (int d = 0; d < 3; ++d) {
    params[d] = RandomParams(rng, points[d]);
    knots[d] = KnotVector::Averaged(4, controls[d], params[d]).value();
  }
  StructuredBlock block(points, 3);
  for (double& x : block.coords()) x = noise(rng);
  const TensorSpline spline = FitTensor(block, params, knots, EndCondition::kFree).value();

  // Kronecker product with i fastest: row index i + m0 (j + m1 k), column a + n0 (b + n1 c).
  const Eigen::MatrixXd a = DenseCollocation(knots[0], params[0]);
  const Eigen::MatrixXd b = DenseCollocation(knots[1], params[1]);
  const Eigen::MatrixXd c = DenseCollocation(knots[2], params[2]);
  Eigen::MatrixXd kron(a.rows() * b.rows() * c.rows(), a.cols() * b.cols() * c.cols());
  for (int k = 0; k < c.rows(); ++k)
    for (int j = 0; j < b.rows(); ++j)
      for (int i = 0; i < a.rows(); ++i)
        for (int z = 0; z < c.cols(); ++z)
          for (int y = 0; y < b.cols(); ++y)
            for (int x = 0; x < a.cols(); ++x)
              kron(i + a.rows() * (j + b.rows() * k), x + a.cols() * (y + b.cols() * z)) =
                  a(i, x) * b(j, y) * c(k, z);
  Eigen::MatrixXd rhs(kron.rows(), 3);
  for (int p = 0; p < rhs.rows(); ++p)
    for (int x = 0; x < 3; ++x) rhs(p, x) = block.coords()[3 * p + x];
  const Eigen::MatrixXd dense = kron.colPivHouseholderQr().solve(rhs);
  for (int p = 0; p < dense.rows(); ++p)
    for (int x = 0; x < 3; ++x) EXPECT_NEAR(spline.control()[3 * p + x], dense(p, x), 1e-11);
  const double dense_residual = (kron * dense - rhs).norm();
  const Deviation dev = MeasureDeviation(spline, params, block).value();
  EXPECT_NEAR(dev.rms * std::sqrt(double(block.num_points())), dense_residual,
              1e-12 * dense_residual);
}

TEST(TensorFitTest, InterpolatedEndsReproduceCornersAndBoundaryFits) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> noise(-1.0, 1.0);
  const Extents points = {15, 12, 1};
  std::array<std::vector<double>, 3> params = {RandomParams(rng, 15), RandomParams(rng, 12), {0.0}};
  const std::array<KnotVector, 3> knots = {KnotVector::Averaged(4, 7, params[0]).value(),
                                           KnotVector::Averaged(4, 6, params[1]).value(),
                                           KnotVector()};
  StructuredBlock block(points, 3);
  for (double& x : block.coords()) x = noise(rng);
  const TensorSpline spline = FitTensor(block, params, knots, EndCondition::kInterpolate).value();
  // Corners exactly.
  for (int j : {0, 11}) {
    for (int i : {0, 14}) {
      const Point3 p = EvaluatePoint(spline, {params[0][i], params[1][j], 0.0});
      for (int x = 0; x < 3; ++x) EXPECT_EQ(p[x], block.Point(i, j, 0)[x]);
    }
  }
  // The edge j = 0 is the 1D fit of that edge's data alone.
  StructuredBlock edge({15, 1, 1}, 3);
  for (int i = 0; i < 15; ++i)
    for (int x = 0; x < 3; ++x) edge.Point(i, 0, 0)[x] = block.Point(i, 0, 0)[x];
  const TensorSpline edge_fit =
      FitTensor(edge, {params[0], {0.0}, {0.0}}, {knots[0], KnotVector(), KnotVector()},
                EndCondition::kInterpolate)
          .value();
  for (int a = 0; a < 7; ++a)
    for (int x = 0; x < 3; ++x)
      EXPECT_NEAR(spline.ControlPoint(a, 0, 0)[x], edge_fit.ControlPoint(a, 0, 0)[x], 1e-14);
}

TEST(FitBlockTest, ReportsSummaryAndInterpolatesWhenCountsEqualPoints) {
  StructuredBlock block({21, 11, 1}, 2);
  for (int j = 0; j < 11; ++j) {
    for (int i = 0; i < 21; ++i) {
      const double r = 1.0 + j * 0.3, t = M_PI * i / 20.0;
      block.Point(i, j, 0)[0] = r * std::cos(t);
      block.Point(i, j, 0)[1] = r * std::sin(t);
    }
  }
  FitOptions interpolate;
  const FittedBlock exact = FitBlock(block, interpolate).value();
  EXPECT_LT(exact.summary.deviation.max, 1e-12);
  EXPECT_EQ(exact.summary.num_control_points, 21 * 11);
  FitOptions coarse;
  coarse.control_counts = {8, 4, 0};
  const FittedBlock fitted = FitBlock(block, coarse).value();
  EXPECT_EQ(fitted.spline.control_extents(), (Extents{8, 4, 1}));
  EXPECT_EQ(fitted.summary.num_points, 231);
  EXPECT_EQ(fitted.summary.num_control_points, 32);
  EXPECT_NEAR(fitted.summary.compression_ratio, 231.0 / 32, 1e-12);
  EXPECT_GT(fitted.summary.deviation.max, fitted.summary.deviation.rms);
  EXPECT_LT(fitted.summary.deviation.max, 1e-2);  // a smooth annulus
  EXPECT_GE(fitted.summary.seconds, 0.0);
  // The reported worst point really is that far off.
  const Extents at = fitted.summary.deviation.max_at;
  const Point3 p = EvaluatePoint(fitted.spline, {fitted.distribution.params(0)[at[0]],
                                                 fitted.distribution.params(1)[at[1]], 0.0});
  EXPECT_NEAR(
      std::hypot(p[0] - block.Point(at[0], at[1], 0)[0], p[1] - block.Point(at[0], at[1], 0)[1]),
      fitted.summary.deviation.max, 1e-14);
}

// A block whose i-lines run along two straight sides meeting at a right angle (the corner of
// a blunt base), fitted through its points: with a break at the corner each piece is a cubic
// through collinear points, so the fitted lines stay on the sides between the points; a C2
// interpolant swings off them beside the corner.
TEST(FitBlockTest, BreaksKeepACornerOfTheData) {
  const int kCorner = 6, ni = 16, nj = 4;
  StructuredBlock block({ni, nj, 1}, 2);
  for (int j = 0; j < nj; ++j) {
    for (int i = 0; i < ni; ++i) {
      const double s = (i <= kCorner ? i : kCorner + 1.7 * (i - kCorner)) * (1.0 + 0.1 * j);
      double* p = block.Point(i, j, 0);
      p[0] = std::min(s, kCorner * (1.0 + 0.1 * j));  // along x, then up along y
      p[1] = std::max(0.0, s - kCorner * (1.0 + 0.1 * j)) + j;
    }
  }
  // The largest distance of the fitted i-lines, sampled finely, from the two sides.
  auto off_sides = [&](const FittedBlock& fitted) {
    double worst = 0.0;
    for (int j = 0; j < nj; ++j) {
      const double v = fitted.distribution.params(1)[j], corner_x = kCorner * (1.0 + 0.1 * j);
      for (int q = 0; q <= 600; ++q) {
        const Point3 p = EvaluatePoint(fitted.spline, {q / 600.0, v, 0.0});
        worst = std::max(worst, std::min(std::abs(p[1] - j), std::abs(p[0] - corner_x)) +
                                    std::max({0.0, p[0] - corner_x, j - p[1]}));
      }
    }
    return worst;
  };
  FitOptions options;
  const FittedBlock smooth = FitBlock(block, options).value();
  EXPECT_GT(off_sides(smooth), 1e-2);
  options.breaks[0] = {kCorner};
  const FittedBlock broken = FitBlock(block, options).value();
  EXPECT_EQ(broken.spline.control_extents(), (Extents{ni, nj, 1}));  // still interpolation
  EXPECT_LT(broken.summary.deviation.max, 1e-12);
  EXPECT_EQ(broken.spline.knots(0).Multiplicity(broken.distribution.params(0)[kCorner]), 3);
  EXPECT_LT(off_sides(broken), 1e-12);
  // Breaks are checked like every option.
  options.breaks[0] = {kCorner, kCorner};
  EXPECT_THAT(FitBlock(block, options).status().message(),
              HasSubstr("breaks[0][1] = 6 is not ascending inside [1, 14]"));
  options.breaks[0] = {0};
  EXPECT_THAT(FitBlock(block, options).status().message(), HasSubstr("breaks[0][0] = 0"));
}

TEST(FitBlockTest, RejectsBadOptionsAndData) {
  StructuredBlock block({10, 6, 1}, 3);
  for (size_t i = 0; i < block.coords().size(); ++i) block.coords()[i] = std::sin(double(i));
  FitOptions options;
  options.control_counts = {4, 4, 0};
  options.order = 4;
  EXPECT_TRUE(FitBlock(block, options).ok());
  // Fewer controls than the order: refused, not fitted at a lower order.
  options.control_counts = {3, 4, 0};
  EXPECT_THAT(FitBlock(block, options).status().message(),
              HasSubstr("control_counts[0] = 3 is below order = 4"));
  options.control_counts = {11, 4, 0};
  EXPECT_THAT(FitBlock(block, options).status().message(),
              HasSubstr("control_counts[0] = 11 exceeds the 10 points of the block in i"));
  options.control_counts = {5, 1, 0};
  EXPECT_THAT(FitBlock(block, options).status().message(), HasSubstr("control_counts[1] = 1"));
  options.control_counts = {5, 4, 3};
  EXPECT_THAT(FitBlock(block, options).status().message(), HasSubstr("single point"));
  options = FitOptions();
  options.order = 1;
  EXPECT_THAT(FitBlock(block, options).status().message(), HasSubstr("order = 1"));
  options = FitOptions();
  block.Point(3, 2, 0)[1] = NAN;
  const absl::Status status = FitBlock(block, options).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("point (3, 2, 0) coordinate y is nan"));
}

TEST(FitBlockTest, HonoursCancellation) {
  StructuredBlock block({30, 30, 30}, 3);
  for (size_t i = 0; i < block.coords().size(); ++i) block.coords()[i] = double(i % 97);
  FitOptions options;
  options.control_counts = {8, 8, 8};
  int polls = 0;
  options.cancel = [&polls] { return ++polls > 2; };
  EXPECT_EQ(FitBlock(block, options).status().code(), absl::StatusCode::kCancelled);
}

}  // namespace
}  // namespace splinegrid
