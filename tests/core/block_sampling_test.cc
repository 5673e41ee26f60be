// Distributions on demand (core/bspline/block_sampling.h, line_arc_length.h), checked with
// geometry computed independently: an arc length known in closed form, straight radial lines
// whose lengths are Euclidean distances, and polylines of many chords.
#include "core/bspline/block_sampling.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/bspline/evaluation.h"
#include "core/bspline/line_arc_length.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

double Distance(const Point3& a, const Point3& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

KnotVector Clamped(int order, int controls) { return KnotVector::Uniform(order, controls); }

// A quarter annulus X(u, v) = r(v) (cos theta(u), sin theta(u)) as a tensor spline: controls
// r_b (cos theta_a, sin theta_a). The j-lines are straight rays from the origin (the control
// net is a product), with radii r_b spread unevenly so the parameter is not arc length.
TensorSpline Annulus() {
  const std::vector<double> radii = {1.0, 1.02, 1.2, 2.0, 6.0, 20.0};
  const int na = 7;
  std::vector<double> control;
  for (double r : radii) {
    for (int a = 0; a < na; ++a) {
      const double theta = 0.5 * std::numbers::pi * a / (na - 1);
      control.push_back(r * std::cos(theta));
      control.push_back(r * std::sin(theta) * (1.0 + 0.3 * a / (na - 1)));
    }
  }
  return TensorSpline::Create({Clamped(4, na), Clamped(4, 6), KnotVector()}, 2, control).value();
}

PointDistribution EvenDistribution(int ni, int nj) {
  std::array<std::vector<double>, 3> params = {
      std::vector<double>(ni), std::vector<double>(nj), {0.0}};
  for (int i = 0; i < ni; ++i) params[0][i] = static_cast<double>(i) / (ni - 1);
  for (int j = 0; j < nj; ++j) params[1][j] = std::pow(static_cast<double>(j) / (nj - 1), 2);
  return PointDistribution::Create(params).value();
}

Resolution Counts(int ni, int nj) {
  Resolution resolution;
  resolution.kind = Resolution::Kind::kCounts;
  resolution.counts = {ni, nj, 1};
  return resolution;
}

// The sampled points of a 2D sampling, [j][i].
std::vector<std::vector<Point3>> Points(const TensorSpline& spline, const BlockSampling& s) {
  std::vector<std::vector<Point3>> out(s.extents()[1]);
  for (int j = 0; j < s.extents()[1]; ++j) {
    for (int i = 0; i < s.extents()[0]; ++i) {
      out[j].push_back(EvaluatePoint(spline, s.ParametersAt(i, j, 0)));
    }
  }
  return out;
}

TEST(LineArcLengthTest, ParabolaLengthIsTheClosedForm) {
  // (t, t^2) is the quadratic Bezier curve with controls (0, 0), (1/2, 0), (1, 1); its length
  // is (2 sqrt(5) + asinh(2)) / 4. The speed sqrt(1 + 4 t^2) is not a polynomial.
  const TensorSpline parabola = TensorSpline::Create({Clamped(3, 3), KnotVector(), KnotVector()}, 2,
                                                     {0.0, 0.0, 0.5, 0.0, 1.0, 1.0})
                                    .value();
  const LineArcLength line(parabola, 0, {0.0, 0.0, 0.0}, 0.0, 1.0);
  const double exact = (2.0 * std::sqrt(5.0) + std::asinh(2.0)) / 4.0;
  EXPECT_NEAR(line.length(), exact, 1e-14);
  // s(t) = (2t sqrt(1 + 4t^2) + asinh(2t)) / 4: the inverse at a few lengths.
  for (double t : {1e-7, 0.01, 0.3, 0.77, 0.999}) {
    const double s = (2.0 * t * std::sqrt(1.0 + 4.0 * t * t) + std::asinh(2.0 * t)) / 4.0;
    EXPECT_NEAR(line.ParameterAt(s), t, 1e-13 * std::max(1.0, t)) << "t = " << t;
    EXPECT_NEAR(line.LengthAt(t), s, 1e-14) << "t = " << t;
  }
  EXPECT_EQ(line.ParameterAt(0.0), 0.0);
  EXPECT_EQ(line.ParameterAt(exact * 2.0), 1.0);
  // A sub-range is measured from its own start.
  const LineArcLength part(parabola, 0, {0.0, 0.0, 0.0}, 0.5, 1.0);
  const double s_half = (1.0 * std::sqrt(2.0) + std::asinh(1.0)) / 4.0;
  EXPECT_NEAR(part.length(), exact - s_half, 1e-14);
}

TEST(BlockSamplingTest, GeometricFirstSpacingOnEveryLineAndConstantRatio) {
  const TensorSpline spline = Annulus();
  const PointDistribution distribution = EvenDistribution(9, 12);
  for (const bool from_end : {false, true}) {
    Resolution resolution = Counts(17, 40);
    resolution.distributions[1] = {Distribution::Kind::kGeometric, 1e-4, from_end};
    const BlockSampling sampling = BlockSampling::Create(spline, distribution, resolution).value();
    EXPECT_EQ(sampling.measured_direction(), 1);
    const auto x = Points(spline, sampling);
    for (int i = 0; i < 17; ++i) {
      // Along a ray, arc length is the distance; the spacings from the wall (or the end).
      std::vector<double> spacing;
      for (int j = 1; j < 40; ++j) spacing.push_back(Distance(x[j][i], x[j - 1][i]));
      if (from_end) std::reverse(spacing.begin(), spacing.end());
      EXPECT_NEAR(spacing[0], 1e-4, 1e-12) << "i = " << i;
      const double ratio = spacing[1] / spacing[0];
      EXPECT_GT(ratio, 1.0);
      for (size_t q = 2; q < spacing.size(); ++q) {
        EXPECT_NEAR(spacing[q] / spacing[q - 1], ratio, 1e-8 * ratio) << "i = " << i;
      }
      // The ends are the block's own.
      EXPECT_EQ(sampling.ParametersAt(i, 0, 0)[1], 0.0);
      EXPECT_EQ(sampling.ParametersAt(i, 39, 0)[1], 1.0);
    }
  }
}

// The annulus extruded along z with uneven heights: the k-lines are straight and vertical.
TensorSpline Extruded() {
  const TensorSpline base = Annulus();
  const std::vector<double> heights = {0.0, 0.05, 0.3, 1.0, 4.0};
  std::vector<double> control;
  for (double z : heights) {
    for (size_t p = 0; p < base.control().size(); p += 2) {
      control.insert(control.end(), {base.control()[p], base.control()[p + 1], z});
    }
  }
  return TensorSpline::Create({base.knots(0), base.knots(1), Clamped(4, 5)}, 3, control).value();
}

TEST(BlockSamplingTest, VolumeMeasuredInKFromTheEndAndEvaluatedPointByPoint) {
  const TensorSpline spline = Extruded();
  std::array<std::vector<double>, 3> params = {std::vector<double>(9), std::vector<double>(12),
                                               std::vector<double>(7)};
  for (int d = 0; d < 3; ++d) {
    for (size_t q = 0; q < params[d].size(); ++q) params[d][q] = q / (params[d].size() - 1.0);
  }
  const PointDistribution distribution = PointDistribution::Create(params).value();
  Resolution resolution;
  resolution.kind = Resolution::Kind::kCounts;
  resolution.counts = {5, 4, 30};
  resolution.distributions[2] = {Distribution::Kind::kGeometric, 1e-3, /*from_end=*/true};
  const BlockSampling sampling = BlockSampling::Create(spline, distribution, resolution).value();
  EXPECT_EQ(sampling.measured_direction(), 2);
  const int64_t n = NumPoints(sampling.extents());
  std::vector<double> x(3 * n), du(3 * n), dv(3 * n), dw(3 * n);
  EvaluateSampledPoints(spline, sampling, 0, n, x.data(), du.data(), dv.data(), dw.data());
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 5; ++i) {
      // Output order i fastest, then j, then k; the last interval of every k-line is 1e-3.
      const auto at = [&](int k) { return 3 * (i + 5 * (j + int64_t{4} * k)); };
      EXPECT_NEAR(x[at(29) + 2] - x[at(28) + 2], 1e-3, 1e-12) << i << ", " << j;
      EXPECT_EQ(x[at(0) + 2], 0.0);
      EXPECT_NEAR(x[at(29) + 2], 4.0, 1e-14);
      for (int k = 0; k < 30; k += 7) {
        const PartialDerivatives d = EvaluateDerivatives(spline, sampling.ParametersAt(i, j, k), 1);
        for (int c = 0; c < 3; ++c) {
          EXPECT_EQ(x[at(k) + c], d(0, 0, 0)[c]);
          EXPECT_EQ(dw[at(k) + c], d(0, 0, 1)[c]);
        }
      }
    }
  }
}

