#include "core/generate/concave_fill.h"

#include <algorithm>
#include <cmath>

namespace splinegrid {
namespace {

double Distance(const Point2& a, const Point2& b) { return std::hypot(b[0] - a[0], b[1] - a[1]); }

// Whether point i (0 < i < n - 1) of the loop turns against its orientation by more than
// `max_kappa` per unit length of half its two segments.
bool TooConcave(const std::vector<Point2>& p, int i, double orientation, double max_kappa) {
  const double half = 0.5 * (Distance(p[i - 1], p[i]) + Distance(p[i], p[i + 1]));
  return -SignedTurning(p, i, orientation) > max_kappa * half;
}

// One implicit Laplacian step on p[a..b] with p[a - 1] and p[b + 1] held (Thomas algorithm):
// (1 + 2 tau) x_i - tau (x_{i-1} + x_{i+1}) = p_i.
void ImplicitStep(std::vector<Point2>& p, int a, int b, double tau) {
  const int m = b - a + 1;
  std::vector<double> c(m);  // the eliminated upper diagonal
  std::vector<Point2> d(m);  // the eliminated right-hand side
  const double diagonal = 1.0 + 2.0 * tau;
  for (int r = 0; r < m; ++r) {
    Point2 rhs = p[a + r];
    if (r == 0) {
      for (int x = 0; x < 2; ++x) rhs[x] += tau * p[a - 1][x];
    }
    if (r == m - 1) {
      for (int x = 0; x < 2; ++x) rhs[x] += tau * p[b + 1][x];
    }
    const double pivot = diagonal - (r > 0 ? -tau * c[r - 1] : 0.0);
    c[r] = -tau / pivot;
    for (int x = 0; x < 2; ++x) d[r][x] = (rhs[x] + (r > 0 ? tau * d[r - 1][x] : 0.0)) / pivot;
  }
  p[b] = d[m - 1];
  for (int r = m - 2; r >= 0; --r) {
    for (int x = 0; x < 2; ++x) p[a + r][x] = d[r][x] - c[r] * p[a + r + 1][x];
  }
}

}  // namespace

ConcaveFill FillConcavities(std::vector<Point2>& layer, const std::vector<bool>& fixed,
                            double orientation, double h_next, double max_turning,
                            double max_move) {
  const int n = static_cast<int>(layer.size());
  const double max_kappa = max_turning / h_next;
  const int max_rounds = 4 * n;
  const std::vector<Point2> before = layer;
  ConcaveFill out;
  for (;; ++out.rounds) {
    std::vector<bool> run(n, false);
    bool any = false;
    for (int i = 1; i + 1 < n; ++i) {
      if (fixed[i] || !TooConcave(layer, i, orientation, max_kappa)) continue;
      any = true;
      // Widen both ways, up to a fixed point or the seam.
      for (int w = i; w >= std::max(1, i - kConcaveFillReach) && !fixed[w]; --w) run[w] = true;
      for (int w = i; w <= std::min(n - 2, i + kConcaveFillReach) && !fixed[w]; ++w) run[w] = true;
    }
    if (!any) break;
    if (out.rounds == max_rounds) {
      out.met = false;
      break;
    }
    for (int a = 1; a + 1 < n;) {
      if (!run[a]) {
        ++a;
        continue;
      }
      int b = a;
      while (b + 1 < n - 1 && run[b + 1]) ++b;
      ImplicitStep(layer, a, b, kConcaveFillTau);
      a = b + 1;
    }
  }
  for (int i = 1; i + 1 < n; ++i) {
    const Point2 move = {layer[i][0] - before[i][0], layer[i][1] - before[i][1]};
    const double length = std::hypot(move[0], move[1]);
    if (length > max_move) {
      layer[i] = {before[i][0] + move[0] * max_move / length,
                  before[i][1] + move[1] * max_move / length};
      ++out.held_back;
    }
  }
  return out;
}

}  // namespace splinegrid
