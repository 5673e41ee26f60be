// Self-intersection of planar polylines (polyline.h).
#include "core/grid/polyline.h"

#include <algorithm>
#include <array>
#include <numeric>
#include <optional>
#include <span>
#include <vector>

namespace splinegrid {

std::optional<PolylineCrossing> FindPolylineCrossing(std::span<const double> xy, bool closed) {
  using P = std::array<double, 2>;
  const int segments = static_cast<int>(xy.size() / 2) - 1;
  if (segments < 2) return std::nullopt;  // no two segments to meet
  auto p = [&](int i) { return P{xy[2 * i], xy[2 * i + 1]}; };
  auto cross = [](P o, P a, P b) {
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
  };
  auto on = [](P s, P e, P q) {  // q in the bounding box of segment s-e
    return std::min(s[0], e[0]) <= q[0] && q[0] <= std::max(s[0], e[0]) &&
           std::min(s[1], e[1]) <= q[1] && q[1] <= std::max(s[1], e[1]);
  };
  for (int i = 0; i + 1 < segments; ++i) {  // neighbours folding back
    const P a = p(i), b = p(i + 1), c = p(i + 2);
    const double dot = (b[0] - a[0]) * (c[0] - b[0]) + (b[1] - a[1]) * (c[1] - b[1]);
    if (cross(a, b, c) == 0.0 && dot < 0.0) return PolylineCrossing{i, i + 1};
  }
  std::vector<int> order(segments);
  std::iota(order.begin(), order.end(), 0);
  auto min_x = [&](int s) { return std::min(xy[2 * s], xy[2 * s + 2]); };
  auto max_x = [&](int s) { return std::max(xy[2 * s], xy[2 * s + 2]); };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return min_x(a) < min_x(b); });
  for (int x = 0; x < segments; ++x) {
    for (int y = x + 1; y < segments && min_x(order[y]) <= max_x(order[x]); ++y) {
      const int lo = std::min(order[x], order[y]), hi = std::max(order[x], order[y]);
      if (hi - lo == 1 || (closed && lo == 0 && hi == segments - 1)) continue;
      const P a = p(lo), b = p(lo + 1), c = p(hi), d = p(hi + 1);
      const double d1 = cross(c, d, a), d2 = cross(c, d, b);
      const double d3 = cross(a, b, c), d4 = cross(a, b, d);
      const bool proper =
          ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
      if (proper || (d1 == 0 && on(c, d, a)) || (d2 == 0 && on(c, d, b)) ||
          (d3 == 0 && on(a, b, c)) || (d4 == 0 && on(a, b, d))) {
        return PolylineCrossing{lo, hi};
      }
    }
  }
  return std::nullopt;
}

}  // namespace splinegrid