TEST(BlockSamplingTest, OnePointSitsAtTheFirstIndexAndACollapsedLineIsKept) {
  const TensorSpline spline = Annulus();
  const PointDistribution distribution = EvenDistribution(9, 12);
  Resolution one = Counts(9, 1);
  one.distributions[1] = {Distribution::Kind::kUniformArcLength};
  const BlockSampling first = BlockSampling::Create(spline, distribution, one).value();
  for (int i = 0; i < 9; ++i) EXPECT_EQ(first.ParametersAt(i, 0, 0)[1], 0.0);

  // A pole: every control of the column a = 0 at one point (up to rounding, as a fit leaves
  // it). Its j-line is shorter than any first spacing, and is kept, not refused.
  std::vector<double> control(spline.control().begin(), spline.control().end());
  for (int b = 0; b < 6; ++b) {
    control[2 * 7 * b] = 0.5 + (b % 2) * 1e-16;
    control[2 * 7 * b + 1] = 0.25;
  }
  const TensorSpline pole = TensorSpline::Create(spline.all_knots(), 2, control).value();
  Resolution resolution = Counts(9, 20);
  resolution.distributions[1] = {Distribution::Kind::kGeometric, 1e-4};
  const auto sampling = BlockSampling::Create(pole, distribution, resolution);
  ASSERT_TRUE(sampling.ok()) << sampling.status();
  for (int j = 0; j < 20; ++j) {
    const Point3 x = EvaluatePoint(pole, sampling->ParametersAt(0, j, 0));
    EXPECT_NEAR(x[0], 0.5, 1e-15);
    EXPECT_NEAR(x[1], 0.25, 1e-15);
  }
}

