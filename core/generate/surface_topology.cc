#include "core/generate/surface_topology.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <numbers>
#include <string>

#include "Eigen/Core"
#include "Eigen/Geometry"
#include "absl/strings/str_cat.h"
#include "core/grid/connectivity_edit.h"
#include "core/util/status_macros.h"
#include "core/util/union_find.h"

namespace splinegrid {
namespace {

using Vec = Eigen::Vector3d;

// Points of a symmetry-plane edge lie this close (times the surface's size) to the plane.
constexpr double kPlaneTolerance = 1e-6;

Vec PointOf(const StructuredBlock& block, int64_t q) {
  const double* x = block.coords().data() + 3 * q;
  return Vec(x[0], x[1], x[2]);
}

// The bounding box of all blocks.
struct Box {
  Vec lo = Vec::Constant(HUGE_VAL), hi = Vec::Constant(-HUGE_VAL);
  double diagonal() const { return (hi - lo).norm(); }
};

Box BoundingBox(const MultiBlockGrid& surface) {
  Box box;
  for (const StructuredBlock& block : surface.blocks) {
    for (int64_t q = 0; q < block.num_points(); ++q) {
      box.lo = box.lo.cwiseMin(PointOf(block, q));
      box.hi = box.hi.cwiseMax(PointOf(block, q));
    }
  }
  return box;
}

// The point indices of block edge e of an ni x nj block: j = 0, j = nj - 1, i = 0, i = ni - 1.
std::vector<int64_t> EdgePoints(int ni, int nj, int e) {
  std::vector<int64_t> out;
  if (e < 2) {
    const int j = e == 0 ? 0 : nj - 1;
    for (int i = 0; i < ni; ++i) out.push_back(i + int64_t{ni} * j);
  } else {
    const int i = e == 2 ? 0 : ni - 1;
    for (int j = 0; j < nj; ++j) out.push_back(i + int64_t{ni} * j);
  }
  return out;
}

// The grid normal (central differences, one-sided on edges) X_i x X_j at point q; zero where a
// direction collapses.
Vec GridNormal(const StructuredBlock& block, int64_t q) {
  const int ni = block.extent(0), nj = block.extent(1);
  const int i = static_cast<int>(q % ni), j = static_cast<int>(q / ni);
  auto at = [&](int ii, int jj) { return PointOf(block, ii + int64_t{ni} * jj); };
  const Vec du = at(std::min(i + 1, ni - 1), j) - at(std::max(i - 1, 0), j);
  const Vec dv = at(i, std::min(j + 1, nj - 1)) - at(i, std::max(j - 1, 0));
  return du.cross(dv);
}

// The global index of (block, point): offsets of the blocks in one numbering.
struct PointNumbering {
  std::vector<int64_t> base;
  int64_t total = 0;
  explicit PointNumbering(const MultiBlockGrid& surface) {
    for (const StructuredBlock& block : surface.blocks) {
      base.push_back(total);
      total += block.num_points();
    }
  }
};

// The direction in which the counter-clockwise boundary loop of a block's (i, j) parameter
// square runs along `face`'s tangential direction: +i along j = 0, +j along i = max, -i along
// j = max, -j along i = 0.
int LoopDirection(const Face& face) {
  if (face.normal == 1) return face.upper ? -1 : +1;
  return face.upper ? +1 : -1;
}

// OK when `match` fits `surface`'s blocks (CheckMatchFits) as a match of two of their edges.
absl::Status CheckSurfaceMatch(const MultiBlockGrid& surface, const BoundaryMatch& match) {
  SG_RETURN_IF_ERROR(CheckMatchFits(surface, match, "the surface's blocks"));
  if (match.a.face.normal == 2 || match.b.face.normal == 2) {
    return absl::InvalidArgumentError(absl::StrCat("connectivity: the match ", match.Describe(),
                                                   " does not fit the surface's blocks"));
  }
  return absl::OkStatus();
}

// Orients the blocks alike (file comment of the header): BFS over the matches. Two blocks are
// oriented alike when their counter-clockwise boundary loops run along the shared edge in
// opposite directions (as two faces of a polyhedron share an edge), a question of the match's
// indices alone: the normals of blocks meeting at a sharp crease point almost opposite ways and
// cannot tell.
absl::Status OrientBlocks(const MultiBlockGrid& surface, const Connectivity& connectivity,
                          SurfaceTopology& out) {
  const int num_blocks = static_cast<int>(surface.blocks.size());
  struct Link {
    int other;
    int sign;
  };
  std::vector<std::vector<Link>> links(num_blocks);
  for (const BoundaryMatch& match : connectivity.matches) {
    // The direction of a along the shared edge (not its face normal).
    const int t = match.a.face.normal == 0 ? 1 : 0;
    const int along = match.reversed[t] ? -1 : +1;
    const int sign = -LoopDirection(match.a.face) * LoopDirection(match.b.face) * along;
    links[match.a.face.block].push_back({match.b.face.block, sign});
    if (match.b.face.block != match.a.face.block) {
      links[match.b.face.block].push_back({match.a.face.block, sign});
    }
  }
  out.side.assign(num_blocks, 0);
  out.component.assign(num_blocks, -1);
  for (int start = 0; start < num_blocks; ++start) {
    if (out.side[start] != 0) continue;
    const int component = out.components++;
    out.side[start] = 1;
    out.component[start] = component;
    std::deque<int> queue = {start};
    while (!queue.empty()) {
      const int b = queue.front();
      queue.pop_front();
      for (const Link& link : links[b]) {
        const int want = out.side[b] * link.sign;
        if (out.side[link.other] == 0) {
          out.side[link.other] = want;
          out.component[link.other] = component;
          queue.push_back(link.other);
        } else if (out.side[link.other] != want) {
          return absl::InvalidArgumentError(absl::StrCat(
              "surface: blocks ", b, " and ", link.other,
              " cannot be oriented alike: their normals agree along one shared edge and are "
              "opposite along another (a non-orientable surface, or blocks matched back to "
              "front)"));
        }
      }
    }
  }
  return absl::OkStatus();
}

// The symmetry plane that block edge `points` of `block` lies on (header), or -1 for none;
// `copies` counts the block points of each vertex.
int FindPlane(const MultiBlockGrid& surface, int b, const std::vector<int64_t>& points,
              const std::vector<int>& copies, const Box& box, SurfaceTopology& out) {
  const StructuredBlock& block = surface.blocks[b];
  // Free: no point but the two ends is shared with another block point.
  for (size_t t = 1; t + 1 < points.size(); ++t) {
    if (copies[out.vertex[b][points[t]]] != 1) return -1;
  }
  const double tolerance = kPlaneTolerance * box.diagonal();
  const double max_sine = std::sin(kSymmetryTiltDegrees * std::numbers::pi / 180.0);
  for (int axis = 0; axis < 3; ++axis) {
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (int64_t q : points) {
      lo = std::min(lo, PointOf(block, q)[axis]);
      hi = std::max(hi, PointOf(block, q)[axis]);
    }
    if (hi - lo > tolerance) continue;
    const double value = 0.5 * (lo + hi);
    const bool below = box.hi[axis] <= value + tolerance;
    const bool above = box.lo[axis] >= value - tolerance;
    if (below == above) continue;  // the surface on both sides (or flat in the plane)
    bool square = true;
    for (int64_t q : points) {
      const Vec n = GridNormal(block, q);
      if (n.norm() > 0.0) square = square && std::abs(n[axis]) <= max_sine * n.norm();
    }
    if (!square) continue;
    for (size_t p = 0; p < out.planes.size(); ++p) {
      if (out.planes[p].axis == axis && std::abs(out.planes[p].value - value) <= tolerance) {
        return static_cast<int>(p);
      }
    }
    if (out.planes.size() >= kMaxSymmetryPlanes) return -1;
    out.planes.push_back({axis, value});
    return static_cast<int>(out.planes.size()) - 1;
  }
  return -1;
}

}  // namespace

absl::StatusOr<SurfaceTopology> BuildSurfaceTopology(const MultiBlockGrid& surface,
                                                     const Connectivity& connectivity,
                                                     bool find_symmetry_planes) {
  const int num_blocks = static_cast<int>(surface.blocks.size());
  const PointNumbering numbering(surface);
  UnionFind joined(numbering.total);
  SurfaceTopology out;
  auto global = [&](int b, const Extents& x) {
    return numbering.base[b] + surface.blocks[b].Index(x[0], x[1], 0);
  };
  for (const BoundaryMatch& match : connectivity.matches) {
    SG_RETURN_IF_ERROR(CheckSurfaceMatch(surface, match));
    if (match.step != 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("surface: the match ", match.Describe(),
                       " has hanging nodes; layers are marched off point-matched blocks only"));
    }
    const int a = match.a.face.block, b = match.b.face.block;
    ForEachMatchedPoint(match, [&](const Extents& x, const Extents& y) {
      joined.Join(global(a, x), global(b, y));
      const double gap = (PointOf(surface.blocks[a], surface.blocks[a].Index(x[0], x[1], 0)) -
                          PointOf(surface.blocks[b], surface.blocks[b].Index(y[0], y[1], 0)))
                             .norm();
      out.max_gap = std::max(out.max_gap, gap);
    });
  }
  // Poles: every point of a collapsed edge is one vertex, and none is smoothed.
  const Box box = BoundingBox(surface);
  const double scale = box.diagonal();
  out.scale = scale;
  std::vector<char> on_pole(numbering.total, 0);
  for (int b = 0; b < num_blocks; ++b) {
    const StructuredBlock& block = surface.blocks[b];
    for (int e = 0; e < 4; ++e) {
      const std::vector<int64_t> points = EdgePoints(block.extent(0), block.extent(1), e);
      const Vec first = PointOf(block, points.front());
      const bool collapsed = std::all_of(points.begin(), points.end(), [&](int64_t q) {
        return (PointOf(block, q) - first).norm() <= kCollapsedFraction * scale;
      });
      if (!collapsed) continue;
      for (int64_t q : points) {
        joined.Join(numbering.base[b] + points.front(), numbering.base[b] + q);
        on_pole[numbering.base[b] + q] = 1;
      }
    }
  }
  // Vertices numbered by their first point.
  std::vector<int64_t> number_of_root(numbering.total, -1);
  out.vertex.resize(num_blocks);
  for (int b = 0; b < num_blocks; ++b) {
    out.vertex[b].resize(surface.blocks[b].num_points());
    for (int64_t q = 0; q < surface.blocks[b].num_points(); ++q) {
      const int64_t root = joined.Find(numbering.base[b] + q);
      if (number_of_root[root] < 0) number_of_root[root] = out.num_vertices++;
      out.vertex[b][q] = number_of_root[root];
    }
  }
  SG_RETURN_IF_ERROR(OrientBlocks(surface, connectivity, out));

