// Small multi-block grids built in the tests of connectivity, boundary kinds, the segment model,
// the multi-block fit and the wall curvature: blocks that share (part of) an edge or a face, in
// either orientation, with hanging nodes, a C-grid whose wall line folds back along its wake, a
// Moebius strip (two blocks that touch inconsistently) and a volume split in two.
#ifndef SPLINEGRID_TESTS_CORE_SYNTHETIC_GRIDS_H_
#define SPLINEGRID_TESTS_CORE_SYNTHETIC_GRIDS_H_

#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

#include "core/grid/connectivity.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

// A planar block of ni x nj points at f(i, j).
inline StructuredBlock PlanarBlock(int ni, int nj,
                                   const std::function<std::array<double, 2>(int, int)>& f) {
  StructuredBlock block({ni, nj, 1}, 2);
  for (int j = 0; j < nj; ++j) {
    for (int i = 0; i < ni; ++i) {
      const std::array<double, 2> p = f(i, j);
      block.Point(i, j, 0)[0] = p[0];
      block.Point(i, j, 0)[1] = p[1];
    }
  }
  return block;
}

// A block of ni x nj x nk points in 3D at f(i, j, k) (nk = 1: a surface).
inline StructuredBlock SpaceBlock(int ni, int nj, int nk,
                                  const std::function<std::array<double, 3>(int, int, int)>& f) {
  StructuredBlock block({ni, nj, nk}, 3);
  for (int k = 0; k < nk; ++k) {
    for (int j = 0; j < nj; ++j) {
      for (int i = 0; i < ni; ++i) {
        const std::array<double, 3> p = f(i, j, k);
        for (int c = 0; c < 3; ++c) block.Point(i, j, k)[c] = p[c];
      }
    }
  }
  return block;
}

// A smooth, mildly curved map of the plane, so that fits need knots.
inline std::array<double, 2> Bend(double x, double y) {
  return {x + 0.08 * std::sin(std::numbers::pi * y), y + 0.08 * std::sin(1.3 * x)};
}

// The block of the points Bend(x0 + i hx, y0 + j hy).
inline StructuredBlock BentRectangle(double x0, double hx, int ni, double y0, double hy, int nj) {
  return PlanarBlock(ni, nj, [=](int i, int j) { return Bend(x0 + i * hx, y0 + j * hy); });
}

// Two blocks side by side: A = [0, 1] x [0, 1] with na x na points and B to its right,
// [1, 2] x [y0, y0 + 1] with na x nb_j points (nb_j = 2 na - 1: hanging nodes). With
// `reversed`, B's j runs downwards (its j = 0 at the top).
inline MultiBlockGrid SideBySide(int na, double y0 = 0.0, int nb_j = 0, bool reversed = false) {
  if (nb_j == 0) nb_j = na;
  const double h = 1.0 / (na - 1), hb = 1.0 / (nb_j - 1);
  MultiBlockGrid grid;
  grid.blocks.push_back(BentRectangle(0.0, h, na, 0.0, h, na));
  grid.blocks.push_back(PlanarBlock(na, nb_j, [=](int i, int j) {
    return Bend(1.0 + i * h, reversed ? y0 + 1.0 - j * hb : y0 + j * hb);
  }));
  return grid;
}

// Geometric spacing: t_0 = 0, t_j - t_{j-1} = first r^(j-1), j = 1 .. n - 1.
inline std::vector<double> GeometricSpacing(int n, double first, double r) {
  std::vector<double> t(n, 0.0);
  for (int j = 1; j < n; ++j) t[j] = t[j - 1] + first * std::pow(r, j - 1);
  return t;
}

