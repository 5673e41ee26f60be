// DirectionFit: pinned controls at kinks, zero ends, penalty rows, rank deficiency, the
// Schoenberg-Whitney predicate against the numerical rank check, and layout independence of
// Apply. Dense least squares (Eigen) is the oracle.
#include "core/fit/solve/direction_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "Eigen/Dense"
#include "absl/strings/str_cat.h"
#include "core/bspline/basis.h"
#include "core/bspline/evaluation.h"
#include "core/bspline/tensor_spline.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

// A straight segment is linear in its chord-length parameter, so a spline space containing the
// piecewise linear function reproduces it up to rounding; relative to the largest coordinate.
constexpr double kReproductionRelTol = 1e-12;
// Banded Givens QR vs dense Householder QR, relative to the largest control value.
constexpr double kDenseAgreementRelTol = 1e-11;

// The dense collocation matrix A(q, j) = N_j(u_q).
Eigen::MatrixXd DenseCollocation(const KnotVector& knots, const std::vector<double>& params) {
  const SampledBasis b = SampleBasis(knots, params);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(params.size(), knots.num_controls());
  for (int q = 0; q < b.num_samples(); ++q) {
    for (int t = 0; t < b.order; ++t) a(q, b.first[q] + t) = b.Row(q)[t];
  }
  return a;
}

// Clamped knots of `order` on [0, 1] with the given interior knots (sorted here).
KnotVector Knots(int order, std::vector<double> interior) {
  std::sort(interior.begin(), interior.end());
  std::vector<double> t(order, 0.0);
  t.insert(t.end(), interior.begin(), interior.end());
  t.insert(t.end(), order, 1.0);
  return KnotVector::Create(order, std::move(t)).value();
}

// Fits `values` (m points of `s` interleaved coordinates, one line) and returns the n control
// points (interleaved).
std::vector<double> FitLine(const DirectionFit& fit, const std::vector<double>& values, int s) {
  std::vector<double> out(static_cast<size_t>(s) * fit.num_controls());
  EXPECT_TRUE(fit.Apply(values.data(), s, 1, out.data()).ok());
  return out;
}