  std::vector<int> copies(out.num_vertices, 0);
  std::vector<char> pole(out.num_vertices, 0), interior(out.num_vertices, 0),
      corner(out.num_vertices, 0);
  for (int b = 0; b < num_blocks; ++b) {
    const int ni = surface.blocks[b].extent(0), nj = surface.blocks[b].extent(1);
    for (int64_t q = 0; q < surface.blocks[b].num_points(); ++q) {
      const int64_t v = out.vertex[b][q];
      const int i = static_cast<int>(q % ni), j = static_cast<int>(q / ni);
      const bool edge_i = i == 0 || i == ni - 1, edge_j = j == 0 || j == nj - 1;
      ++copies[v];
      pole[v] = pole[v] || on_pole[numbering.base[b] + q];
      interior[v] = interior[v] || (!edge_i && !edge_j);
      corner[v] = corner[v] || (edge_i && edge_j);
    }
  }
  out.plane.assign(out.num_vertices, 0);
  if (find_symmetry_planes) {
    for (int b = 0; b < num_blocks; ++b) {
      const StructuredBlock& block = surface.blocks[b];
      for (int e = 0; e < 4; ++e) {
        const std::vector<int64_t> points = EdgePoints(block.extent(0), block.extent(1), e);
        if (std::all_of(points.begin(), points.end(),
                        [&](int64_t q) { return on_pole[numbering.base[b] + q] != 0; })) {
          continue;  // a pole, no edge
        }
        const int p = FindPlane(surface, b, points, copies, box, out);
        if (p < 0) continue;
        for (int64_t q : points) out.plane[out.vertex[b][q]] |= uint8_t{1} << p;
      }
    }
  }
  out.kind.resize(out.num_vertices);
  for (int64_t v = 0; v < out.num_vertices; ++v) {
    if (pole[v]) {
      out.kind[v] = VertexKind::kFixed;
    } else if (copies[v] > 1 || interior[v] || out.plane[v] != 0) {
      out.kind[v] = VertexKind::kShared;
    } else {
      out.kind[v] = corner[v] ? VertexKind::kFixed : VertexKind::kFreeEdge;
    }
  }
  return out;
}

