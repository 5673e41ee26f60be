#include "core/grid/reference_length.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "core/util/union_find.h"

namespace splinegrid {
namespace {

using Point3 = std::array<double, 3>;

// Relative distance (to the bounding-box diagonal) within which points coincide.
constexpr double kCoincidence = 1e-9;

double Distance2(const Point3& p, const Point3& q) {
  double d2 = 0.0;
  for (int c = 0; c < 3; ++c) d2 += (p[c] - q[c]) * (p[c] - q[c]);
  return d2;
}

// A wall's diameter and the two points that span it.
struct Diameter {
  double length = 0.0;
  Point3 from{}, to{};
  bool exact = true;
};

// The farthest point of `points` from p.
int Farthest(const std::vector<Point3>& points, const Point3& p) {
  int best = 0;
  double best_d2 = -1.0;
  for (size_t q = 0; q < points.size(); ++q) {
    const double d2 = Distance2(points[q], p);
    if (d2 > best_d2) best_d2 = d2, best = static_cast<int>(q);
  }
  return best;
}

// Exact (O(m^2)) up to kExactDiameterPoints, farthest-point sweeps beyond (file comment).
Diameter DiameterOf(const std::vector<Point3>& points) {
  Diameter d;
  const size_t m = points.size();
  double best = 0.0;
  int a = 0, b = 0;
  if (static_cast<int64_t>(m) <= kExactDiameterPoints) {
    for (size_t p = 0; p < m; ++p) {
      for (size_t q = p + 1; q < m; ++q) {
        const double d2 = Distance2(points[p], points[q]);
        if (d2 > best) best = d2, a = static_cast<int>(p), b = static_cast<int>(q);
      }
    }
  } else {
    d.exact = false;
    for (int c = 0; c < 3; ++c) {
      for (int sign : {-1, 1}) {
        int seed = 0;
        for (size_t q = 1; q < m; ++q) {
          if (sign * points[q][c] > sign * points[seed][c]) seed = static_cast<int>(q);
        }
        // Sweep until the farthest pair stops growing (a few steps).
        int p = seed;
        for (int step = 0; step < 8; ++step) {
          const int q = Farthest(points, points[p]);
          const double d2 = Distance2(points[p], points[q]);
          if (d2 <= best) break;
          best = d2, a = p, b = q;
          p = q;
        }
      }
    }
  }
  d.length = std::sqrt(best);
  if (m > 0) d.from = points[a], d.to = points[b];
  return d;
}

std::string FormatPoint(const Point3& p, int dim) {
  return dim == 2 ? absl::StrFormat("(%.6g, %.6g)", p[0], p[1])
                  : absl::StrFormat("(%.6g, %.6g, %.6g)", p[0], p[1], p[2]);
}

// Every wall point of a grid, with its block, and the bounding box of the grid.
struct WallPoints {
  std::vector<Point3> points;
  std::vector<int> point_block;
  Point3 lo, hi;
  int dim = 2;
  // Per block, the wall id of each point (-1: not a wall point).
  std::vector<std::vector<int>> ids;
};

// The wall points of `grid` by `kinds` (blocks or points without kinds have none), and its
// bounding box.
WallPoints CollectWallPoints(const MultiBlockGrid& grid, const BoundaryKinds& kinds) {
  WallPoints w;
  w.lo.fill(std::numeric_limits<double>::infinity());
  w.hi.fill(-std::numeric_limits<double>::infinity());
  w.ids.resize(grid.blocks.size());
  for (size_t b = 0; b < grid.blocks.size(); ++b) {
    const StructuredBlock& block = grid.blocks[b];
    w.dim = std::max(w.dim, block.spatial_dim());
    const std::vector<uint8_t>* mask =
        b < kinds.point_kinds.size() ? &kinds.point_kinds[b] : nullptr;
    w.ids[b].assign(block.num_points(), -1);
    for (int64_t p = 0; p < block.num_points(); ++p) {
      Point3 x{0.0, 0.0, 0.0};
      for (int c = 0; c < block.spatial_dim(); ++c)
        x[c] = block.coords()[block.spatial_dim() * p + c];
      for (int c = 0; c < 3; ++c) {
        w.lo[c] = std::min(w.lo[c], x[c]), w.hi[c] = std::max(w.hi[c], x[c]);
      }
      if (mask == nullptr || static_cast<size_t>(p) >= mask->size()) continue;
      if (((*mask)[p] & static_cast<uint8_t>(BoundaryKind::kWall)) == 0) continue;
      w.ids[b][p] = static_cast<int>(w.points.size());
      w.points.push_back(x);
      w.point_block.push_back(static_cast<int>(b));
    }
  }
  return w;
}

// Joins the wall points that are neighbours along the index directions of a block.
void JoinIndexNeighbours(const MultiBlockGrid& grid, const std::vector<std::vector<int>>& ids,
                         UnionFind& walls) {
  for (size_t b = 0; b < grid.blocks.size(); ++b) {
    const StructuredBlock& block = grid.blocks[b];
    const Extents n = block.extents();
    for (int k = 0; k < n[2]; ++k) {
      for (int j = 0; j < n[1]; ++j) {
        for (int i = 0; i < n[0]; ++i) {
          const int id = ids[b][block.Index(i, j, k)];
          if (id < 0) continue;
          if (i + 1 < n[0] && ids[b][block.Index(i + 1, j, k)] >= 0) {
            walls.Join(id, ids[b][block.Index(i + 1, j, k)]);
          }
          if (j + 1 < n[1] && ids[b][block.Index(i, j + 1, k)] >= 0) {
            walls.Join(id, ids[b][block.Index(i, j + 1, k)]);
          }
          if (k + 1 < n[2] && ids[b][block.Index(i, j, k + 1)] >= 0) {
            walls.Join(id, ids[b][block.Index(i, j, k + 1)]);
          }
        }
      }
    }
  }
}

// Joins the points within `eps` of each other (across blocks, or across a cut of one block): a
// hash grid of cells of the coincidence distance from `lo`, each point compared with the points
// of its 27 neighbour cells.
void JoinCoinciding(const std::vector<Point3>& points, const Point3& lo, double eps,
                    UnionFind& walls) {
  std::map<std::array<int64_t, 3>, std::vector<int>> cells;
  auto cell_of = [&](const Point3& x) {
    std::array<int64_t, 3> key;
    for (int c = 0; c < 3; ++c) key[c] = static_cast<int64_t>(std::floor((x[c] - lo[c]) / eps));
    return key;
  };
  for (size_t p = 0; p < points.size(); ++p)
    cells[cell_of(points[p])].push_back(static_cast<int>(p));
  for (size_t p = 0; p < points.size(); ++p) {
    const std::array<int64_t, 3> key = cell_of(points[p]);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const auto it = cells.find({key[0] + dx, key[1] + dy, key[2] + dz});
          if (it == cells.end()) continue;
          for (int q : it->second) {
            if (Distance2(points[p], points[q]) <= eps * eps)
              walls.Join(static_cast<int64_t>(p), q);
          }
        }
      }
    }
  }
}

