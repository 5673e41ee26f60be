#include "core/grid/point_distribution.h"

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace splinegrid {
namespace {

// Strongly clustered toward 0, like a wall-normal direction.
std::vector<double> Clustered(int m) {
  std::vector<double> u(m);
  for (int i = 0; i < m; ++i) u[i] = std::expm1(4.0 * i / (m - 1)) / std::expm1(4.0);
  u.back() = 1.0;
  return u;
}

TEST(PointDistributionTest, LevelZeroReproducesTheOriginalParameters) {
  const PointDistribution dist =
      PointDistribution::Create({Clustered(17), {0.0, 1.0}, {0.0}}).value();
  EXPECT_EQ(dist.Refined(0, 0, 16, 0), dist.params(0));
  EXPECT_EQ(dist.Refined(1, 0, 1, 0), (std::vector<double>{0.0, 1.0}));
  EXPECT_EQ(dist.Refined(2, 0, 0, 3), (std::vector<double>{0.0}));
}

TEST(PointDistributionTest, RefinementKeepsOriginalsAndClustering) {
  const std::vector<double> u = Clustered(17);
  const PointDistribution dist = PointDistribution::Create({u, {0.0}, {0.0}}).value();
  for (int level : {1, 2, 3}) {
    const std::vector<double> r = dist.Refined(0, 0, 16, level);
    const int per = 1 << level;
    ASSERT_EQ(r.size(), 16u * per + 1);
    for (int i = 0; i <= 16; ++i) EXPECT_EQ(r[i * per], u[i]) << "level " << level;
    for (size_t q = 1; q < r.size(); ++q) EXPECT_GT(r[q], r[q - 1]);
    // New samples split each interval into sub-intervals of similar size: clustering follows.
    for (int i = 0; i < 16; ++i) {
      for (int q = 0; q < per; ++q) {
        const double sub = r[i * per + q + 1] - r[i * per + q];
        const double whole = u[i + 1] - u[i];
        EXPECT_GT(sub, 0.2 * whole / per);
        EXPECT_LT(sub, 2.0 * whole / per);
      }
    }
  }
  // A sub-box: indices 4..9 at level 1.
  const std::vector<double> box = dist.Refined(0, 4, 9, 1);
  ASSERT_EQ(box.size(), 11u);
  EXPECT_EQ(box.front(), u[4]);
  EXPECT_EQ(box.back(), u[9]);
}

TEST(PointDistributionTest, ResamplingIsMonotoneAndSpansTheRange) {
  const PointDistribution dist = PointDistribution::Create({Clustered(9), {0.0}, {0.0}}).value();
  for (int n : {2, 5, 9, 100}) {
    const std::vector<double> r = dist.Resampled(0, 0.0, 8.0, n);
    ASSERT_EQ(r.size(), static_cast<size_t>(n));
    EXPECT_EQ(r.front(), 0.0);
    EXPECT_EQ(r.back(), 1.0);
    for (int q = 1; q < n; ++q) EXPECT_GT(r[q], r[q - 1]);
  }
  EXPECT_EQ(dist.Resampled(0, 0.0, 8.0, 9), dist.params(0));
  EXPECT_EQ(dist.Resampled(0, 3.0, 8.0, 1), (std::vector<double>{dist.params(0)[3]}));
}

std::array<std::vector<double>, 3> Params(std::vector<double> u, std::vector<double> v,
                                          std::vector<double> w) {
  return {std::move(u), std::move(v), std::move(w)};
}

TEST(PointDistributionTest, CreateRejectsBadParameters) {
  using ::testing::HasSubstr;
  EXPECT_THAT(
      PointDistribution::Create(Params({0.0, 0.5, 0.5, 1.0}, {0.0}, {0.0})).status().message(),
      HasSubstr("parameter 2 = 0.5 does not exceed"));
  EXPECT_THAT(PointDistribution::Create(Params({0.0}, {0.1, 0.9}, {0.0})).status().message(),
              HasSubstr("direction 1"));
  EXPECT_THAT(PointDistribution::Create(Params({0.0}, {0.0}, {})).status().message(),
              HasSubstr("no parameters"));
  EXPECT_THAT(PointDistribution::Create(Params({2.0}, {0.0}, {0.0})).status().message(),
              HasSubstr("outside [0, 1]"));
}

}  // namespace
}  // namespace splinegrid
