#include "core/deform/boundary_controls.h"

#include <algorithm>

#include "absl/strings/str_cat.h"

namespace splinegrid {
namespace {

int64_t PointIndex(const Extents& m, const Extents& x) {
  return x[0] + int64_t{m[0]} * (x[1] + int64_t{m[1]} * x[2]);
}

// Flags of the cells of a boundary manifold (a face, or a whole surface block) with tangential
// directions `t` (1 or 2 of them) and the other indices at `base`, as 2D prefix sums, so that
// "does any flagged cell overlap this box of cells" is O(1).
class CellCounts {
 public:
  CellCounts(const Extents& m, const std::vector<int>& t, const Extents& base,
             const std::vector<uint8_t>& flagged)
      : n1_(m[t[0]] - 1), n2_(t.size() > 1 ? m[t[1]] - 1 : 1) {
    sum_.assign((n1_ + 1) * (n2_ + 1), 0);
    for (int j = 0; j < n2_; ++j) {
      for (int i = 0; i < n1_; ++i) {
        bool all = true;
        for (int dj = 0; dj <= (t.size() > 1 ? 1 : 0); ++dj) {
          for (int di = 0; di <= 1; ++di) {
            Extents x = base;
            x[t[0]] = i + di;
            if (t.size() > 1) x[t[1]] = j + dj;
            all = all && flagged[PointIndex(m, x)] != 0;
          }
        }
        At(i + 1, j + 1) = At(i, j + 1) + At(i + 1, j) - At(i, j) + (all ? 1 : 0);
      }
    }
  }
  // Whether a flagged cell lies in [i0, i1] x [j0, j1] (inclusive; empty ranges give false).
  bool Any(int i0, int i1, int j0, int j1) const {
    i0 = std::max(i0, 0);
    j0 = std::max(j0, 0);
    i1 = std::min(i1, n1_ - 1);
    j1 = std::min(j1, n2_ - 1);
    if (i0 > i1 || j0 > j1) return false;
    return At(i1 + 1, j1 + 1) - At(i0, j1 + 1) - At(i1 + 1, j0) + At(i0, j0) > 0;
  }

 private:
  int64_t& At(int i, int j) { return sum_[i + int64_t{n1_ + 1} * j]; }
  int64_t At(int i, int j) const { return sum_[i + int64_t{n1_ + 1} * j]; }
  int n1_, n2_;
  std::vector<int64_t> sum_;
};

// The cells [lo, hi] of direction d whose open parameter interval (u_i, u_{i+1}) overlaps the
// open support (t_a, t_{a+k}) of control a.
std::pair<int, int> OverlappedCells(const KnotVector& knots, const std::vector<double>& u, int a) {
  const double s0 = knots.knot(a), s1 = knots.knot(a + knots.order());
  const int lo = static_cast<int>(std::upper_bound(u.begin(), u.end(), s0) - u.begin()) - 1;
  const int hi = static_cast<int>(std::lower_bound(u.begin(), u.end(), s1) - u.begin()) - 1;
  return {std::max(lo, 0), hi};
}

}  // namespace

absl::StatusOr<std::vector<std::vector<uint8_t>>> SelectedPoints(
    const std::vector<Extents>& extents, const BoundaryKinds& kinds,
    const BoundarySelection& selection) {
  const int nb = static_cast<int>(extents.size());
  std::vector<std::vector<uint8_t>> selected(nb);
  for (int b = 0; b < nb; ++b) {
    selected[b].assign(NumPoints(extents[b]), 0);
    if (!selection.ranges.empty()) continue;
    for (size_t p = 0; p < selected[b].size(); ++p) {
      selected[b][p] = (kinds.point_kinds[b][p] & selection.kinds) != 0;
    }
  }
  for (size_t r = 0; r < selection.ranges.size(); ++r) {
    const FaceRange& range = selection.ranges[r];
    const std::string name = absl::StrCat("boundary range ", r);
    const int b = range.face.block;
    if (b < 0 || b >= nb) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": block ", b, " is outside [0, ", nb - 1, "]"));
    }
    const Extents& m = extents[b];
    // A direction of one point as the normal names the whole block: a surface block's wall.
    const int d = range.face.normal;
    if (d < 0 || d > 2) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": normal direction ", d, " is outside [0, 2]"));
    }
    const int side = range.face.upper ? m[d] - 1 : 0;
    for (int e = 0; e < 3; ++e) {
      const int lo = e == d ? side : range.begin[e], hi = e == d ? side : range.end[e];
      if (lo < 0 || hi >= m[e] || lo > hi) {
        return absl::InvalidArgumentError(absl::StrCat(name, ": direction ", e, " range [",
                                                       range.begin[e], ", ", range.end[e],
                                                       "] is not inside [0, ", m[e] - 1, "]"));
      }
    }
    Extents x;
    for (x[2] = d == 2 ? side : range.begin[2]; x[2] <= (d == 2 ? side : range.end[2]); ++x[2]) {
      for (x[1] = d == 1 ? side : range.begin[1]; x[1] <= (d == 1 ? side : range.end[1]); ++x[1]) {
        for (x[0] = d == 0 ? side : range.begin[0]; x[0] <= (d == 0 ? side : range.end[0]);
             ++x[0]) {
          selected[b][PointIndex(m, x)] = 1;
        }
      }
    }
  }
  return selected;
}