double MaxAbs(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

// ----- Pins at a kink ------------------------------------------------------------------------

// A V-shaped polyline a -> kink -> b sampled densely with chord-length parameters.
struct Polyline {
  std::vector<double> points;  // (x, y) interleaved
  std::vector<double> params;
  int kink_row = 0;
};

Polyline SampleV(const double a[2], const double kink[2], const double b[2], int left, int right) {
  Polyline v;
  for (int r = 0; r < left; ++r) {
    const double t = static_cast<double>(r) / left;
    v.points.push_back(a[0] + t * (kink[0] - a[0]));
    v.points.push_back(a[1] + t * (kink[1] - a[1]));
  }
  v.kink_row = left;
  v.points.push_back(kink[0]);
  v.points.push_back(kink[1]);
  for (int r = 1; r <= right; ++r) {
    const double t = static_cast<double>(r) / right;
    v.points.push_back(kink[0] + t * (b[0] - kink[0]));
    v.points.push_back(kink[1] + t * (b[1] - kink[1]));
  }
  const int m = left + right + 1;
  v.params.assign(m, 0.0);
  for (int r = 1; r < m; ++r) {
    v.params[r] = v.params[r - 1] + std::hypot(v.points[2 * r] - v.points[2 * r - 2],
                                               v.points[2 * r + 1] - v.points[2 * r - 1]);
  }
  const double length = v.params.back();
  for (double& u : v.params) u /= length;
  v.params.back() = 1.0;
  return v;
}

// A knot of multiplicity order - 1 at the kink parameter and a pin of the control whose basis
// function is 1 there: the fit passes through the kink exactly and each straight side is fitted
// on its own, so it is reproduced up to rounding.
TEST(DirectionFitTest, PinnedKinkIsExactAndEachSideIsReproduced) {
  struct Case {
    double a[2], kink[2], b[2];
    int left, right;
    int order;
  };
  const std::vector<Case> cases = {
      {{-1.0, 0.8}, {0.3, -0.2}, {2.0, 1.5}, 40, 60, 4},
      {{0.0, 0.0}, {1.0, 1.0}, {2.0, 0.0}, 25, 25, 4},
      {{5.0, -3.0}, {5.7, 0.1}, {9.0, 0.4}, 33, 71, 3},
      {{-0.1, 0.0}, {0.0, 0.05}, {0.1, 0.0}, 50, 20, 5},
      {{1.0, 2.0}, {-1.0, 2.5}, {1.5, 3.3}, 17, 45, 4},
  };
  for (const Case& c : cases) {
    const Polyline v = SampleV(c.a, c.kink, c.b, c.left, c.right);
    const double u_kink = v.params[v.kink_row];
    const int k = c.order;
    std::vector<double> interior(k - 1, u_kink);
    for (double f : {0.3, 0.7}) interior.push_back(f * u_kink);
    for (double f : {0.25, 0.5, 0.8}) interior.push_back(u_kink + f * (1.0 - u_kink));
    const KnotVector knots = Knots(k, interior);
    const int pinned = knots.FindSpan(u_kink) - k + 1;
    SCOPED_TRACE(absl::StrCat("kink at ", u_kink, ", order ", k, ", pinned control ", pinned));
    // The pinned control's basis function is the only one that is nonzero at the kink.
    const SampledBasis at_kink = SampleBasis(knots, std::vector<double>{u_kink});
    for (int t = 0; t < k; ++t) {
      EXPECT_NEAR(at_kink.Row(0)[t], at_kink.first[0] + t == pinned ? 1.0 : 0.0, 1e-15);
    }
    const std::vector<Pin> pins = {{pinned, v.kink_row}};
    const DirectionFit fit =
        DirectionFit::Create(knots, v.params, EndCondition::kInterpolate, pins).value();
    const std::vector<double> control = FitLine(fit, v.points, 2);
    // The pinned control and the end controls are the data, bit for bit.
    EXPECT_EQ(control[2 * pinned], c.kink[0]);
    EXPECT_EQ(control[2 * pinned + 1], c.kink[1]);
    EXPECT_EQ(control[0], c.a[0]);
    EXPECT_EQ(control[1], c.a[1]);
    EXPECT_EQ(control[control.size() - 2], c.b[0]);
    EXPECT_EQ(control[control.size() - 1], c.b[1]);

    const TensorSpline curve =
        TensorSpline::Create({knots, KnotVector(), KnotVector()}, 2, control).value();
    const Point3 at = EvaluatePoint(curve, {u_kink, 0.0, 0.0});
    EXPECT_EQ(at[0], c.kink[0]);
    EXPECT_EQ(at[1], c.kink[1]);
    const double tol = kReproductionRelTol * MaxAbs(v.points);
    for (int r = 0; r < static_cast<int>(v.params.size()); ++r) {
      const Point3 p = EvaluatePoint(curve, {v.params[r], 0.0, 0.0});
      ASSERT_NEAR(p[0], v.points[2 * r], tol) << "row " << r;
      ASSERT_NEAR(p[1], v.points[2 * r + 1], tol) << "row " << r;
    }
    // Between the samples too: each side is the straight segment.
    for (double f : {0.13, 0.5, 0.91}) {
      const Point3 left = EvaluatePoint(curve, {f * u_kink, 0.0, 0.0});
      const Point3 right = EvaluatePoint(curve, {u_kink + f * (1.0 - u_kink), 0.0, 0.0});
      for (int x = 0; x < 2; ++x) {
        EXPECT_NEAR(left[x], c.a[x] + f * (c.kink[x] - c.a[x]), tol);
        EXPECT_NEAR(right[x], c.kink[x] + f * (c.b[x] - c.kink[x]), tol);
      }
    }

    // Without the repeated knot a cubic cannot turn the corner: the same number of simple knots
    // leaves a visible error, so the test above is not trivially satisfied.
    std::vector<double> simple;
    for (int t = 0; t < static_cast<int>(interior.size()); ++t) {
      simple.push_back((t + 1.0) / (interior.size() + 1.0));
    }
    const DirectionFit smooth =
        DirectionFit::Create(Knots(k, simple), v.params, EndCondition::kInterpolate).value();
    const std::vector<double> smooth_control = FitLine(smooth, v.points, 2);
    const TensorSpline smooth_curve =
        TensorSpline::Create({Knots(k, simple), KnotVector(), KnotVector()}, 2, smooth_control)
            .value();
    const Point3 near_kink = EvaluatePoint(smooth_curve, {u_kink, 0.0, 0.0});
    EXPECT_GT(std::hypot(near_kink[0] - c.kink[0], near_kink[1] - c.kink[1]), 1e3 * tol);
  }
}

// ----- End conditions and penalties ------------------------------------------------------------

// Random data on random increasing parameters.
struct LineData {
  std::vector<double> params;
  std::vector<double> values;  // s interleaved coordinates per point
};

LineData RandomLine(std::mt19937& rng, int m, int s) {
  std::uniform_real_distribution<double> step(0.2, 1.8), value(-1.0, 1.0);
  LineData line;
  line.params.assign(m, 0.0);
  for (int r = 1; r < m; ++r) line.params[r] = line.params[r - 1] + step(rng);
  for (double& u : line.params) u /= line.params.back();
  line.params.back() = 1.0;
  for (int r = 0; r < m * s; ++r) line.values.push_back(value(rng));
  return line;
}

// Column c of the interleaved values as an Eigen vector.
Eigen::VectorXd Coordinate(const std::vector<double>& values, int s, int c) {
  Eigen::VectorXd x(values.size() / s);
  for (int r = 0; r < x.size(); ++r) x(r) = values[s * r + c];
  return x;
}

TEST(DirectionFitTest, ZeroEndsGiveZeroEndControls) {
  std::mt19937 rng(17);
  for (int order : {2, 3, 4, 6}) {
    const int m = 41, n = 13, s = 3;
    const LineData line = RandomLine(rng, m, s);
    const KnotVector knots = KnotVector::Averaged(order, n, line.params).value();
    const DirectionFit fit = DirectionFit::Create(knots, line.params, EndCondition::kZero).value();
    const std::vector<double> control = FitLine(fit, line.values, s);
    const Eigen::MatrixXd a = DenseCollocation(knots, line.params);
    const double tol = kDenseAgreementRelTol * MaxAbs(control);
    for (int c = 0; c < s; ++c) {
      EXPECT_EQ(control[c], 0.0) << "order " << order;
      EXPECT_EQ(control[s * (n - 1) + c], 0.0) << "order " << order;
      // The interior controls are the least-squares fit with the end columns removed.
      const Eigen::VectorXd interior =
          a.middleCols(1, n - 2).colPivHouseholderQr().solve(Coordinate(line.values, s, c));
      for (int j = 1; j + 1 < n; ++j) {
        EXPECT_NEAR(control[s * j + c], interior(j - 1), tol) << "order " << order;
      }
    }
  }
}

// Second-difference smoothing rows lambda (p_j - 2 p_{j+1} + p_{j+2}).
std::vector<PenaltyRow> SecondDifferences(int n, double lambda) {
  std::vector<PenaltyRow> rows;
  for (int j = 0; j + 2 < n; ++j) rows.push_back({j, {lambda, -2.0 * lambda, lambda}});
  return rows;
}

// The same as a dense matrix (n - 2 x n).
Eigen::MatrixXd DenseSecondDifferences(int n, double lambda) {
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(n - 2, n);
  for (int j = 0; j + 2 < n; ++j) {
    d(j, j) = lambda;
    d(j, j + 1) = -2.0 * lambda;
    d(j, j + 2) = lambda;
  }
  return d;
}

// The dense solution of min ||A p - x||^2 + ||D p||^2, with p_0 = x_0 and p_{n-1} = x_{m-1}
// fixed when `interpolate`.
Eigen::VectorXd DensePenalized(const Eigen::MatrixXd& a, const Eigen::MatrixXd& d,
                               const Eigen::VectorXd& x, bool interpolate) {
  const int m = a.rows(), n = a.cols();
  Eigen::MatrixXd stacked(m + d.rows(), n);
  stacked << a, d;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(m + d.rows());
  rhs.head(m) = x;
  if (!interpolate) return stacked.colPivHouseholderQr().solve(rhs);
  Eigen::VectorXd p(n);
  p(0) = x(0);
  p(n - 1) = x(m - 1);
  rhs -= stacked.col(0) * p(0) + stacked.col(n - 1) * p(n - 1);
  p.segment(1, n - 2) = stacked.middleCols(1, n - 2).colPivHouseholderQr().solve(rhs);
  return p;
}

TEST(DirectionFitTest, PenaltyRowsChangeTheFitAndZeroWeightRowsDoNot) {
  std::mt19937 rng(23);
  const int m = 60, n = 18, s = 2;
  for (EndCondition ends : {EndCondition::kFree, EndCondition::kInterpolate}) {
    const bool interpolate = ends == EndCondition::kInterpolate;
    const LineData line = RandomLine(rng, m, s);
    const KnotVector knots = KnotVector::Averaged(4, n, line.params).value();
    const DirectionFit plain = DirectionFit::Create(knots, line.params, ends).value();
    const std::vector<double> plain_control = FitLine(plain, line.values, s);

    // Zero-weight rows are no rows at all: bit-identical controls.
    const std::vector<PenaltyRow> zero = SecondDifferences(n, 0.0);
    const DirectionFit zero_fit = DirectionFit::Create(knots, line.params, ends, {}, zero).value();
    EXPECT_EQ(FitLine(zero_fit, line.values, s), plain_control);

    const Eigen::MatrixXd a = DenseCollocation(knots, line.params);
    for (double lambda : {0.1, 1.0, 10.0}) {
      SCOPED_TRACE(absl::StrCat(interpolate ? "interpolated" : "free", " ends, lambda ", lambda));
      const DirectionFit fit =
          DirectionFit::Create(knots, line.params, ends, {}, SecondDifferences(n, lambda)).value();
      const std::vector<double> control = FitLine(fit, line.values, s);
      double change = 0.0;
      for (size_t i = 0; i < control.size(); ++i) {
        change = std::max(change, std::abs(control[i] - plain_control[i]));
      }
      EXPECT_GT(change, 1e-2 * MaxAbs(plain_control));
      const double tol = kDenseAgreementRelTol * MaxAbs(control);
      for (int c = 0; c < s; ++c) {
        const Eigen::VectorXd dense = DensePenalized(a, DenseSecondDifferences(n, lambda),
                                                     Coordinate(line.values, s, c), interpolate);
        for (int j = 0; j < n; ++j) EXPECT_NEAR(control[s * j + c], dense(j), tol);
      }
    }
  }
}

// The smallest case of a penalty row narrower than the band: order 2, two controls, one data
// point at u = 0.5 (row [0.5, 0.5]) and the penalty row [1] on p_0. The system
//   [0.5 0.5; 1 0] p = [1; 0]
// is square and regular (p = (0, 2)), so the fit must succeed and reproduce it.
TEST(DirectionFitTest, PenaltyRowShorterThanTheBandIsFullyEliminated) {
  const std::vector<double> params = {0.5};
  const std::vector<PenaltyRow> penalty = {{0, {1.0}}};
  const absl::StatusOr<DirectionFit> fit =
      DirectionFit::Create(KnotVector::Uniform(2, 2), params, EndCondition::kFree, {}, penalty);
  ASSERT_TRUE(fit.ok()) << fit.status();
  const std::vector<double> control = FitLine(*fit, {1.0}, 1);
  EXPECT_NEAR(control[0], 0.0, 1e-15);
  EXPECT_NEAR(control[1], 2.0, 1e-15);
}

// ----- Rank deficiency ------------------------------------------------------------------------

// Data on [0, 0.3] and [0.7, 1] only, with knot spans inside the gap.
std::vector<double> ParamsWithGap() {
  std::vector<double> params;
  for (int r = 0; r < 20; ++r) params.push_back(0.3 * r / 19.0);
  for (int r = 0; r < 20; ++r) params.push_back(0.7 + 0.3 * r / 19.0);
  return params;
}

TEST(DirectionFitTest, KnotSpanWithoutDataIsFailedPrecondition) {
  const std::vector<double> params = ParamsWithGap();
  const KnotVector knots = KnotVector::Uniform(4, 20);  // 17 spans of 1/17
  EXPECT_FALSE(SchoenbergWhitneyHolds(knots, params, {}));
  for (EndCondition ends : {EndCondition::kFree, EndCondition::kInterpolate, EndCondition::kZero}) {
    const absl::StatusOr<DirectionFit> fit = DirectionFit::Create(knots, params, ends);
    EXPECT_EQ(fit.status().code(), absl::StatusCode::kFailedPrecondition);
    EXPECT_THAT(fit.status().message(), HasSubstr("rank deficient"));
    EXPECT_THAT(fit.status().message(), HasSubstr("20 controls of order 4 for 40 points"));
  }
  // Fewer points than controls without penalties is an argument error, not a rank error.
  const absl::StatusOr<DirectionFit> too_few =
      DirectionFit::Create(KnotVector::Uniform(4, 50), params, EndCondition::kFree);
  EXPECT_EQ(too_few.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(too_few.status().message(), HasSubstr("50 control points cannot be fitted to 40"));
}

// A smoothing penalty determines the controls that the data of ParamsWithGap leave free: the
// fit succeeds and equals the dense solution of the stacked system [A; D] p = [x; 0].
TEST(DirectionFitTest, SmoothingPenaltyDeterminesControlsTheDataLeaveFree) {
  const std::vector<double> params = ParamsWithGap();
  const KnotVector knots = KnotVector::Uniform(4, 20);
  const std::vector<PenaltyRow> smoothing = SecondDifferences(20, 1e-3);
  const absl::StatusOr<DirectionFit> smoothed =
      DirectionFit::Create(knots, params, EndCondition::kFree, {}, smoothing);
  ASSERT_TRUE(smoothed.ok()) << smoothed.status();
  std::vector<double> values(params.size());
  for (size_t r = 0; r < params.size(); ++r) values[r] = std::sin(3.0 * params[r]);
  const std::vector<double> control = FitLine(*smoothed, values, 1);
  Eigen::VectorXd x(values.size());
  for (size_t r = 0; r < values.size(); ++r) x(r) = values[r];
  const Eigen::VectorXd dense =
      DensePenalized(DenseCollocation(knots, params), DenseSecondDifferences(20, 1e-3), x, false);
  for (int j = 0; j < 20; ++j) {
    EXPECT_NEAR(control[j], dense(j), kDenseAgreementRelTol * dense.cwiseAbs().maxCoeff()) << j;
  }
}

// Uniform data with a few coarse knot spans followed by a long stretch of one data point per
// span (knots at the midpoints between data, as the adaptive fit produces when it refines a
// region fully). The collocation matrix is well conditioned (checked densely), so the fit must
// succeed and equal the dense least-squares solution. The Givens rotations of this pattern pass
// a geometrically shrinking rounding residue from one R row to the next; once it is below
// ~1e-162 its square underflows and sqrt(r^2 + h^2) = 0 must not turn into 0 / 0.
TEST(DirectionFitTest, LongStretchOfOnePointPerSpanIsWellPosed) {
  const int m = 201;
  std::vector<double> params(m);
  for (int r = 0; r < m; ++r) params[r] = static_cast<double>(r) / (m - 1);
  std::vector<double> interior;
  for (int r = 3; r < 20; r += 3) interior.push_back((r + 0.5) / (m - 1));
  for (int r = 20; r + 4 < m; ++r) interior.push_back((r + 0.5) / (m - 1));
  const KnotVector knots = Knots(4, interior);
  ASSERT_TRUE(SchoenbergWhitneyHolds(knots, params, {}));
  const Eigen::MatrixXd a = DenseCollocation(knots, params);
  const Eigen::VectorXd singular = a.jacobiSvd().singularValues();
  ASSERT_GT(singular(singular.size() - 1), 1e-3 * singular(0));  // well conditioned
  std::vector<double> values(m);
  for (int r = 0; r < m; ++r) values[r] = std::sin(4.0 * params[r]) + params[r] * params[r];
  for (EndCondition ends : {EndCondition::kFree, EndCondition::kInterpolate}) {
    const absl::StatusOr<DirectionFit> fit = DirectionFit::Create(knots, params, ends);
    ASSERT_TRUE(fit.ok()) << fit.status();
    const std::vector<double> control = FitLine(*fit, values, 1);
    for (double c : control) ASSERT_TRUE(std::isfinite(c));
    if (ends == EndCondition::kFree) {
      Eigen::VectorXd x(m);
      for (int r = 0; r < m; ++r) x(r) = values[r];
      const Eigen::VectorXd dense = a.colPivHouseholderQr().solve(x);
      for (int j = 0; j < knots.num_controls(); ++j) {
        EXPECT_NEAR(control[j], dense(j), kDenseAgreementRelTol * dense.cwiseAbs().maxCoeff());
      }
    }
  }
}

// ----- Schoenberg-Whitney vs the numerical rank check ------------------------------------------

// A random clamped knot vector on [0, 1]: random interior knots, some repeated (multiplicity up
// to order - 1).
KnotVector RandomKnots(std::mt19937& rng, int order, int num_controls) {
  std::uniform_real_distribution<double> uniform(0.02, 0.98);
  std::uniform_int_distribution<int> multiplicity(2, std::max(order - 1, 2));
  std::vector<double> interior;
  while (static_cast<int>(interior.size()) < num_controls - order) {
    const double t = uniform(rng);
    const int times = order > 2 && uniform(rng) < 0.25 ? multiplicity(rng) : 1;
    interior.insert(interior.end(),
                    std::min(times, num_controls - order - static_cast<int>(interior.size())), t);
  }
  return Knots(order, interior);
}

// Random clustered parameters: a few tight clusters and some parameters exactly at knots (the
// open/closed support boundaries), sorted and distinct; with `ends` the first is 0, the last 1.
std::vector<double> RandomClusteredParams(std::mt19937& rng, const KnotVector& knots, int m,
                                          bool ends) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0), spread(0.0, 0.04);
  std::uniform_int_distribution<int> clusters(1, 4),
      pick(0, knots.num_controls() + knots.order() - 1);
  std::vector<double> centres(clusters(rng)), widths(centres.size());
  for (size_t c = 0; c < centres.size(); ++c) {
    centres[c] = uniform(rng);
    widths[c] = spread(rng);
  }
  std::vector<double> params;
  if (ends) params = {0.0, 1.0};
  for (int attempt = 0; static_cast<int>(params.size()) < m && attempt < 100 * m; ++attempt) {
    double u;
    if (uniform(rng) < 0.2) {
      u = knots.knot(pick(rng));  // exactly at a knot
    } else {
      const size_t c = static_cast<size_t>(uniform(rng) * centres.size()) % centres.size();
      u = std::clamp(centres[c] + widths[c] * (2.0 * uniform(rng) - 1.0), 0.0, 1.0);
    }
    // Distinct, and not within 1e-9 of another (no near-duplicates that would be rounding
    // noise for the rank check).
    bool close = false;
    for (double p : params) close |= std::abs(p - u) < 1e-9;
    if (!close) params.push_back(u);
  }
  std::sort(params.begin(), params.end());
  return params;
}