absl::Status OrientOutward(const MultiBlockGrid& surface, SurfaceTopology& topology) {
  const int num_blocks = static_cast<int>(surface.blocks.size());
  for (int c = 0; c < topology.components; ++c) {
    Vec centroid = Vec::Zero();
    int64_t count = 0;
    for (int b = 0; b < num_blocks; ++b) {
      if (topology.component[b] != c) continue;
      for (int64_t q = 0; q < surface.blocks[b].num_points(); ++q)
        centroid += PointOf(surface.blocks[b], q);
      count += surface.blocks[b].num_points();
    }
    centroid /= static_cast<double>(count);
    double flux = 0.0, magnitude = 0.0;
    int first = -1;
    for (int b = 0; b < num_blocks; ++b) {
      if (topology.component[b] != c) continue;
      if (first < 0) first = b;
      for (int64_t q = 0; q < surface.blocks[b].num_points(); ++q) {
        const Vec n = topology.side[b] * GridNormal(surface.blocks[b], q);
        const Vec r = PointOf(surface.blocks[b], q) - centroid;
        flux += n.dot(r);
        magnitude += n.norm() * r.norm();
      }
    }
    if (!(std::abs(flux) > 1e-3 * magnitude)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "surface: the blocks connected to block ", first,
          " enclose no volume, so 'outward' has no meaning for them; give the side instead"));
    }
    if (flux < 0.0) {
      for (int b = 0; b < num_blocks; ++b) {
        if (topology.component[b] == c) topology.side[b] = -topology.side[b];
      }
    }
  }
  return absl::OkStatus();
}

}  // namespace splinegrid
