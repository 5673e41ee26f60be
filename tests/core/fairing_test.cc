// Fairing: the jump rows (finite differences of the controls on uniform knots, skipped at
// multiple knots, checked against the derivative jumps evaluated on both sides of a knot), the
// trade-off lambda controls (a theorem of penalised least squares: the penalty falls and the
// residual rises with lambda), and faired tensor fits of curves, surfaces and volumes.
#include "core/fit/solve/fairing.h"

#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "core/bspline/evaluation.h"
#include "core/fit/solve/tensor_fit.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

// Basis derivative rounding: coefficients of order 1 computed from knots of order 1e-1.
constexpr double kCoefficientTol = 1e-9;
// Penalised least squares: penalty non-increasing and residual non-decreasing in lambda, up to
// the rounding of the banded QR (relative).
constexpr double kMonotoneSlack = 1e-9;

// Binomial coefficients with alternating sign: the k-th difference of k + 1 controls.
std::vector<double> KthDifference(int k) {
  std::vector<double> c(k + 1);
  double binom = 1.0;
  for (int s = 0; s <= k; ++s) {
    c[s] = ((k - s) % 2 == 0 ? 1.0 : -1.0) * binom;
    binom = binom * (k - s) / (s + 1);
  }
  return c;
}

// `per_span` data parameters inside every knot span of `knots`, none on a knot.
std::vector<double> ParamsInSpans(const KnotVector& knots, int per_span) {
  std::vector<double> params;
  const std::vector<double> breaks = [&] {
    std::vector<double> b = {0.0};
    for (double t : knots.InteriorBreaks()) b.push_back(t);
    b.push_back(1.0);
    return b;
  }();
  for (size_t s = 0; s + 1 < breaks.size(); ++s) {
    for (int q = 0; q < per_span; ++q) {
      params.push_back(breaks[s] + (breaks[s + 1] - breaks[s]) * (q + 0.5) / per_span);
    }
  }
  return params;
}

// On uniform knots of width h, h^(k-1) times the jump of the (k-1)-th derivative is the k-th
// difference of the k + 1 controls around the knot (for cubics, +-(-1, 4, -6, 4, -1)); each row
// is weighted by sqrt(lambda m_q), m_q the mean number of data points in the two spans.
TEST(FairingTest, UniformKnotsGiveKthDifferences) {
  for (int k = 2; k <= 5; ++k) {
    SCOPED_TRACE(k);
    const KnotVector knots = KnotVector::Uniform(k, 3 * k + 4);
    const std::vector<double> params = ParamsInSpans(knots, 3);
    const double lambda = 2.5;
    const std::vector<PenaltyRow> rows = JumpPenaltyRows(knots, params, lambda);
    ASSERT_EQ(static_cast<int>(rows.size()), knots.num_controls() - k);  // every interior knot
    const std::vector<double> expected = KthDifference(k);
    int uniform_rows = 0;
    for (size_t r = 0; r < rows.size(); ++r) {
      const int q = static_cast<int>(r) + k;  // knot index of the row
      EXPECT_EQ(rows[r].first, q - k);
      ASSERT_EQ(static_cast<int>(rows[r].values.size()), k + 1);
      // Away from the clamped ends the k + 1 functions have uniform supports.
      if (q - k < k - 1 || q > knots.num_controls() - k) continue;
      const double weight = std::sqrt(lambda * 3.0);  // 6 points in the two spans
      const double sign = rows[r].values[0] * expected[0] > 0 ? 1.0 : -1.0;
      for (int s = 0; s <= k; ++s) {
        EXPECT_NEAR(rows[r].values[s], sign * weight * expected[s], kCoefficientTol) << s;
      }
      ++uniform_rows;
    }
    EXPECT_GE(uniform_rows, 3);
  }
}

