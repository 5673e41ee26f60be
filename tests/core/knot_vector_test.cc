#include "core/bspline/knot_vector.h"

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