// The walls (the sets of `joined`), their diameters, the largest; the bounding-box `diagonal`
// when every wall is a single point.
ReferenceLength LargestWall(const WallPoints& w, UnionFind& joined, double diagonal) {
  std::map<int, std::vector<Point3>> members;
  std::map<int, std::set<int>> blocks;  // of each wall
  for (size_t p = 0; p < w.points.size(); ++p) {
    const int root = static_cast<int>(joined.Find(static_cast<int64_t>(p)));
    members[root].push_back(w.points[p]);
    blocks[root].insert(w.point_block[p]);
  }
  // In the order of the walls' first points, so that ties resolve the same way every time.
  std::vector<int> roots;
  for (const auto& [root, unused] : members) roots.push_back(root);
  std::sort(roots.begin(), roots.end());
  Diameter best;
  int best_root = roots.front();
  for (int root : roots) {
    const Diameter d = DiameterOf(members[root]);
    if (d.length > best.length) best = d, best_root = root;
  }
  ReferenceLength r;
  r.length = best.length;
  r.source = ReferenceLengthSource::kWall;
  const size_t count = members[best_root].size();
  const std::set<int>& from = blocks[best_root];
  r.description = absl::StrFormat(
      "the largest extent of %d wall%s: %d points from %s, from %s to %s%s", roots.size(),
      roots.size() == 1 ? "" : "s", count,
      from.size() == 1   ? absl::StrCat("block ", *from.begin())
      : from.size() <= 8 ? absl::StrCat(from.size(), " blocks (", absl::StrJoin(from, ", "), ")")
                         : absl::StrCat(from.size(), " blocks"),
      FormatPoint(best.from, w.dim), FormatPoint(best.to, w.dim),
      best.exact ? "" : " (farthest-point estimate: a lower bound of the diameter)");
  if (!(r.length > 0.0)) {
    // Every wall a single point: the bounding box.
    r.length = diagonal;
    r.source = ReferenceLengthSource::kBoundingBox;
    r.description = "the walls have no extent: the diagonal of the grid's bounding box";
  }
  return r;
}

}  // namespace

std::string_view ReferenceLengthSourceName(ReferenceLengthSource source) {
  switch (source) {
    case ReferenceLengthSource::kGiven:
      return "given";
    case ReferenceLengthSource::kWall:
      return "wall";
    case ReferenceLengthSource::kBoundingBox:
      return "bounding box";
  }
  return "unknown";
}

ReferenceLength DetectReferenceLength(const MultiBlockGrid& grid, const BoundaryKinds& kinds) {
  const WallPoints w = CollectWallPoints(grid, kinds);
  const double diagonal =
      w.points.empty() && grid.blocks.empty() ? 0.0 : std::sqrt(Distance2(w.lo, w.hi));
  if (w.points.empty()) {
    ReferenceLength r;
    r.length = diagonal;
    r.source = ReferenceLengthSource::kBoundingBox;
    r.description =
        absl::StrFormat("no wall point: the diagonal of the grid's bounding box, from %s to %s",
                        FormatPoint(w.lo, w.dim), FormatPoint(w.hi, w.dim));
    return r;
  }
  // The walls: wall points joined when they are neighbours in a block or coincide.
  UnionFind walls(w.points.size());
  JoinIndexNeighbours(grid, w.ids, walls);
  const double eps = std::max(kCoincidence * diagonal, std::numeric_limits<double>::min());
  JoinCoinciding(w.points, w.lo, eps, walls);
  return LargestWall(w, walls, diagonal);
}

BoundaryTolerances ScaleTolerances(const BoundaryTolerances& tolerances, uint8_t relative_kinds,
                                   double reference_length) {
  BoundaryTolerances t = tolerances;
  if (relative_kinds & kRelativeWall) t.wall *= reference_length;
  if (relative_kinds & kRelativeInterface) t.interface *= reference_length;
  if (relative_kinds & kRelativeOuter) t.outer *= reference_length;
  if ((relative_kinds & kRelativeInterior) && std::isfinite(t.interior)) {
    t.interior *= reference_length;
  }
  return t;
}

}  // namespace splinegrid