// The scaled jumps equal h_q^(k-1) (s^(k-1)(t_q+) - s^(k-1)(t_q-)), the derivative evaluated
// inside the two spans (it is constant on each), h_q the mean of their widths; knots of
// multiplicity > 1 get no row.
TEST(FairingTest, JumpsMatchEvaluatedDerivativesAndSkipMultipleKnots) {
  const std::vector<double> t = {0,   0,   0,   0,   0.1,  0.25, 0.3, 0.3, 0.42, 0.5,
                                 0.5, 0.5, 0.6, 0.7, 0.85, 1,    1,   1,   1};
  const KnotVector knots = KnotVector::Create(4, t).value();
  std::vector<double> controls(knots.num_controls());
  for (size_t j = 0; j < controls.size(); ++j) controls[j] = std::sin(1.7 * j) + 0.1 * j * j;
  const std::vector<double> jumps = ScaledDerivativeJumps(knots, controls);
  const std::vector<int> simple = {4, 5, 8, 12, 13, 14};  // 0.1 0.25 0.42 0.6 0.7 0.85
  ASSERT_EQ(jumps.size(), simple.size());
  const std::vector<PenaltyRow> rows = JumpPenaltyRows(knots, ParamsInSpans(knots, 4), 1.0);
  ASSERT_EQ(rows.size(), simple.size());

  std::vector<double> net(2 * controls.size(), 0.0);
  for (size_t j = 0; j < controls.size(); ++j) net[2 * j] = controls[j];
  const TensorSpline curve =
      TensorSpline::Create({knots, KnotVector(), KnotVector()}, 2, net).value();
  for (size_t r = 0; r < simple.size(); ++r) {
    const int q = simple[r];
    EXPECT_EQ(rows[r].first, q - 4);
    const double left = 0.5 * (t[q - 1] + t[q]), right = 0.5 * (t[q] + t[q + 1]);
    const double d_left = EvaluateDerivatives(curve, {left, 0, 0}, 3)(3, 0, 0)[0];
    const double d_right = EvaluateDerivatives(curve, {right, 0, 0}, 3)(3, 0, 0)[0];
    const double h = 0.5 * (t[q + 1] - t[q - 1]);
    const double expected = h * h * h * (d_right - d_left);
    EXPECT_NEAR(jumps[r], expected, 1e-9 * (1.0 + std::abs(expected))) << "knot " << t[q];
    // The row applied to the controls is the jump times sqrt(lambda m_q) = sqrt(m_q).
    double applied = 0.0;
    for (int s = 0; s <= 4; ++s) applied += rows[r].values[s] * controls[rows[r].first + s];
    EXPECT_NEAR(applied, std::sqrt(4.0) * jumps[r], 1e-9 * (1.0 + std::abs(applied)));
  }
}

TEST(FairingTest, NoRowsWithoutWeightOrSimpleKnots) {
  const KnotVector knots = KnotVector::Uniform(4, 9);
  const std::vector<double> params = ParamsInSpans(knots, 3);
  EXPECT_TRUE(JumpPenaltyRows(knots, params, 0.0).empty());
  EXPECT_TRUE(JumpPenaltyRows(knots, params, -1.0).empty());
  EXPECT_EQ(JumpPenaltyRows(knots, params, 1e-12).size(), 5u);
  EXPECT_TRUE(JumpPenaltyRows(KnotVector::Uniform(4, 4), params, 1.0).empty());  // one piece
  EXPECT_TRUE(
      JumpPenaltyRows(KnotVector(), std::vector<double>{0.0}, 1.0).empty());  // unused direction
  const KnotVector feature = KnotVector::Create(3, {0, 0, 0, 0.5, 0.5, 1, 1, 1}).value();
  EXPECT_TRUE(JumpPenaltyRows(feature, params, 1.0).empty());
  EXPECT_TRUE(ScaledDerivativeJumps(feature, {1, 2, 3, 4, 5}).empty());
}

TEST(FairingTest, OptionsValidation) {
  FairingOptions options;
  options.weight = -1.0;
  EXPECT_TRUE(options.Validate().ok());  // off: the weight is unused
  for (FairingMode mode : {FairingMode::kWeight, FairingMode::kToTolerance}) {
    options.mode = mode;
    for (double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
      options.weight = bad;
      const absl::Status status = options.Validate();
      EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << bad;
      EXPECT_THAT(status.message(), HasSubstr("weight"));
    }
    options.weight = 1e-6;
    EXPECT_TRUE(options.Validate().ok());
  }
}

// A wiggly curve: a smooth wave with a fast ripple, at parameters with the same number of
// points in every span (so m_q is the same for every knot and the scaled jumps are the
// penalty up to a constant factor).
StructuredBlock WigglyCurve(const std::vector<double>& params) {
  StructuredBlock block({static_cast<int>(params.size()), 1, 1}, 2);
  for (size_t r = 0; r < params.size(); ++r) {
    const double u = params[r];
    block.Point(r, 0, 0)[0] = u + 0.01 * std::sin(83.0 * u);
    block.Point(r, 0, 0)[1] = std::sin(6.0 * u) + 0.03 * std::sin(97.0 * u);
  }
  return block;
}