TEST(SchoenbergWhitneyTest, AgreesWithTheRankCheckOfCreate) {
  std::mt19937 rng(2024);
  int holds = 0, fails = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::uniform_int_distribution<int> order_dist(2, 5), extra(0, 10), pin_count(0, 2);
    const int order = order_dist(rng);
    const int n = order + extra(rng);
    const KnotVector knots = RandomKnots(rng, order, n);
    const bool ends = trial % 2 == 1;
    std::uniform_int_distribution<int> m_dist(n, n + 12);
    const std::vector<double> params = RandomClusteredParams(rng, knots, m_dist(rng), ends);
    const int m = static_cast<int>(params.size());
    if (m < n) continue;  // Create rejects that up front (INVALID_ARGUMENT)
    std::vector<int> pinned;
    if (ends) pinned = {0, n - 1};
    std::vector<Pin> pins;
    if (n > 3) {
      std::uniform_int_distribution<int> control(1, n - 2), row(0, m - 1);
      for (int p = pin_count(rng); p > 0; --p) {
        const int c = control(rng);
        if (std::find(pinned.begin(), pinned.end(), c) != pinned.end()) continue;
        pinned.push_back(c);
        pins.push_back({c, row(rng)});
      }
    }
    const bool sw = SchoenbergWhitneyHolds(knots, params, pinned);
    const absl::StatusOr<DirectionFit> fit = DirectionFit::Create(
        knots, params, ends ? EndCondition::kInterpolate : EndCondition::kFree, pins);
    std::string knots_text, params_text;
    for (double t : knots.knots()) absl::StrAppend(&knots_text, t, " ");
    for (double u : params) absl::StrAppend(&params_text, u, " ");
    ASSERT_EQ(fit.ok(), sw) << "trial " << trial << ": order " << order << ", knots " << knots_text
                            << "\nparams " << params_text << "\npinned " << pinned.size() << ": "
                            << fit.status();
    if (!sw) {
      EXPECT_EQ(fit.status().code(), absl::StatusCode::kFailedPrecondition);
    }
    (sw ? holds : fails) += 1;
  }
  // Both outcomes are well represented.
  EXPECT_GT(holds, 300);
  EXPECT_GT(fails, 300);
}

