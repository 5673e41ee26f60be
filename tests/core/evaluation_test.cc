#include "core/bspline/evaluation.h"

#include <random>

#include "core/bspline/differential_geometry.h"
#include "gtest/gtest.h"

namespace splinegrid {
namespace {

TensorSpline RandomSpline(std::mt19937& rng, const Extents& controls, int order, int s) {
  std::uniform_real_distribution<double> value(-1.0, 1.0), knot(0.0, 1.0);
  std::array<KnotVector, 3> knots;
  for (int d = 0; d < 3; ++d) {
    if (controls[d] == 1) continue;
    const int k = std::min(order, controls[d]);
    std::vector<double> interior(controls[d] - k);
    for (double& t : interior) t = knot(rng);
    std::sort(interior.begin(), interior.end());
    std::vector<double> t(k, 0.0);
    t.insert(t.end(), interior.begin(), interior.end());
    t.insert(t.end(), k, 1.0);
    knots[d] = KnotVector::Create(k, t).value();
  }
  std::vector<double> control(s * NumPoints(controls));
  for (double& c : control) c = value(rng);
  return TensorSpline::Create(knots, s, control).value();
}

std::vector<double> RandomParams(std::mt19937& rng, int count) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<double> p(count);
  for (double& u : p) u = uniform(rng);
  std::sort(p.begin(), p.end());
  if (count > 1) {
    p.front() = 0.0;
    p.back() = 1.0;
  }
  return p;
}

// Sum factorisation gives the same points and first derivatives as point-wise evaluation.
TEST(GridEvaluatorTest, MatchesPointEvaluation) {
  std::mt19937 rng(21);
  for (const Extents& controls :
       {Extents{9, 1, 1}, Extents{7, 5, 1}, Extents{5, 6, 7}, Extents{2, 6, 4}}) {
    for (int s : {2, 3}) {
      const TensorSpline spline = RandomSpline(rng, controls, 4, s);
      std::array<std::vector<double>, 3> params;
      for (int d = 0; d < 3; ++d) params[d] = RandomParams(rng, controls[d] == 1 ? 1 : 11 + d);
      GridEvaluator evaluator(spline, params, /*first_derivatives=*/true);
      const int64_t lines = evaluator.num_lines(), size = evaluator.line_size();
      std::vector<double> p(lines * size), du(p.size()), dv(p.size()), dw(p.size());
      // Two pieces, the second starting mid-plane, as a streaming caller would.
      const int64_t split = lines / 3;
      evaluator.EvaluateLines(split, lines, p.data() + split * size, du.data() + split * size,
                              dv.data() + split * size, dw.data() + split * size);
      evaluator.EvaluateLines(0, split, p.data(), du.data(), dv.data(), dw.data());
      const Extents n = evaluator.extents();
      for (int k = 0; k < n[2]; ++k) {
        for (int j = 0; j < n[1]; ++j) {
          for (int i = 0; i < n[0]; ++i) {
            const PartialDerivatives ders =
                EvaluateDerivatives(spline, {params[0][i], params[1][j], params[2][k]}, 1);
            const int64_t at = s * (i + int64_t{n[0]} * (j + int64_t{n[1]} * k));
            for (int c = 0; c < s; ++c) {
              EXPECT_NEAR(p[at + c], ders(0, 0, 0)[c], 1e-13);
              EXPECT_NEAR(du[at + c], ders(1, 0, 0)[c], 1e-11);
              EXPECT_NEAR(dv[at + c], ders(0, 1, 0)[c], 1e-11);
              EXPECT_NEAR(dw[at + c], ders(0, 0, 1)[c], 1e-11);
            }
          }
        }
      }
    }
  }
}

// Mixed partial derivatives up to order 3 against central differences.
TEST(EvaluateDerivativesTest, MatchFiniteDifferences) {
  std::mt19937 rng(4);
  const TensorSpline spline = RandomSpline(rng, {7, 6, 5}, 4, 3);
  std::uniform_real_distribution<double> uniform(0.1, 0.9);
  for (int trial = 0; trial < 20; ++trial) {
    const Point3 uvw = {uniform(rng), uniform(rng), uniform(rng)};
    const PartialDerivatives ders = EvaluateDerivatives(spline, uvw, 3);
    const double h = 1e-6;
    for (int d = 0; d < 3; ++d) {
      for (int order = 1; order <= 3; ++order) {
        int lower[3] = {0, 0, 0}, higher[3] = {0, 0, 0};
        lower[d] = order - 1;
        higher[d] = order;
        Point3 plus = uvw, minus = uvw;
        plus[d] += h;
        minus[d] -= h;
        // Skip samples that straddle a knot (the derivative jumps there).
        const KnotVector& kv = spline.knots(d);
        if (kv.FindSpan(plus[d]) != kv.FindSpan(minus[d])) continue;
        const PartialDerivatives dp = EvaluateDerivatives(spline, plus, 3);
        const PartialDerivatives dm = EvaluateDerivatives(spline, minus, 3);
        for (int c = 0; c < 3; ++c) {
          const double fd =
              (dp(lower[0], lower[1], lower[2])[c] - dm(lower[0], lower[1], lower[2])[c]) / (2 * h);
          const double exact = ders(higher[0], higher[1], higher[2])[c];
          EXPECT_NEAR(exact, fd, 1e-4 * (1.0 + std::abs(exact)))
              << "direction " << d << " order " << order;
        }
      }
    }
    // A mixed derivative: d2/dudv.
    Point3 pp = uvw, pm = uvw, mp = uvw, mm = uvw;
    pp[0] += h, pp[1] += h, pm[0] += h, pm[1] -= h, mp[0] -= h, mp[1] += h, mm[0] -= h, mm[1] -= h;
    const Point3 a = EvaluatePoint(spline, pp), b = EvaluatePoint(spline, pm),
                 c = EvaluatePoint(spline, mp), e = EvaluatePoint(spline, mm);
    for (int x = 0; x < 3; ++x) {
      const double fd = (a[x] - b[x] - c[x] + e[x]) / (4 * h * h);
      EXPECT_NEAR(ders(1, 1, 0)[x], fd, 1e-3 * (1.0 + std::abs(fd)));
    }
  }
}

// The parabola y = x^2 as a quadratic Bezier curve: kappa(x) = 2 / (1 + 4 x^2)^(3/2).
TEST(DifferentialGeometryTest, ParabolaCurvature) {
  const KnotVector kv = KnotVector::Uniform(3, 3);
  const TensorSpline parabola =
      TensorSpline::Create({kv, KnotVector(), KnotVector()}, 2, {0, 0, 0.5, 0, 1, 1}).value();
  EXPECT_EQ(CurveDirection(parabola).value(), 0);
  for (double x : {0.0, 0.25, 0.5, 1.0}) {
    EXPECT_NEAR(CurveCurvature(parabola, 0, x), 2.0 / std::pow(1 + 4 * x * x, 1.5), 1e-13);
  }
  // The reversed curve turns right: negative curvature in 2D.
  const TensorSpline reversed =
      TensorSpline::Create({kv, KnotVector(), KnotVector()}, 2, {1, 1, 0.5, 0, 0, 0}).value();
  EXPECT_NEAR(CurveCurvature(reversed, 0, 1.0), -2.0, 1e-13);
}

// Bilinear patch z = x y: normal (-y, -x, 1) / sqrt(1 + x^2 + y^2).
TEST(DifferentialGeometryTest, BilinearPatchNormal) {
  const KnotVector kv = KnotVector::Uniform(2, 2);
  const TensorSpline patch =
      TensorSpline::Create({kv, kv, KnotVector()}, 3, {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 1}).value();
  for (double x : {0.0, 0.3, 1.0}) {
    for (double y : {0.0, 0.6}) {
      const Point3 n = SurfaceNormal(patch, 0, 1, {x, y, 0.0});
      const double len = std::sqrt(1 + x * x + y * y);
      EXPECT_NEAR(n[0], -y / len, 1e-14);
      EXPECT_NEAR(n[1], -x / len, 1e-14);
      EXPECT_NEAR(n[2], 1 / len, 1e-14);
    }
  }
  EXPECT_FALSE(CurveDirection(patch).ok());
}

}  // namespace
}  // namespace splinegrid