// A C-grid around an ellipse (chord 1, thickness 0.2): i runs along the wall line j = 0 from
// the end of the lower wake (x = 1 + wake_cells h) to the trailing edge (i = wake_cells), around
// the ellipse (body_cells intervals, lower side first) and back out along the upper wake, which
// coincides with the lower one: point i of j = 0 is point ni - 1 - i for i <= wake_cells. The
// grid lines j leave the wall along its normal (downwards on the lower wake, upwards on the
// upper) with spacing 1e-3 doubling per layer, so j = 0 is a wall by its clustering (the first
// layer is below 0.05 of the median spacing 2^5 1e-3).
struct CGrid {
  MultiBlockGrid grid;
  int wake_cells = 0;  // the wake runs over i in [0, wake_cells] and [ni - 1 - wake_cells, ni - 1]
  int ni = 0;
  int leading_edge = 0;  // index of the leading edge on j = 0
};
inline CGrid MakeCGrid(int wake_cells = 6, int body_cells = 32, int nj = 11) {
  CGrid c;
  c.wake_cells = wake_cells;
  c.ni = 2 * wake_cells + body_cells + 1;
  c.leading_edge = wake_cells + body_cells / 2;
  const double h = 0.15;
  const std::vector<double> layers = GeometricSpacing(nj, 1e-3, 2.0);
  c.grid.blocks.push_back(PlanarBlock(c.ni, nj, [=](int i, int j) -> std::array<double, 2> {
    const double s = layers[j];
    const int upper_start = c.ni - 1 - wake_cells;
    if (i <= wake_cells) return {1.0 + (wake_cells - i) * h, -s};
    if (i >= upper_start) return {1.0 + (i - upper_start) * h, s};
    // Ellipse (0.5 + 0.5 cos t, -0.1 sin t), t from 0 to 2 pi, outward normal.
    const double t = 2.0 * std::numbers::pi * (i - wake_cells) / body_cells;
    const double nx = 0.1 * std::cos(t), ny = -0.5 * std::sin(t);
    const double len = std::hypot(nx, ny);
    return {0.5 + 0.5 * std::cos(t) + s * nx / len, -0.1 * std::sin(t) + s * ny / len};
  }));
  return c;
}

// A Moebius strip in two surface blocks (theta in [0, pi] and [pi, 2 pi], ni x nj each): they
// meet forwards at theta = pi and reversed (the strip's half twist) at theta = 0 = 2 pi, so the
// j directions of the two blocks are linked both forwards and reversed.
inline MultiBlockGrid MoebiusStrip(int ni = 9, int nj = 5) {
  MultiBlockGrid grid;
  for (int half = 0; half < 2; ++half) {
    grid.blocks.push_back(SpaceBlock(ni, nj, 1, [=](int i, int j, int) -> std::array<double, 3> {
      const double theta = std::numbers::pi * (half + static_cast<double>(i) / (ni - 1));
      const double s = -0.3 + 0.6 * j / (nj - 1);
      const double r = 1.0 + s * std::cos(0.5 * theta);
      return {r * std::cos(theta), r * std::sin(theta), s * std::sin(0.5 * theta)};
    }));
  }
  return grid;
}

// The box [0, 2] x [0, 1] x [0, 1], bent, in two volume blocks split at x = 1, n^3 points each.
// The second block's index directions are permuted (its i runs along y, j along x) and its k is
// reversed, so the shared face is A i=max ~ B j=0 with j->i, k->k reversed.
inline std::array<double, 3> BendVolume(double x, double y, double z) {
  return {x + 0.05 * std::sin(2.0 * z), y + 0.05 * std::sin(1.5 * x), z + 0.05 * std::sin(y)};
}
inline MultiBlockGrid SplitBox(int n) {
  const double h = 1.0 / (n - 1);
  MultiBlockGrid grid;
  grid.blocks.push_back(
      SpaceBlock(n, n, n, [=](int i, int j, int k) { return BendVolume(i * h, j * h, k * h); }));
  grid.blocks.push_back(SpaceBlock(
      n, n, n, [=](int i, int j, int k) { return BendVolume(1.0 + j * h, i * h, 1.0 - k * h); }));
  return grid;
}

// Largest distance between the points of every index pair of `match` (MapToB), and the number
// of pairs.
inline double MatchGap(const MultiBlockGrid& grid, const BoundaryMatch& match, int* pairs) {
  const StructuredBlock& a = grid.blocks[match.a.face.block];
  const StructuredBlock& b = grid.blocks[match.b.face.block];
  double gap = 0.0;
  *pairs = 0;
  for (int k = match.a.begin[2]; k <= match.a.end[2]; ++k) {
    for (int j = match.a.begin[1]; j <= match.a.end[1]; ++j) {
      for (int i = match.a.begin[0]; i <= match.a.end[0]; ++i) {
        const Extents y = match.MapToB({i, j, k});
        for (int d = 0; d < 3; ++d) {
          if (y[d] < 0 || y[d] >= b.extent(d)) return INFINITY;
        }
        double d2 = 0.0;
        for (int c = 0; c < a.spatial_dim(); ++c) {
          const double diff = a.Point(i, j, k)[c] - b.Point(y[0], y[1], y[2])[c];
          d2 += diff * diff;
        }
        gap = std::max(gap, std::sqrt(d2));
        ++*pairs;
      }
    }
  }
  return gap;
}

}  // namespace splinegrid

#endif  // SPLINEGRID_TESTS_CORE_SYNTHETIC_GRIDS_H_