TEST(BlockSamplingTest, UniformArcLengthAlongCurvedLines) {
  const TensorSpline spline = Annulus();
  const PointDistribution distribution = EvenDistribution(9, 12);
  Resolution resolution = Counts(33, 5);
  resolution.distributions[0] = {Distribution::Kind::kUniformArcLength};
  const BlockSampling sampling = BlockSampling::Create(spline, distribution, resolution).value();
  EXPECT_EQ(sampling.measured_direction(), 0);
  for (int j = 0; j < 5; ++j) {
    // The length of every interval by a polyline of 2000 chords: equal to 1e-6.
    std::vector<double> lengths;
    for (int i = 1; i < 33; ++i) {
      const double a = sampling.ParametersAt(i - 1, j, 0)[0], b = sampling.ParametersAt(i, j, 0)[0];
      const double v = sampling.ParametersAt(i, j, 0)[1];
      double length = 0.0;
      Point3 previous = EvaluatePoint(spline, {a, v, 0.0});
      for (int q = 1; q <= 2000; ++q) {
        const Point3 next = EvaluatePoint(spline, {a + (b - a) * q / 2000, v, 0.0});
        length += Distance(previous, next);
        previous = next;
      }
      lengths.push_back(length);
    }
    for (double length : lengths) EXPECT_NEAR(length / lengths[0], 1.0, 1e-6) << "j = " << j;
  }
}

