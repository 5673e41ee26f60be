#include "core/generate/loop_geometry.h"

#include <algorithm>
#include <cmath>

namespace splinegrid {

std::vector<double> Flat(const std::vector<Point2>& p) {
  std::vector<double> xy;
  xy.reserve(2 * p.size());
  for (const Point2& q : p) {
    xy.push_back(q[0]);
    xy.push_back(q[1]);
  }
  return xy;
}

double SignedArea2(const std::vector<Point2>& p) {
  double a = 0.0;
  for (size_t i = 0; i + 1 < p.size(); ++i) a += Cross(p[i], p[i + 1]);
  return a;
}

std::vector<Point2> LoopNormals(const std::vector<Point2>& p, double orientation) {
  const int n = static_cast<int>(p.size());
  std::vector<Point2> normals(n);
  for (int i = 0; i < n; ++i) {
    const int prev = i == 0 ? n - 2 : i - 1;
    const int next = i == n - 1 ? 1 : i + 1;
    const double tx = p[next][0] - p[prev][0], ty = p[next][1] - p[prev][1];
    const double len = std::hypot(tx, ty);
    normals[i] = {orientation * ty / len, -orientation * tx / len};
  }
  return normals;
}

Point2 CornerBisector(const std::vector<Point2>& p, int i, double orientation) {
  const int n = static_cast<int>(p.size());
  const int prev = i == 0 ? n - 2 : i - 1;
  const int next = i == n - 1 ? 1 : i + 1;
  auto unit = [](const Point2& from, const Point2& to) {
    const double dx = to[0] - from[0], dy = to[1] - from[1], len = std::hypot(dx, dy);
    return len > 0.0 ? Point2{dx / len, dy / len} : Point2{0.0, 0.0};
  };
  const Point2 a = unit(p[prev], p[i]), b = unit(p[i], p[next]);
  // The sum of the sides' unit normals; at a cusp (sides reversed) it vanishes and the
  // bisector continues the arriving side.
  Point2 m = {orientation * (a[1] + b[1]), -orientation * (a[0] + b[0])};
  if (std::hypot(m[0], m[1]) < 1e-9) m = {a[0] - b[0], a[1] - b[1]};
  const double len = std::hypot(m[0], m[1]);
  return len > 0.0 ? Point2{m[0] / len, m[1] / len} : Point2{0.0, 0.0};
}

double SignedTurning(const std::vector<Point2>& p, int i, double orientation) {
  const int n = static_cast<int>(p.size());
  const int prev = i == 0 ? n - 2 : i - 1;
  const int next = i == n - 1 ? 1 : i + 1;
  const Point2 a = {p[i][0] - p[prev][0], p[i][1] - p[prev][1]};
  const Point2 b = {p[next][0] - p[i][0], p[next][1] - p[i][1]};
  return orientation * std::atan2(Cross(a, b), a[0] * b[0] + a[1] * b[1]);
}

double SignedCellArea(const StructuredBlock& grid, int i, int j) {
  const double* a = grid.Point(i, j, 0);
  const double* b = grid.Point(i + 1, j, 0);
  const double* c = grid.Point(i + 1, j + 1, 0);
  const double* d = grid.Point(i, j + 1, 0);
  return 0.5 * Cross({c[0] - a[0], c[1] - a[1]}, {d[0] - b[0], d[1] - b[1]});
}

double TurningDegrees(const std::vector<Point2>& p, int i) {
  return std::abs(SignedTurning(p, i, 1.0)) * 180.0 / 3.14159265358979323846;
}

StructuredBlock ReversedI(const StructuredBlock& block) {
  StructuredBlock out(block.extents(), block.spatial_dim());
  const int ni = block.extent(0), s = block.spatial_dim();
  for (int k = 0; k < block.extent(2); ++k) {
    for (int j = 0; j < block.extent(1); ++j) {
      for (int i = 0; i < ni; ++i) {
        std::copy(block.Point(ni - 1 - i, j, k), block.Point(ni - 1 - i, j, k) + s,
                  out.Point(i, j, k));
      }
    }
  }
  return out;
}

}  // namespace splinegrid
