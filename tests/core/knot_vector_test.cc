#include "core/bspline/knot_vector.h"

#include <algorithm>
#include <cmath>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

TEST(KnotVectorTest, UniformIsClampedAndEquallySpaced) {
  const KnotVector kv = KnotVector::Uniform(4, 7);
  EXPECT_THAT(std::vector<double>(kv.knots().begin(), kv.knots().end()),
              ::testing::ElementsAre(0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1));
  EXPECT_EQ(kv.num_controls(), 7);
  EXPECT_EQ(kv.degree(), 3);
  EXPECT_EQ(kv.InteriorBreaks(), (std::vector<double>{0.25, 0.5, 0.75}));
}

TEST(KnotVectorTest, AveragedInterpolationIsEq9_8) {
  // P&T eq. 9.8 with p = 3: t_4 = (u_1 + u_2 + u_3) / 3.
  const std::vector<double> u = {0.0, 0.1, 0.3, 0.6, 0.8, 1.0};
  const KnotVector kv = KnotVector::Averaged(4, 6, u).value();
  ASSERT_EQ(kv.knots().size(), 10u);
  EXPECT_NEAR(kv.knot(4), (0.1 + 0.3 + 0.6) / 3, 1e-15);
  EXPECT_NEAR(kv.knot(5), (0.3 + 0.6 + 0.8) / 3, 1e-15);
}

TEST(KnotVectorTest, AveragedApproximationIsEq9_68) {
  // m = 10 points, n = 6 controls, k = 4: d = 10 / 3, j = 1: i = 3, a = 1/3;
  // j = 2: i = 6, a = 2/3.
  std::vector<double> u(10);
  for (int i = 0; i < 10; ++i) u[i] = (i / 9.0) * (i / 9.0);
  const KnotVector kv = KnotVector::Averaged(4, 6, u).value();
  EXPECT_NEAR(kv.knot(4), (2.0 / 3) * u[2] + (1.0 / 3) * u[3], 1e-15);
  EXPECT_NEAR(kv.knot(5), (1.0 / 3) * u[5] + (2.0 / 3) * u[6], 1e-15);
  // Every knot span holds data (Schoenberg-Whitney).
  for (int span = 3; span < 6; ++span) {
    int inside = 0;
    for (double x : u) inside += (x >= kv.knot(span) && x <= kv.knot(span + 1)) ? 1 : 0;
    EXPECT_GT(inside, 0) << "span " << span;
  }
}

// A break at a data index is a knot of multiplicity k - 1 there; each piece has the Averaged
// knots of its own parameters, rescaled, and with as many controls as points (interpolation)
// the pieces interpolate their own data.
TEST(KnotVectorTest, AveragedWithBreaksIsAveragedPerPiece) {
  std::vector<double> u(13);
  for (int i = 0; i < 13; ++i) u[i] = std::pow(i / 12.0, 1.5);
  const int kBreak = 5;
  const KnotVector kv = KnotVector::AveragedWithBreaks(4, 13, u, std::vector<int>{kBreak}).value();
  EXPECT_EQ(kv.num_controls(), 13);
  EXPECT_EQ(kv.Multiplicity(u[kBreak]), 3);
  // Piece 0: data 0..5 (6 controls), piece 1: data 5..12 (8 controls), one shared.
  std::vector<double> left(u.begin(), u.begin() + kBreak + 1);
  for (double& x : left) x /= u[kBreak];
  const KnotVector expected_left = KnotVector::Averaged(4, 6, left).value();
  for (int j = 4; j < 6; ++j) EXPECT_NEAR(kv.knot(j), expected_left.knot(j) * u[kBreak], 1e-15);
  std::vector<double> right(u.begin() + kBreak, u.end());
  for (double& x : right) x = (x - u[kBreak]) / (1.0 - u[kBreak]);
  const KnotVector expected_right = KnotVector::Averaged(4, 8, right).value();
  for (int j = 4; j < 8; ++j) {
    EXPECT_NEAR(kv.knot(6 + 3 + (j - 4)), u[kBreak] + expected_right.knot(j) * (1.0 - u[kBreak]),
                1e-15);
  }
  // Fewer controls than data: k each, the rest in proportion to the data beyond k (2 and 4):
  // 10 + 1 - 8 = 3 spare -> 1 and 2, so 5 and 6 controls.
  const KnotVector fewer =
      KnotVector::AveragedWithBreaks(4, 10, u, std::vector<int>{kBreak}).value();
  EXPECT_EQ(fewer.num_controls(), 10);
  EXPECT_EQ(fewer.Multiplicity(u[kBreak]), 3);
  EXPECT_EQ(fewer.knot(5 + 1 - 1), u[kBreak]);  // 5 controls: 1 interior knot, then the break
  EXPECT_LT(fewer.knot(4), u[kBreak]);
  // No breaks: Averaged itself.
  const KnotVector none = KnotVector::AveragedWithBreaks(4, 13, u, {}).value();
  const KnotVector averaged = KnotVector::Averaged(4, 13, u).value();
  EXPECT_TRUE(std::equal(none.knots().begin(), none.knots().end(), averaged.knots().begin()));
}

