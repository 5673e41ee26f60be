#include "core/grid/boundary_kinds.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"

namespace splinegrid {
namespace {

double Distance(const StructuredBlock& block, const Extents& x, const Extents& y) {
  const double* p = block.Point(x[0], x[1], x[2]);
  const double* q = block.Point(y[0], y[1], y[2]);
  double d2 = 0.0;
  for (int c = 0; c < block.spatial_dim(); ++c) d2 += (p[c] - q[c]) * (p[c] - q[c]);
  return std::sqrt(d2);
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// One bit per face of a block: i=0, i=max, j=0, j=max, k=0, k=max.
uint8_t FaceBit(const Face& face) { return uint8_t{1} << (2 * face.normal + face.upper); }

// Calls fn(x) for every point x of `face`.
template <typename Fn>
void ForEachFacePoint(const StructuredBlock& block, const Face& face, Fn fn) {
  Extents lo = {0, 0, 0}, hi = {block.extent(0) - 1, block.extent(1) - 1, block.extent(2) - 1};
  lo[face.normal] = hi[face.normal] = face.upper ? block.extent(face.normal) - 1 : 0;
  for (int k = lo[2]; k <= hi[2]; ++k) {
    for (int j = lo[1]; j <= hi[1]; ++j) {
      for (int i = lo[0]; i <= hi[0]; ++i) fn(Extents{i, j, k});
    }
  }
}

// Wall or outer, from the clustering of the grid towards the face.
BoundaryKind GeometricKind(const StructuredBlock& block, const Face& face,
                           const BoundaryKindOptions& options) {
  const int d = face.normal;
  std::vector<double> first, all;
  ForEachFacePoint(block, face, [&](const Extents& x) {
    Extents y = x;
    y[d] += face.upper ? -1 : 1;
    first.push_back(Distance(block, x, y));
  });
  // Median spacing of direction d over (a sample of) the whole block.
  const int64_t n = block.num_points();
  const int64_t stride = std::max<int64_t>(1, n / 20000);
  for (int64_t p = 0; p < n; p += stride) {
    const Extents x = {static_cast<int>(p % block.extent(0)),
                       static_cast<int>((p / block.extent(0)) % block.extent(1)),
                       static_cast<int>(p / (int64_t{block.extent(0)} * block.extent(1)))};
    if (x[d] + 1 >= block.extent(d)) continue;
    Extents y = x;
    ++y[d];
    all.push_back(Distance(block, x, y));
  }
  return Median(first) < options.wall_spacing_ratio * Median(all) ? BoundaryKind::kWall
                                                                  : BoundaryKind::kOuter;
}

// A wall segment of a planar block: two neighbouring points of a wall face that both carry the
// wall kind.
struct WallSegment {
  const double* a;
  const double* b;
};

// Position of a point of `block`.
const double* At(const StructuredBlock& block, const Extents& x) {
  return block.Point(x[0], x[1], x[2]);
}

// Whether a solid lies behind the face at `contact` (a point at an end of an unmatched run of a
// face of a planar block): some wall segment that starts at (a point coincident with) `contact`
// leaves it on the side of the face away from the block's interior, i.e. its unit direction w
// has w . n_in < -kBehind, with n_in the unit direction from the face into the block there.
// (A channel inlet between two walls fails this: its walls run along the block's side.)
bool SolidBehind(const double* contact, const double* inward, int dim,
                 std::span<const WallSegment> walls, double coincide) {
  constexpr double kBehind = 0.1;  // cos 84 degrees: the wall turns away by > 6 degrees
  double n2 = 0.0;
  for (int c = 0; c < dim; ++c) n2 += (inward[c] - contact[c]) * (inward[c] - contact[c]);
  if (!(n2 > 0.0)) return false;
  for (const WallSegment& w : walls) {
    for (const auto& [from, to] : {std::pair{w.a, w.b}, std::pair{w.b, w.a}}) {
      double gap2 = 0.0, dot = 0.0, l2 = 0.0;
      for (int c = 0; c < dim; ++c) {
        gap2 += (from[c] - contact[c]) * (from[c] - contact[c]);
        dot += (to[c] - from[c]) * (inward[c] - contact[c]);
        l2 += (to[c] - from[c]) * (to[c] - from[c]);
      }
      if (gap2 <= coincide * coincide && l2 > 0.0 && dot < -kBehind * std::sqrt(l2 * n2)) {
        return true;
      }
    }
  }
  return false;
}

// Second pass of ClassifyBoundaries for planar blocks (one point in k): a run of unmatched
// points of a face classified outer by clustering is a wall when a solid lies behind the face at
// both ends of the run (SolidBehind), as at the blunt base of a nozzle lip or a thick trailing
// edge: the run then joins two walls of one solid across the side of the face away from the
// flow. The clustering test misses such bases when the grid is not clustered towards them.
// Overridden faces are left as given. Cost: O(boundary points x wall segments) for the run ends.
void WallBasesBetweenWalls(const MultiBlockGrid& grid, std::span<const FaceKindOverride> overrides,
                           const std::vector<std::vector<uint8_t>>& matched, BoundaryKinds& kinds) {
  constexpr uint8_t kWallBit = static_cast<uint8_t>(BoundaryKind::kWall);
  constexpr uint8_t kOuterBit = static_cast<uint8_t>(BoundaryKind::kOuter);
  std::vector<WallSegment> walls;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  int dim = 0;
  for (int b = 0; b < static_cast<int>(grid.blocks.size()); ++b) {
    const StructuredBlock& block = grid.blocks[b];
    if (block.extent(2) != 1) continue;
    dim = std::max(dim, block.spatial_dim());
    for (int64_t p = 0; p < block.num_points(); ++p) {
      for (int c = 0; c < block.spatial_dim(); ++c) {
        lo[c] = std::min(lo[c], block.coords()[block.spatial_dim() * p + c]);
        hi[c] = std::max(hi[c], block.coords()[block.spatial_dim() * p + c]);
      }
    }
    const std::vector<Face> faces = BlockFaces(block, b);
    for (size_t f = 0; f < faces.size(); ++f) {
      if (kinds.face_kinds[b][f] != BoundaryKind::kWall) continue;
      const int e = 1 - faces[f].normal;  // the face's own direction
      Extents x = {0, 0, 0};
      x[faces[f].normal] = faces[f].upper ? block.extent(faces[f].normal) - 1 : 0;
      for (int r = 0; r + 1 < block.extent(e); ++r) {
        Extents y = x;
        x[e] = r, y[e] = r + 1;
        if ((kinds.point_kinds[b][block.Index(x[0], x[1], 0)] & kWallBit) &&
            (kinds.point_kinds[b][block.Index(y[0], y[1], 0)] & kWallBit)) {
          walls.push_back({At(block, x), At(block, y)});
        }
      }
    }
  }
  if (walls.empty()) return;
  double diagonal2 = 0.0;
  for (int c = 0; c < dim; ++c) diagonal2 += (hi[c] - lo[c]) * (hi[c] - lo[c]);
  const double coincide = 1e-9 * std::sqrt(diagonal2);
  for (int b = 0; b < static_cast<int>(grid.blocks.size()); ++b) {
    const StructuredBlock& block = grid.blocks[b];
    if (block.extent(2) != 1 || ActiveDirections(block.extents()) != 2) continue;
    const std::vector<Face> faces = BlockFaces(block, b);
    for (size_t f = 0; f < faces.size(); ++f) {
      const Face& face = faces[f];
      const bool overridden =
          std::any_of(overrides.begin(), overrides.end(),
                      [&](const FaceKindOverride& o) { return o.face == face; });
      if (overridden || kinds.face_kinds[b][f] != BoundaryKind::kOuter) continue;
      const int d = face.normal, e = 1 - d, n = block.extent(e);
      auto point = [&](int r) {
        Extents x = {0, 0, 0};
        x[d] = face.upper ? block.extent(d) - 1 : 0;
        x[e] = r;
        return x;
      };
      auto inward = [&](int r) {
        Extents x = point(r);
        x[d] += face.upper ? -1 : 1;
        return At(block, x);
      };
      auto unmatched = [&](int r) {
        const Extents x = point(r);
        return !(matched[b][block.Index(x[0], x[1], 0)] & FaceBit(face));
      };
      bool all_runs = true, any_run = false;
      for (int r0 = 0; r0 < n;) {
        if (!unmatched(r0)) {
          ++r0;
          continue;
        }
        int r1 = r0;
        while (r1 + 1 < n && unmatched(r1 + 1)) ++r1;
        any_run = true;
        // The contact points: the matched neighbours of the run, or its own ends at corners.
        const int c0 = r0 > 0 ? r0 - 1 : r0, c1 = r1 + 1 < n ? r1 + 1 : r1;
        const bool base =
            SolidBehind(At(block, point(c0)), inward(c0), block.spatial_dim(), walls, coincide) &&
            SolidBehind(At(block, point(c1)), inward(c1), block.spatial_dim(), walls, coincide);
        if (base) {
          for (int r = c0; r <= c1; ++r) {
            const Extents x = point(r);
            uint8_t& k = kinds.point_kinds[b][block.Index(x[0], x[1], 0)];
            // The run and its contact points become wall: the outer kind they carry is this
            // face's, except at a block corner, which keeps the other face's kind.
            if (r > 0 && r + 1 < n) k &= static_cast<uint8_t>(~kOuterBit);
            k |= kWallBit;
          }
        } else {
          all_runs = false;
        }
        r0 = r1 + 1;
      }
      if (any_run && all_runs) kinds.face_kinds[b][f] = BoundaryKind::kWall;
    }
  }
}

}  // namespace

std::string_view BoundaryKindName(BoundaryKind kind) {
  switch (kind) {
    case BoundaryKind::kWall:
      return "wall";
    case BoundaryKind::kInterface:
      return "interface";
    case BoundaryKind::kOuter:
      return "outer";
  }
  return "unknown";
}

absl::StatusOr<BoundaryKinds> ClassifyBoundaries(const MultiBlockGrid& grid,
                                                 const Connectivity& connectivity,
                                                 std::span<const FaceKindOverride> overrides,
                                                 const BoundaryKindOptions& options) {
  const int num_blocks = static_cast<int>(grid.blocks.size());
  for (const FaceKindOverride& o : overrides) {
    if (o.face.block < 0 || o.face.block >= num_blocks || o.face.normal < 0 || o.face.normal > 2 ||
        grid.blocks[o.face.block].extent(o.face.normal) == 1) {
      return absl::InvalidArgumentError(absl::StrCat(
          "face kind override: block ", o.face.block, " face ",
          o.face.normal >= 0 && o.face.normal <= 2 ? FaceName(o.face) : "?", " does not exist"));
    }
  }
  BoundaryKinds kinds;
  kinds.point_kinds.resize(num_blocks);
  kinds.face_kinds.resize(num_blocks);
  // Matched points first: they are interface whatever their face is. `matched` holds, per
  // point, a bit per face (FaceBit) on which a match covers it: a point at the end of a match
  // (a corner, an edge of a volume face) also lies on the neighbouring face, whose kind it
  // still carries.
  std::vector<std::vector<uint8_t>> matched(num_blocks);
  for (int b = 0; b < num_blocks; ++b) {
    kinds.point_kinds[b].assign(grid.blocks[b].num_points(), 0);
    matched[b].assign(grid.blocks[b].num_points(), 0);
  }
  auto mark = [&](const FaceRange& r) {
    const StructuredBlock& block = grid.blocks[r.face.block];
    for (int k = r.begin[2]; k <= r.end[2]; ++k) {
      for (int j = r.begin[1]; j <= r.end[1]; ++j) {
        for (int i = r.begin[0]; i <= r.end[0]; ++i) {
          const int64_t p = block.Index(i, j, k);
          matched[r.face.block][p] |= FaceBit(r.face);
          kinds.point_kinds[r.face.block][p] |= static_cast<uint8_t>(BoundaryKind::kInterface);
        }
      }
    }
  };
  for (const BoundaryMatch& m : connectivity.matches) {
    mark(m.a);
    mark(m.b);
  }
  for (int b = 0; b < num_blocks; ++b) {
    const StructuredBlock& block = grid.blocks[b];
    const bool surface = block.spatial_dim() == 3 && ActiveDirections(block.extents()) == 2;
    if (surface) {
      for (uint8_t& k : kinds.point_kinds[b]) k |= static_cast<uint8_t>(BoundaryKind::kWall);
    }
    for (const Face& face : BlockFaces(block, b)) {
      BoundaryKind kind = surface ? BoundaryKind::kWall : GeometricKind(block, face, options);
      for (const FaceKindOverride& o : overrides) {
        if (o.face == face) kind = o.kind;
      }
      kinds.face_kinds[b].push_back(kind);
      // A point matched on this face still carries the face's kind where it borders an unmatched
      // point of the face: the end of a C-grid's wake cut is also the airfoil's trailing edge.
      auto unmatched = [&](const Extents& x) {
        return !(matched[b][block.Index(x[0], x[1], x[2])] & FaceBit(face));
      };
      ForEachFacePoint(block, face, [&](const Extents& x) {
        bool own = unmatched(x);
        for (int d = 0; d < 3 && !own; ++d) {
          if (d == face.normal) continue;
          for (int step : {-1, 1}) {
            Extents y = x;
            y[d] += step;
            if (y[d] >= 0 && y[d] < block.extent(d) && unmatched(y)) own = true;
          }
        }
        if (own) kinds.point_kinds[b][block.Index(x[0], x[1], x[2])] |= static_cast<uint8_t>(kind);
      });
    }
  }
  WallBasesBetweenWalls(grid, overrides, matched, kinds);
  return kinds;
}

absl::Status BoundaryTolerances::Validate() const {
  const std::pair<const char*, double> fields[] = {
      {"wall", wall}, {"interface", interface}, {"outer", outer}};
  for (const auto& [name, value] : fields) {
    if (!(value > 0.0) || !std::isfinite(value)) {
      return absl::InvalidArgumentError(absl::StrCat("tolerances.", name, " = ", value,
                                                     "; tolerances must be positive and finite"));
    }
  }
  if (!(interior > 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("tolerances.interior = ", interior, "; must be positive (or infinite)"));
  }
  if (!(edge >= 0.0 && edge <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("tolerances.edge = ", edge, " is outside [0, 1]"));
  }
  return absl::OkStatus();
}

double BoundaryTolerances::For(uint8_t mask) const {
  if (mask == 0) return interior;
  double t = INFINITY;
  if (mask & static_cast<uint8_t>(BoundaryKind::kWall)) t = std::min(t, wall);
  if (mask & static_cast<uint8_t>(BoundaryKind::kInterface)) t = std::min(t, interface);
  if (mask & static_cast<uint8_t>(BoundaryKind::kOuter)) t = std::min(t, outer);
  return t;
}

std::vector<double> PointTolerances(const BoundaryKinds& kinds, int b,
                                    const BoundaryTolerances& tolerances) {
  std::vector<double> tol(kinds.point_kinds[b].size());
  for (size_t p = 0; p < tol.size(); ++p) tol[p] = tolerances.For(kinds.point_kinds[b][p]);
  return tol;
}

std::vector<double> PointEdgeTolerances(const BoundaryKinds& kinds, int b,
                                        const BoundaryTolerances& tolerances) {
  return std::vector<double>(kinds.point_kinds[b].size(), tolerances.edge);
}

}  // namespace splinegrid