// ----- Layout independence of Apply ------------------------------------------------------------

// A p x q family of lines of `len` points with s coordinates, stored along index direction
// `direction` of a block: extents (len, p, q), (p, len, q) or (p, q, len). Element (c, r) of
// line (x, y) is at Index(direction, c, r, x, y).
struct LineFamily {
  int s, len, p, q;

  int64_t Index(int direction, int c, int r, int x, int y) const {
    switch (direction) {
      case 0:
        return c + s * (r + int64_t{len} * (x + int64_t{p} * y));
      case 1:
        return c + s * (x + int64_t{p} * (r + int64_t{len} * y));
      default:
        return c + s * (x + int64_t{p} * (y + int64_t{q} * r));
    }
  }

  // `values` stored along direction `from`, restored along direction `to`.
  std::vector<double> Relayout(const std::vector<double>& values, int from, int to) const {
    std::vector<double> out(values.size());
    for (int y = 0; y < q; ++y) {
      for (int x = 0; x < p; ++x) {
        for (int r = 0; r < len; ++r) {
          for (int c = 0; c < s; ++c) out[Index(to, c, r, x, y)] = values[Index(from, c, r, x, y)];
        }
      }
    }
    return out;
  }

  // The (a, b) of DirectionFit::Apply for lines along `direction`.
  int64_t A(int direction) const {
    return direction == 0 ? s : direction == 1 ? int64_t{s} * p : int64_t{s} * p * q;
  }
  int64_t B(int direction) const {
    return direction == 0 ? int64_t{p} * q : direction == 1 ? q : 1;
  }
};

