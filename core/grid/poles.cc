#include "core/grid/poles.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace splinegrid {
namespace {

constexpr char kNames[] = "ijk";

double Distance2(const double* p, const double* q, int s) {
  double d2 = 0.0;
  for (int c = 0; c < s; ++c) d2 += (p[c] - q[c]) * (p[c] - q[c]);
  return d2;
}

}  // namespace

std::string Pole::Describe() const {
  std::string s = absl::StrCat("block ", block);
  for (int e : {normal, line_end}) {
    if (e >= 0) absl::StrAppend(&s, " ", std::string(1, kNames[e]), "=", lo[e]);
  }
  absl::StrAppend(&s, " collapsed along ", std::string(1, kNames[d]));
  return s;
}

double PoleTolerance(const MultiBlockGrid& grid) {
  if (grid.blocks.empty()) return 0.0;
  const int s = grid.blocks.front().spatial_dim();
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (const StructuredBlock& block : grid.blocks) {
    const auto c = block.coords();
    for (size_t x = 0; x < c.size(); ++x) {
      const int a = static_cast<int>(x % block.spatial_dim());
      if (a >= s) continue;
      lo[a] = std::min(lo[a], c[x]);
      hi[a] = std::max(hi[a], c[x]);
    }
  }
  double diag2 = 0.0;
  for (int c = 0; c < s; ++c) diag2 += (hi[c] - lo[c]) * (hi[c] - lo[c]);
  const double tol = kPoleRelativeTolerance * std::sqrt(diag2);
  return std::isfinite(tol) ? tol : 0.0;
}

bool LineCollapsed(const StructuredBlock& block, const Extents& at, int d, int lo, int hi,
                   double tolerance) {
  Extents x = at;
  x[d] = lo;
  const double* first = block.Point(x[0], x[1], x[2]);
  const double tol2 = tolerance * tolerance;
  for (int r = lo + 1; r <= hi; ++r) {
    x[d] = r;
    // Written so that NaN counts as not collapsed.
    if (!(Distance2(first, block.Point(x[0], x[1], x[2]), block.spatial_dim()) <= tol2)) {
      return false;
    }
  }
  return true;
}

bool BoxCollapsedAlong(const StructuredBlock& block, const Extents& lo, const Extents& hi, int d,
                       double tolerance) {
  const int e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2;
  for (int y = lo[e2]; y <= hi[e2]; ++y) {
    for (int x = lo[e1]; x <= hi[e1]; ++x) {
      Extents at = {0, 0, 0};
      at[e1] = x;
      at[e2] = y;
      if (!LineCollapsed(block, at, d, lo[d], hi[d], tolerance)) return false;
    }
  }
  return true;
}

bool BoxCollapsed(const StructuredBlock& block, const Extents& lo, const Extents& hi,
                  double tolerance) {
  for (int d = 0; d < 3; ++d) {
    if (lo[d] < hi[d] && BoxCollapsedAlong(block, lo, hi, d, tolerance)) return true;
  }
  return false;
}

std::vector<Pole> FindPoles(const MultiBlockGrid& grid, double tolerance) {
  std::vector<Pole> poles;
  for (int b = 0; b < static_cast<int>(grid.blocks.size()); ++b) {
    const StructuredBlock& block = grid.blocks[b];
    const Extents& m = block.extents();
    for (int n = 0; n < 3; ++n) {
      if (m[n] == 1) continue;
      for (int side : {0, m[n] - 1}) {
        for (int d = 0; d < 3; ++d) {
          if (d == n || m[d] == 1) continue;
          // The other tangential direction of the face (extent 1 on surfaces).
          const int e = 3 - n - d;
          Pole face{b, d, {0, 0, 0}, {m[0] - 1, m[1] - 1, m[2] - 1}, n};
          face.lo[n] = face.hi[n] = side;
          if (BoxCollapsedAlong(block, face.lo, face.hi, d, tolerance)) {
            poles.push_back(face);
            continue;
          }
          if (m[e] == 1) continue;
          for (int end : {0, m[e] - 1}) {  // the face's boundary lines along d
            Pole line = face;
            line.lo[e] = line.hi[e] = end;
            line.line_end = e;
            if (LineCollapsed(block, line.lo, d, 0, m[d] - 1, tolerance)) poles.push_back(line);
          }
        }
      }
    }
  }
  return poles;
}

std::vector<std::vector<uint8_t>> PointsOnPoles(const MultiBlockGrid& grid,
                                                const std::vector<Pole>& poles) {
  std::vector<std::vector<uint8_t>> on_pole(grid.blocks.size());
  for (const Pole& pole : poles) {
    const StructuredBlock& block = grid.blocks[pole.block];
    std::vector<uint8_t>& mask = on_pole[pole.block];
    mask.resize(static_cast<size_t>(block.num_points()), 0);
    for (int k = pole.lo[2]; k <= pole.hi[2]; ++k) {
      for (int j = pole.lo[1]; j <= pole.hi[1]; ++j) {
        for (int i = pole.lo[0]; i <= pole.hi[0]; ++i) mask[block.Index(i, j, k)] = 1;
      }
    }
  }
  return on_pole;
}

}  // namespace splinegrid
