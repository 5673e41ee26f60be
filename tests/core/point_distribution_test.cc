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

// ----- Breaks and geometric end slopes ---------------------------------------------------------

namespace splinegrid {
namespace {

// Rounding of an affine map of the parameters (u -> a + b u), relative to 1.
constexpr double kAffineRounding = 1e-15;

// Breaks of direction i only.
std::array<std::vector<int>, 3> IBreaks(std::vector<int> breaks) {
  return {std::move(breaks), {}, {}};
}

// Two distributions that agree on indices 0..8 and differ beyond: with a break at 8, refining
// 0..8 uses nothing beyond the break (bit for bit), and 8..16 nothing before it.
TEST(PointDistributionBreaksTest, PiecesAreRefinedIndependently) {
  const std::vector<double> u = Clustered(17);
  std::vector<double> v = u;  // same up to index 8, evenly spaced after it
  for (int i = 9; i < 17; ++i) v[i] = u[8] + (1.0 - u[8]) * (i - 8) / 8.0;
  std::vector<double> w = v;  // same as v from index 8 on, different before
  for (int i = 1; i < 8; ++i) w[i] = u[8] * i / 8.0;
  const PointDistribution du = PointDistribution::Create({u, {0.0}, {0.0}}, IBreaks({8})).value();
  const PointDistribution dv = PointDistribution::Create({v, {0.0}, {0.0}}, IBreaks({8})).value();
  const PointDistribution dw = PointDistribution::Create({w, {0.0}, {0.0}}, IBreaks({8})).value();
  EXPECT_EQ(du.breaks(0), std::vector<int>{8});
  for (int level : {1, 2, 3}) {
    EXPECT_EQ(du.Refined(0, 0, 8, level), dv.Refined(0, 0, 8, level)) << level;
    EXPECT_EQ(dv.Refined(0, 8, 16, level), dw.Refined(0, 8, 16, level)) << level;
    EXPECT_NE(du.Refined(0, 8, 16, level), dv.Refined(0, 8, 16, level)) << level;
    // Monotone across the break, and exact at it.
    const std::vector<double> all = du.Refined(0, 0, 16, level);
    EXPECT_EQ(all[8 << level], u[8]);
    for (size_t q = 1; q < all.size(); ++q) EXPECT_GT(all[q], all[q - 1]);
  }
  // Without the break the slope at index 8 sees both sides: the refinements differ.
  const PointDistribution nu = PointDistribution::Create({u, {0.0}, {0.0}}).value();
  const PointDistribution nv = PointDistribution::Create({v, {0.0}, {0.0}}).value();
  EXPECT_NE(nu.Refined(0, 0, 8, 2), nv.Refined(0, 0, 8, 2));
}

// A shared segment sits at different parameters in the blocks that share it (an affine image,
// possibly reversed); between breaks each block refines it to the same image.
TEST(PointDistributionBreaksTest, RefinementCommutesWithAffineMapsAndReversal) {
  const std::vector<double> u = Clustered(13);
  // Piece 3..9 of u (breaks at 3 and 9) as the whole of v, and reversed as the whole of r.
  std::vector<double> v(7), r(7);
  for (int i = 0; i < 7; ++i) {
    v[i] = (u[3 + i] - u[3]) / (u[9] - u[3]);
    r[6 - i] = 1.0 - v[i];
  }
  v.back() = 1.0;
  r.front() = 0.0;
  const PointDistribution du =
      PointDistribution::Create({u, {0.0}, {0.0}}, IBreaks({3, 9})).value();
  const PointDistribution dv = PointDistribution::Create({v, {0.0}, {0.0}}).value();
  const PointDistribution dr = PointDistribution::Create({r, {0.0}, {0.0}}).value();
  for (int level : {1, 2, 3}) {
    const std::vector<double> a = du.Refined(0, 3, 9, level);
    const std::vector<double> b = dv.Refined(0, 0, 6, level);
    const std::vector<double> c = dr.Refined(0, 0, 6, level);
    ASSERT_EQ(a.size(), b.size());
    ASSERT_EQ(a.size(), c.size());
    for (size_t q = 0; q < a.size(); ++q) {
      const double mapped = (a[q] - u[3]) / (u[9] - u[3]);
      EXPECT_NEAR(b[q], mapped, kAffineRounding * 4) << level << " " << q;
      EXPECT_NEAR(c[c.size() - 1 - q], 1.0 - mapped, kAffineRounding * 4) << level << " " << q;
    }
  }
}

TEST(PointDistributionBreaksTest, CreateRejectsBadBreaks) {
  const std::vector<double> u = Clustered(9);
  for (const std::vector<int>& breaks :
       {std::vector<int>{0}, std::vector<int>{8}, std::vector<int>{5, 3}, std::vector<int>{4, 4},
        std::vector<int>{-1}}) {
    const absl::StatusOr<PointDistribution> d =
        PointDistribution::Create({u, {0.0}, {0.0}}, IBreaks(breaks));
    EXPECT_EQ(d.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(d.status().message(), ::testing::HasSubstr("break"));
  }
  EXPECT_THAT(PointDistribution::Create(
                  {u, {0.0}, {0.0}}, {std::vector<int>{}, std::vector<int>{1}, std::vector<int>{}})
                  .status()
                  .message(),
              ::testing::HasSubstr("direction 1"));
  EXPECT_TRUE(PointDistribution::Create({u, {0.0}, {0.0}}, IBreaks({1, 7})).ok());
}

// Geometric stretching h_{i+1} = r h_i, as grid generators make wall layers: refined
// sub-intervals follow the exact geometric continuation u_i + h_i (r^t - 1) / (r - 1) within a
// few per cent, in the first and last interval (the end slopes) as inside.
std::vector<double> Geometric(int n, double r) {
  std::vector<double> u(n);
  const double total = (std::pow(r, n - 1) - 1.0) / (r - 1.0);
  for (int i = 0; i < n; ++i) u[i] = (std::pow(r, i) - 1.0) / (r - 1.0) / total;
  u.back() = 1.0;
  return u;
}

// Largest relative error of the refined sub-intervals of interval i against the geometric ones.
double GeometricError(const PointDistribution& dist, const std::vector<double>& u, double r, int i,
                      int level) {
  const int per = 1 << level;
  const std::vector<double> refined = dist.Refined(0, i, i + 1, level);
  double worst = 0.0;
  for (int q = 0; q < per; ++q) {
    const double t0 = static_cast<double>(q) / per, t1 = static_cast<double>(q + 1) / per;
    const double exact = (u[i + 1] - u[i]) * (std::pow(r, t1) - std::pow(r, t0)) / (r - 1.0);
    worst = std::max(worst, std::abs((refined[q + 1] - refined[q]) / exact - 1.0));
  }
  return worst;
}

TEST(PointDistributionGeometricTest, EndIntervalsFollowTheGeometricContinuation) {
  // r = 2 (and its mirror image 1/2, stretched towards the other end): within 3%.
  for (double r : {2.0, 0.5}) {
    const std::vector<double> u = Geometric(9, r);
    const PointDistribution dist = PointDistribution::Create({u, {0.0}, {0.0}}).value();
    for (int level : {1, 2, 3}) {
      for (int i : {0, 3, 7}) {
        EXPECT_LT(GeometricError(dist, u, r, i, level), 0.03)
            << "r " << r << " level " << level << " interval " << i;
      }
    }
  }
  // Stronger stretching, r = 3: the end intervals are as good as the interior ones (a
  // three-point end formula would collapse the first sub-cell to ~0.3 of its size).
  const std::vector<double> u = Geometric(9, 3.0);
  const PointDistribution dist = PointDistribution::Create({u, {0.0}, {0.0}}).value();
  const double interior = GeometricError(dist, u, 3.0, 4, 2);
  EXPECT_LT(interior, 0.06);
  EXPECT_LT(GeometricError(dist, u, 3.0, 0, 2), interior + 1e-3);
  EXPECT_LT(GeometricError(dist, u, 3.0, 7, 2), interior + 1e-3);
  // The same holds at each side of a break.
  const PointDistribution split =
      PointDistribution::Create({u, {0.0}, {0.0}}, IBreaks({4})).value();
  EXPECT_LT(GeometricError(split, u, 3.0, 3, 2), interior + 1e-3);
  EXPECT_LT(GeometricError(split, u, 3.0, 4, 2), interior + 1e-3);
}

}  // namespace
}  // namespace splinegrid