TEST(BlockSamplingTest, UniformParameterAndOriginalAreTensorGrids) {
  const TensorSpline spline = Annulus();
  const PointDistribution distribution = EvenDistribution(9, 12);
  Resolution resolution;
  resolution.level = 1;
  resolution.box = IndexBox{{2, 3, 0}, {6, 9, 0}};
  resolution.distributions[1] = {Distribution::Kind::kUniformParameter};
  const BlockSampling sampling = BlockSampling::Create(spline, distribution, resolution).value();
  EXPECT_EQ(sampling.measured_direction(), -1);
  EXPECT_EQ(sampling.extents(), (Extents{9, 13, 1}));
  // j: evenly spaced between the box's parameters (3/11)^2 and (9/11)^2; i follows the
  // original distribution.
  const std::vector<double>& v = sampling.params()[1];
  EXPECT_EQ(v.front(), distribution.params(1)[3]);
  EXPECT_EQ(v.back(), distribution.params(1)[9]);
  for (size_t q = 1; q < v.size(); ++q) EXPECT_NEAR(v[q] - v[q - 1], (v.back() - v[0]) / 12, 1e-15);
  EXPECT_EQ(sampling.params()[0], distribution.Refined(0, 2, 6, 1));
}

TEST(BlockSamplingTest, PointwiseEvaluationMatchesTheGridEvaluator) {
  const TensorSpline spline = Annulus();
  const PointDistribution distribution = EvenDistribution(9, 12);
  Resolution resolution;
  resolution.level = 1;
  const BlockSampling sampling = BlockSampling::Create(spline, distribution, resolution).value();
  GridEvaluator evaluator(spline, sampling.params(), /*first_derivatives=*/true);
  const int64_t n = NumPoints(sampling.extents()) * 2;
  std::vector<double> x(n), du(n), dv(n), dw(n), px(n), pdu(n), pdv(n), pdw(n);
  evaluator.EvaluateLines(0, evaluator.num_lines(), x.data(), du.data(), dv.data(), dw.data());
  EvaluateSampledPoints(spline, sampling, 0, n / 2, px.data(), pdu.data(), pdv.data(), pdw.data());
  for (int64_t q = 0; q < n; ++q) {
    EXPECT_NEAR(px[q], x[q], 1e-13);
    EXPECT_NEAR(pdu[q], du[q], 1e-12);
    EXPECT_NEAR(pdv[q], dv[q], 1e-12);
    EXPECT_EQ(pdw[q], 0.0);
  }
  // A piece from the middle lands at the start of the buffer.
  std::vector<double> piece(10);
  EvaluateSampledPoints(spline, sampling, 100, 5, piece.data());
  for (int q = 0; q < 10; ++q) EXPECT_NEAR(piece[q], x[200 + q], 1e-13);
}

