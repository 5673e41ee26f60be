#include "core/bspline/basis.h"

#include <random>

#include "core/bspline/knot_vector.h"
#include "gtest/gtest.h"

namespace splinegrid {
namespace {

constexpr double kTight = 1e-13;

// The NURBS Book, Ex. 2.3/2.4: U = {0,0,0,1,2,3,4,4,5,5,5}, p = 2, u = 5/2.
TEST(BasisTest, NurbsBookExample2_3) {
  const KnotVector kv = KnotVector::Create(3, {0, 0, 0, 1, 2, 3, 4, 4, 5, 5, 5}).value();
  const double u = 2.5;
  const int span = kv.FindSpan(u);
  EXPECT_EQ(span, 4);
  double n[3];
  BasisFunctions(kv, span, u, n);
  EXPECT_NEAR(n[0], 1.0 / 8, kTight);
  EXPECT_NEAR(n[1], 6.0 / 8, kTight);
  EXPECT_NEAR(n[2], 1.0 / 8, kTight);
  double ders[3 * 3];
  BasisDerivatives(kv, span, u, 2, ders);
  EXPECT_NEAR(ders[3 + 0], -0.5, kTight);
  EXPECT_NEAR(ders[3 + 1], 0.0, kTight);
  EXPECT_NEAR(ders[3 + 2], 0.5, kTight);
  // Second derivatives of the quadratics on [2, 3): (3-u)^2/2 -> 1, (u-2)^2/2 -> 1, middle -2.
  EXPECT_NEAR(ders[6 + 0], 1.0, kTight);
  EXPECT_NEAR(ders[6 + 1], -2.0, kTight);
  EXPECT_NEAR(ders[6 + 2], 1.0, kTight);
}

// FindSpan on the same vector, including the ends and a double knot.
TEST(BasisTest, FindSpanNurbsBook) {
  const KnotVector kv = KnotVector::Create(3, {0, 0, 0, 1, 2, 3, 4, 4, 5, 5, 5}).value();
  EXPECT_EQ(kv.FindSpan(0.0), 2);
  EXPECT_EQ(kv.FindSpan(0.5), 2);
  EXPECT_EQ(kv.FindSpan(1.0), 3);
  EXPECT_EQ(kv.FindSpan(3.999), 5);
  EXPECT_EQ(kv.FindSpan(4.0), 7);
  EXPECT_EQ(kv.FindSpan(5.0), 7);
}

KnotVector RandomKnots(std::mt19937& rng, int order, int controls) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<double> interior(controls - order);
  for (double& t : interior) t = uniform(rng);
  std::sort(interior.begin(), interior.end());
  std::vector<double> knots(order, 0.0);
  knots.insert(knots.end(), interior.begin(), interior.end());
  knots.insert(knots.end(), order, 1.0);
  return KnotVector::Create(order, knots).value();
}

// sum_j N_j(u) = 1 and sum_j N_j^(d)(u) = 0 for every order and random knots.
TEST(BasisTest, PartitionOfUnity) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int order = 1; order <= kMaxOrder; ++order) {
    const int controls = order == 1 ? 1 : order + 7;
    const KnotVector kv = order == 1 ? KnotVector() : RandomKnots(rng, order, controls);
    for (int trial = 0; trial < 50; ++trial) {
      const double u = trial == 0 ? 0.0 : trial == 1 ? 1.0 : uniform(rng);
      const int span = kv.FindSpan(u);
      std::vector<double> ders((order + 1) * order);
      BasisDerivatives(kv, span, u, order, ders.data());
      for (int d = 0; d <= order; ++d) {
        // Cancellation error scales with the size of the terms (derivatives grow like
        // 1 / span^d on short spans).
        double sum = 0.0, magnitude = 0.0;
        for (int t = 0; t < order; ++t) {
          sum += ders[d * order + t];
          magnitude += std::abs(ders[d * order + t]);
        }
        EXPECT_NEAR(sum, d == 0 ? 1.0 : 0.0, 1e-13 * std::max(1.0, magnitude))
            << "order " << order << " derivative " << d << " u " << u;
      }
      std::vector<double> values(order);
      BasisFunctions(kv, span, u, values.data());
      for (int t = 0; t < order; ++t) {
        EXPECT_NEAR(values[t], ders[t], kTight);
        EXPECT_GE(values[t], 0.0);
      }
    }
  }
}

// Analytic derivatives against central differences of the next lower derivative.
TEST(BasisTest, DerivativesMatchFiniteDifferences) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uniform(0.05, 0.95);
  for (int order : {2, 3, 4, 5, 6}) {
    const KnotVector kv = RandomKnots(rng, order, order + 5);
    for (int trial = 0; trial < 40; ++trial) {
      const double u = uniform(rng);
      const int span = kv.FindSpan(u);
      // Stay inside the span so that the piecewise polynomial is smooth around u.
      const double h = 1e-5 * std::min(u - kv.knot(span), kv.knot(span + 1) - u);
      if (!(h > 1e-12)) continue;
      const int max_d = std::min(3, order - 1);
      std::vector<double> ders((max_d + 1) * order), plus(ders.size()), minus(ders.size());
      BasisDerivatives(kv, span, u, max_d, ders.data());
      BasisDerivatives(kv, span, u + h, max_d, plus.data());
      BasisDerivatives(kv, span, u - h, max_d, minus.data());
      for (int d = 1; d <= max_d; ++d) {
        for (int t = 0; t < order; ++t) {
          const double fd = (plus[(d - 1) * order + t] - minus[(d - 1) * order + t]) / (2 * h);
          const double scale = 1.0 + std::abs(ders[d * order + t]);
          EXPECT_NEAR(ders[d * order + t], fd, 1e-5 * scale)
              << "order " << order << " d " << d << " t " << t << " u " << u;
        }
      }
    }
  }
}

TEST(BasisTest, SampleBasisClampsAndRecordsFirstIndex) {
  const KnotVector kv = KnotVector::Uniform(4, 7);
  const std::vector<double> params = {-0.5, 0.0, 0.5, 1.0, 1.5};
  const SampledBasis b = SampleBasis(kv, params, 1);
  ASSERT_EQ(b.num_samples(), 5);
  EXPECT_EQ(b.first[0], 0);
  EXPECT_NEAR(b.Row(0)[0], 1.0, kTight);  // clamped to u = 0
  EXPECT_EQ(b.first[4], 3);
  EXPECT_NEAR(b.Row(4)[3], 1.0, kTight);  // clamped to u = 1: only N_{n-1}
  double sum = 0.0;
  for (int t = 0; t < 4; ++t) sum += b.Row(2, 1)[t];
  EXPECT_NEAR(sum, 0.0, 1e-12);
}

}  // namespace
}  // namespace splinegrid