TEST(KnotVectorTest, UsableBreaksLeaveOrderDataAndControlsToEveryPiece) {
  // Order 4, 20 data: a piece needs 4 data (3 intervals).
  const std::vector<int> candidates = {2, 3, 6, 7, 10, 17};
  // 2: only 2 intervals from the start; 3: kept; 6: kept; 7: 1 interval after 6; 10: kept;
  // 17: 2 intervals to the end.
  EXPECT_EQ(KnotVector::UsableBreaks(4, 20, 20, candidates), (std::vector<int>{3, 6, 10}));
  // p pieces need p k - (p - 1) controls: two 7, three 10, four 13.
  EXPECT_EQ(KnotVector::UsableBreaks(4, 10, 20, candidates), (std::vector<int>{3, 6}));
  EXPECT_EQ(KnotVector::UsableBreaks(4, 9, 20, candidates), (std::vector<int>{3}));
  EXPECT_EQ(KnotVector::UsableBreaks(4, 6, 20, candidates), (std::vector<int>{}));
  std::vector<double> u(20);
  for (int i = 0; i < 20; ++i) u[i] = i / 19.0;
  EXPECT_THAT(KnotVector::AveragedWithBreaks(4, 20, u, std::vector<int>{2}).status().message(),
              HasSubstr("do not leave 4 of the 20 data and 4 of the 20 controls"));
  EXPECT_THAT(
      KnotVector::AveragedWithBreaks(4, 9, u, std::vector<int>{3, 6, 10}).status().message(),
      HasSubstr("breaks"));
  EXPECT_THAT(KnotVector::AveragedWithBreaks(1, 1, u, std::vector<int>{5}).status().message(),
              HasSubstr("order = 1"));
}

TEST(KnotVectorTest, CreateRejectsBadVectors) {
  EXPECT_THAT(KnotVector::Create(4, {0, 0, 0, 1, 1, 1}).status().message(),
              HasSubstr("at least 8"));
  EXPECT_THAT(KnotVector::Create(3, {0, 0, 0, 0.7, 0.5, 1, 1, 1}).status().message(),
              HasSubstr("knots[4] = 0.5"));
  EXPECT_THAT(KnotVector::Create(3, {0, 0, 0.1, 0.5, 1, 1, 1}).status().message(),
              HasSubstr("not clamped"));
  EXPECT_THAT(KnotVector::Create(3, {0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1}).status().message(),
              HasSubstr("multiplicity 3"));
  EXPECT_THAT(KnotVector::Create(2, {0, 0, NAN, 1, 1}).status().message(), HasSubstr("not finite"));
  EXPECT_THAT(KnotVector::Create(2, {1, 1, 1, 1}).status().message(), HasSubstr("empty domain"));
  EXPECT_THAT(KnotVector::Create(11, std::vector<double>(22, 0.0)).status().message(),
              HasSubstr("order = 11"));
  EXPECT_EQ(KnotVector::Create(3, {0, 0, 0, 0.5, 0.5, 1, 1, 1}).status().code(),
            absl::StatusCode::kOk);
}

TEST(KnotVectorTest, AveragedRejectsBadParameters) {
  EXPECT_THAT(
      KnotVector::Averaged(4, 5, std::vector<double>{0, 0.5, 0.5, 0.7, 1}).status().message(),
      HasSubstr("not strictly increasing"));
  EXPECT_THAT(KnotVector::Averaged(4, 6, std::vector<double>{0, 0.5, 0.7, 1}).status().message(),
              HasSubstr("control count = 6"));
  EXPECT_THAT(KnotVector::Averaged(4, 3, std::vector<double>{0, 0.5, 0.7, 1}).status().message(),
              HasSubstr("control count = 3"));
}

}  // namespace
}  // namespace splinegrid