// The same lines stored along direction 0, 1 or 2 of a block give bit-identical controls, and
// each line's controls are those of the line fitted alone: Apply's blocking, in-place and
// gathered paths do the same arithmetic per line.
TEST(DirectionFitTest, ApplyGivesIdenticalResultsForEveryLayout) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  const int s = 3, m = 37, n = 12;
  std::vector<double> params(m);
  for (int r = 0; r < m; ++r) params[r] = std::pow(static_cast<double>(r) / (m - 1), 1.5);
  const KnotVector knots = KnotVector::Averaged(4, n, params).value();
  struct Setup {
    EndCondition ends;
    std::vector<Pin> pins;
  };
  const std::vector<Setup> setups = {{EndCondition::kFree, {}},
                                     {EndCondition::kInterpolate, {}},
                                     {EndCondition::kInterpolate, {{5, 17}}},
                                     {EndCondition::kZero, {{7, 20}}}};
  // 24 x 16 lines: along direction 2 a slab is 1152 columns, more than one block of work.
  for (const auto& [p, q] : std::vector<std::pair<int, int>>{{24, 16}, {5, 3}, {1, 1}}) {
    const LineFamily data{s, m, p, q}, controls{s, n, p, q};
    std::vector<double> lines(static_cast<size_t>(s) * m * p * q);
    for (double& x : lines) x = value(rng);
    for (size_t setup = 0; setup < setups.size(); ++setup) {
      SCOPED_TRACE(absl::StrCat(p, " x ", q, " lines, setup ", setup));
      const DirectionFit fit =
          DirectionFit::Create(knots, params, setups[setup].ends, setups[setup].pins).value();
      std::array<std::vector<double>, 3> out;
      for (int d = 0; d < 3; ++d) {
        const std::vector<double> in = data.Relayout(lines, 0, d);
        std::vector<double> fitted(static_cast<size_t>(s) * n * p * q);
        ASSERT_TRUE(fit.Apply(in.data(), data.A(d), data.B(d), fitted.data()).ok());
        out[d] = controls.Relayout(fitted, d, 0);
      }
      EXPECT_EQ(out[1], out[0]);
      EXPECT_EQ(out[2], out[0]);
      // A line fitted alone.
      const int x = p / 2, y = q - 1;
      std::vector<double> one(static_cast<size_t>(s) * m);
      for (int r = 0; r < m; ++r) {
        for (int c = 0; c < s; ++c) one[s * r + c] = lines[data.Index(0, c, r, x, y)];
      }
      const std::vector<double> alone = FitLine(fit, one, s);
      for (int j = 0; j < n; ++j) {
        for (int c = 0; c < s; ++c) {
          EXPECT_EQ(alone[s * j + c], out[0][controls.Index(0, c, j, x, y)]);
        }
      }
    }
  }
}

TEST(DirectionFitTest, ApplyHonoursCancellation) {
  const int m = 30, n = 8;
  std::vector<double> params(m);
  for (int r = 0; r < m; ++r) params[r] = static_cast<double>(r) / (m - 1);
  const DirectionFit fit = DirectionFit::Create(KnotVector::Averaged(4, n, params).value(), params,
                                                EndCondition::kInterpolate)
                               .value();
  std::vector<double> in(static_cast<size_t>(m) * 4096, 1.0), out(static_cast<size_t>(n) * 4096);
  int polls = 0;
  const absl::Status status =
      fit.Apply(in.data(), 4096, 1, out.data(), [&polls] { return ++polls > 1; });
  EXPECT_EQ(status.code(), absl::StatusCode::kCancelled);
  EXPECT_EQ(polls, 2);
}

}  // namespace
}  // namespace splinegrid