// Sum over both coordinates of the squared scaled jumps of `spline`'s direction-0 controls.
double SquaredJumps(const TensorSpline& spline) {
  const int s = spline.spatial_dim();
  const Extents n = spline.control_extents();
  double sum = 0.0;
  for (int64_t line = 0; line < int64_t{n[1]} * n[2]; ++line) {
    for (int c = 0; c < s; ++c) {
      std::vector<double> values(n[0]);
      for (int a = 0; a < n[0]; ++a) values[a] = spline.control()[s * (line * n[0] + a) + c];
      for (double j : ScaledDerivativeJumps(spline.knots(0), values)) sum += j * j;
    }
  }
  return sum;
}

TEST(FairingTest, LargerLambdaSmoothsMoreAndFitsLess) {
  const KnotVector knots = KnotVector::Uniform(4, 24);
  const std::vector<double> params = ParamsInSpans(knots, 4);
  const StructuredBlock block = WigglyCurve(params);
  double previous_jumps = INFINITY, previous_residual = -1.0;
  double first_jumps = 0.0, first_residual = 0.0;
  for (double lambda : {0.0, 1e-4, 1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0, 1e3, 1e4}) {
    SCOPED_TRACE(lambda);
    const TensorSpline fit =
        FitTensor(block, {params, {0.0}, {0.0}}, {knots, KnotVector(), KnotVector()},
                  EndCondition::kFree, {}, {}, lambda)
            .value();
    const Deviation dev = MeasureDeviation(fit, {params, {0.0}, {0.0}}, block).value();
    const double residual = dev.rms * dev.rms * block.num_points();
    const double jumps = SquaredJumps(fit);
    EXPECT_LE(jumps, previous_jumps * (1.0 + kMonotoneSlack));
    EXPECT_GE(residual, previous_residual * (1.0 - kMonotoneSlack));
    if (lambda == 0.0) {
      first_jumps = jumps;
      first_residual = residual;
    }
    previous_jumps = jumps;
    previous_residual = residual;
  }
  // Not just monotone: the strongest weight removes almost all the jumps, at a price.
  EXPECT_LT(previous_jumps, 1e-3 * first_jumps);
  EXPECT_GT(previous_residual, 2.0 * first_residual);
}

// Tensor fits with fairing: data that a single polynomial piece per direction reproduces are
// reproduced with any weight (their jumps vanish); wiggly data are smoothed (smaller jumps,
// larger deviation), with the corners still exact.
TEST(FairingTest, FitTensorWithFairingOnCurveSurfaceVolume) {
  for (const Extents& m : {Extents{41, 1, 1}, Extents{21, 17, 1}, Extents{13, 11, 9}}) {
    SCOPED_TRACE(m[0]);
    std::array<std::vector<double>, 3> params;
    std::array<KnotVector, 3> knots;
    for (int d = 0; d < 3; ++d) {
      params[d] = {0.0};
      if (m[d] == 1) continue;
      for (int r = 1; r < m[d]; ++r) params[d].push_back(std::pow(r / (m[d] - 1.0), 1.3));
      knots[d] = KnotVector::Averaged(4, m[d] / 2, params[d]).value();
    }
    StructuredBlock poly(m, 3), wiggly(m, 3);
    for (int k = 0; k < m[2]; ++k) {
      for (int j = 0; j < m[1]; ++j) {
        for (int i = 0; i < m[0]; ++i) {
          const double u = params[0][i], v = params[1][j], w = params[2][k];
          const double p[3] = {u * u * u - v * w, u * v * v + w * w * w, 1.0 + u - 2.0 * v * w};
          for (int c = 0; c < 3; ++c) {
            poly.Point(i, j, k)[c] = p[c];
            wiggly.Point(i, j, k)[c] = p[c] + 0.02 * std::sin(40.0 * (u + 2.0 * v + 3.0 * w + c));
          }
        }
      }
    }
    const double lambda = 100.0;
    const TensorSpline exact =
        FitTensor(poly, params, knots, EndCondition::kInterpolate, {}, {}, lambda).value();
    EXPECT_LT(MeasureDeviation(exact, params, poly).value().max, 1e-12);

    const TensorSpline plain = FitTensor(wiggly, params, knots, EndCondition::kInterpolate).value();
    const TensorSpline faired =
        FitTensor(wiggly, params, knots, EndCondition::kInterpolate, {}, {}, lambda).value();
    EXPECT_GT(MeasureDeviation(faired, params, wiggly).value().rms,
              MeasureDeviation(plain, params, wiggly).value().rms);
    EXPECT_LT(SquaredJumps(faired), 0.5 * SquaredJumps(plain));
    const Extents n = faired.control_extents();
    const double* corner = faired.ControlPoint(n[0] - 1, n[1] - 1, n[2] - 1);
    const double* data = wiggly.Point(m[0] - 1, m[1] - 1, m[2] - 1);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(corner[c], data[c]);
  }
}

}  // namespace
}  // namespace splinegrid
