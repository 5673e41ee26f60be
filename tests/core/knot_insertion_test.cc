#include "core/bspline/knot_insertion.h"

#include <random>

#include "core/bspline/evaluation.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace splinegrid {
namespace {

TensorSpline RandomSpline(std::mt19937& rng, const Extents& controls, int order, int s) {
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::array<KnotVector, 3> knots;
  for (int d = 0; d < 3; ++d) {
    if (controls[d] > 1) knots[d] = KnotVector::Uniform(std::min(order, controls[d]), controls[d]);
  }
  std::vector<double> control(s * NumPoints(controls));
  for (double& c : control) c = value(rng);
  return TensorSpline::Create(knots, s, control).value();
}

double MaxDistance(const TensorSpline& a, const TensorSpline& b, std::mt19937& rng) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  double worst = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    const Point3 uvw = {uniform(rng), uniform(rng), uniform(rng)};
    const Point3 pa = EvaluatePoint(a, uvw), pb = EvaluatePoint(b, uvw);
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(pa[c] - pb[c]));
  }
  return worst;
}

TEST(KnotInsertionTest, LeavesCurveSurfaceAndVolumeUnchanged) {
  std::mt19937 rng(5);
  for (const Extents& controls : {Extents{9, 1, 1}, Extents{7, 6, 1}, Extents{5, 6, 7}}) {
    TensorSpline spline = RandomSpline(rng, controls, 4, 3);
    for (int d = 0; d < 3; ++d) {
      if (controls[d] == 1) continue;
      for (double u : {0.31, 0.5, 0.5, 0.77}) {  // 0.5 twice: raises a multiplicity
        const TensorSpline refined = InsertKnot(spline, d, u).value();
        EXPECT_EQ(refined.control_extents()[d], spline.control_extents()[d] + 1);
        EXPECT_LT(MaxDistance(spline, refined, rng), 1e-14);
        spline = refined;
      }
    }
  }
}

TEST(KnotInsertionTest, MultipleInsertionAndTwoDimensionalPoints) {
  std::mt19937 rng(9);
  const TensorSpline spline = RandomSpline(rng, {8, 5, 1}, 4, 2);
  const TensorSpline refined = InsertKnot(spline, 0, 0.45, 3).value();
  EXPECT_EQ(refined.knots(0).Multiplicity(0.45), 3);
  EXPECT_LT(MaxDistance(spline, refined, rng), 1e-14);
  // With multiplicity k - 1 the iso-curve u = 0.45 is the curve of one control row.
  const int row = refined.knots(0).FindSpan(0.45) - 3;
  std::vector<double> iso_control;
  for (int b = 0; b < 5; ++b) {
    iso_control.insert(iso_control.end(), refined.ControlPoint(row, b, 0),
                       refined.ControlPoint(row, b, 0) + 2);
  }
  const TensorSpline iso =
      TensorSpline::Create({refined.knots(1), KnotVector(), KnotVector()}, 2, iso_control).value();
  for (double v : {0.0, 0.3, 0.8, 1.0}) {
    const Point3 on_surface = EvaluatePoint(refined, {0.45, v, 0.0});
    const Point3 on_row = EvaluatePoint(iso, {v, 0.0, 0.0});
    EXPECT_NEAR(on_surface[0], on_row[0], 1e-14);
    EXPECT_NEAR(on_surface[1], on_row[1], 1e-14);
  }
}

TEST(KnotInsertionTest, RejectsBadRequests) {
  std::mt19937 rng(1);
  const TensorSpline spline = RandomSpline(rng, {6, 1, 1}, 4, 3);
  EXPECT_THAT(InsertKnot(spline, 0, 1.0).status().message(), ::testing::HasSubstr("not inside"));
  EXPECT_THAT(InsertKnot(spline, 0, NAN).status().message(), ::testing::HasSubstr("not inside"));
  EXPECT_THAT(InsertKnot(spline, 3, 0.5).status().message(), ::testing::HasSubstr("direction"));
  EXPECT_THAT(InsertKnot(spline, 0, 0.5, 4).status().message(),
              ::testing::HasSubstr("exceeds the maximum"));
  // A knot already there twice can be inserted once more for a cubic.
  const TensorSpline twice = InsertKnot(spline, 0, 0.5, 2).value();
  EXPECT_TRUE(InsertKnot(twice, 0, 0.5).ok());
  EXPECT_FALSE(InsertKnot(InsertKnot(twice, 0, 0.5).value(), 0, 0.5).ok());
}

}  // namespace
}  // namespace splinegrid