std::vector<std::vector<ControlRole>> ClassifyControls(
    const std::vector<FittedBlock>& blocks, const BoundaryKinds& kinds,
    const std::vector<std::vector<uint8_t>>& selected) {
  const auto held =
      static_cast<uint8_t>(BoundaryKind::kOuter) | static_cast<uint8_t>(BoundaryKind::kWall);
  std::vector<std::vector<ControlRole>> roles(blocks.size());
  for (size_t b = 0; b < blocks.size(); ++b) {
    const FittedBlock& block = blocks[b];
    const Extents m = {block.distribution.num_points(0), block.distribution.num_points(1),
                       block.distribution.num_points(2)};
    const Extents n = block.spline.control_extents();
    roles[b].assign(NumPoints(n), ControlRole::kFree);
    std::vector<uint8_t> fixed(selected[b].size());
    for (size_t p = 0; p < fixed.size(); ++p) {
      fixed[p] = !selected[b][p] && (kinds.point_kinds[b][p] & held) != 0;
    }
    std::vector<int> active;
    for (int d = 0; d < 3; ++d) {
      if (m[d] > 1) active.push_back(d);
    }
    // The boundary manifolds: (normal direction or -1 for the whole block, side).
    std::vector<std::pair<int, int>> manifolds;
    if (static_cast<int>(active.size()) < block.spline.spatial_dim()) {
      manifolds.push_back({-1, 0});
    } else {
      for (int d : active) {
        manifolds.push_back({d, 0});
        manifolds.push_back({d, m[d] - 1});
      }
    }
    for (const auto& [normal, side] : manifolds) {
      std::vector<int> t;
      for (int d : active) {
        if (d != normal) t.push_back(d);
      }
      if (t.empty()) continue;
      Extents base = {0, 0, 0};
      if (normal >= 0) base[normal] = side;
      const CellCounts moved(m, t, base, selected[b]);
      const CellCounts held_cells(m, t, base, fixed);
      const int control_side = normal >= 0 && side > 0 ? n[normal] - 1 : 0;
      const int n1 = n[t[0]], n2 = t.size() > 1 ? n[t[1]] : 1;
      for (int a2 = 0; a2 < n2; ++a2) {
        for (int a1 = 0; a1 < n1; ++a1) {
          const auto [i0, i1] =
              OverlappedCells(block.spline.knots(t[0]), block.distribution.params(t[0]), a1);
          int j0 = 0, j1 = 0;
          if (t.size() > 1) {
            std::tie(j0, j1) =
                OverlappedCells(block.spline.knots(t[1]), block.distribution.params(t[1]), a2);
          }
          Extents c = {0, 0, 0};
          if (normal >= 0) c[normal] = control_side;
          c[t[0]] = a1;
          if (t.size() > 1) c[t[1]] = a2;
          ControlRole& role = roles[b][PointIndex(n, c)];
          if (moved.Any(i0, i1, j0, j1)) {
            role = ControlRole::kMoved;
          } else if (held_cells.Any(i0, i1, j0, j1) && role != ControlRole::kMoved) {
            role = ControlRole::kFixed;
          }
        }
      }
    }
  }
  return roles;
}

}  // namespace splinegrid