TEST(BlockSamplingTest, RefusalsNameTheField) {
  const TensorSpline spline = Annulus();
  const PointDistribution distribution = EvenDistribution(9, 12);
  const auto error = [&](const Resolution& resolution) {
    return BlockSampling::Create(spline, distribution, resolution).status().ToString();
  };
  Resolution two = Counts(9, 12);
  two.distributions[0] = {Distribution::Kind::kUniformArcLength};
  two.distributions[1] = {Distribution::Kind::kGeometric, 1e-3};
  EXPECT_THAT(error(two), HasSubstr("distributions.i and distributions.j are both measured"));
  Resolution few = Counts(9, 2);
  few.distributions[1] = {Distribution::Kind::kGeometric, 1e-3};
  EXPECT_THAT(error(few), HasSubstr("gives 2 point(s) in that direction"));
  for (double bad : {0.0, -1.0, std::nan(""), HUGE_VAL}) {
    Resolution spacing = Counts(9, 12);
    spacing.distributions[1] = {Distribution::Kind::kGeometric, bad};
    EXPECT_THAT(error(spacing), HasSubstr("is not a positive finite length"));
    EXPECT_THAT(error(spacing), HasSubstr("distributions.j.first_spacing = "));
  }
  // Counts whose product would overflow are refused before anything is sized.
  const PointDistribution volume =
      PointDistribution::Create({std::vector<double>{0.0, 1.0}, std::vector<double>{0.0, 1.0},
                                 std::vector<double>{0.0, 1.0}})
          .value();
  Resolution huge;
  huge.kind = Resolution::Kind::kCounts;
  huge.counts = {1 << 16, 1 << 24, 1 << 24};
  EXPECT_EQ(SampleExtents(volume, huge).status().code(), absl::StatusCode::kOutOfRange);
  EXPECT_THAT(SampleExtents(volume, huge).status().message(), HasSubstr("over 2^40"));
  Resolution long_first = Counts(9, 12);
  long_first.distributions[1] = {Distribution::Kind::kGeometric, 50.0};
  EXPECT_THAT(error(long_first), HasSubstr("is not below the length"));
  EXPECT_THAT(error(long_first), HasSubstr("the grid line at output i = 0"));
  // A spacing that double precision cannot resolve at the grid's coordinates (up to 20 here)
  // would give points with the same coordinates: refused, not sampled. 1e-12 is resolved.
  for (double tiny : {1e-300, 1e-20, 1e-15}) {
    Resolution spacing = Counts(9, 12);
    spacing.distributions[1] = {Distribution::Kind::kGeometric, tiny};
    EXPECT_THAT(error(spacing), HasSubstr("closer than double precision separates")) << tiny;
  }
  Resolution fine = Counts(9, 12);
  fine.distributions[1] = {Distribution::Kind::kGeometric, 1e-12};
  const BlockSampling sampling = BlockSampling::Create(spline, distribution, fine).value();
  const auto x = Points(spline, sampling);
  for (int i = 0; i < 9; ++i) EXPECT_GT(Distance(x[1][i], x[0][i]), 0.5e-12) << "i = " << i;
  Resolution stray = Counts(9, 12);
  stray.distributions[0] = {Distribution::Kind::kUniformArcLength, 0.1};
  EXPECT_THAT(error(stray), HasSubstr("distributions.i.first_spacing = 0.1 is only for"));
  Resolution stray_end = Counts(9, 12);
  stray_end.distributions[2] = {Distribution::Kind::kUniformParameter, 0.0, true};
  EXPECT_THAT(error(stray_end), HasSubstr("distributions.k.from_end is only for"));
  // A cancelled caller stops the placement; a tensor sampling has nothing to cancel.
  Resolution measured = Counts(9, 12);
  measured.distributions[1] = {Distribution::Kind::kUniformArcLength};
  const CancelCheck cancelled = [] { return true; };
  EXPECT_EQ(BlockSampling::Create(spline, distribution, measured, cancelled).status().code(),
            absl::StatusCode::kCancelled);
  EXPECT_TRUE(BlockSampling::Create(spline, distribution, Counts(9, 12), cancelled).ok());
  // SampleParameters alone cannot place a measured direction.
  EXPECT_THAT(SampleParameters(distribution, two).status().ToString(), HasSubstr("are both"));
  Resolution one = Counts(9, 12);
  one.distributions[0] = {Distribution::Kind::kUniformArcLength};
  EXPECT_THAT(SampleParameters(distribution, one).status().ToString(), HasSubstr("BlockSampling"));
}

}  // namespace
}  // namespace splinegrid
