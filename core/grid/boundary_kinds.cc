#include "core/grid/boundary_kinds.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

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

// A wall segment: two neighbouring points, along one direction of a wall face, that both carry
// the wall kind, seen from one end (`from`) towards the other (`to`).
struct WallSegment {
  const double* from;
  const double* to;
};

// Position of a point of `block`.
const double* At(const StructuredBlock& block, const Extents& x) {
  return block.Point(x[0], x[1], x[2]);
}

// The wall segments of a grid, found by their starting point: sorted by a projection of `from`
// on a direction no grid plane is likely to be normal to, so that the segments starting at one
// point are a short range of the order.
class WallSegments {
 public:
  WallSegments(int dim, double coincide) : dim_(dim), coincide_(coincide) {}

  void Add(const double* a, const double* b) {
    segments_.push_back({a, b});
    segments_.push_back({b, a});
  }
  void Sort() {
    std::sort(segments_.begin(), segments_.end(), [&](const WallSegment& x, const WallSegment& y) {
      return Key(x.from) < Key(y.from);
    });
  }
  bool empty() const { return segments_.empty(); }

  // Whether a solid lies behind a face at `contact` (a point at an end of an unmatched run of a
  // face line; `inward` its neighbour into the block): some wall segment that starts at (a point
  // coincident with) `contact` leaves it on the side of the face away from the block's interior,
  // i.e. its unit direction w has w . n_in < -kBehind, with n_in the unit direction from the face
  // into the block there. (A channel inlet between two walls fails this: its walls run along
  // the block's side.)
  bool SolidBehind(const double* contact, const double* inward) const {
    constexpr double kBehind = 0.1;  // cos 84 degrees: the wall turns away by > 6 degrees
    double n2 = 0.0;
    for (int c = 0; c < dim_; ++c) n2 += (inward[c] - contact[c]) * (inward[c] - contact[c]);
    if (!(n2 > 0.0)) return false;
    const double key = Key(contact), reach = 2.0 * coincide_;  // |kProjection| < 2
    auto it = std::lower_bound(segments_.begin(), segments_.end(), key - reach,
                               [&](const WallSegment& w, double k) { return Key(w.from) < k; });
    for (; it != segments_.end() && Key(it->from) <= key + reach; ++it) {
      double gap2 = 0.0, dot = 0.0, l2 = 0.0;
      for (int c = 0; c < dim_; ++c) {
        gap2 += (it->from[c] - contact[c]) * (it->from[c] - contact[c]);
        dot += (it->to[c] - it->from[c]) * (inward[c] - contact[c]);
        l2 += (it->to[c] - it->from[c]) * (it->to[c] - it->from[c]);
      }
      if (gap2 <= coincide_ * coincide_ && l2 > 0.0 && dot < -kBehind * std::sqrt(l2 * n2)) {
        return true;
      }
    }
    return false;
  }

 private:
  static constexpr double kProjection[3] = {1.0, 0.6180339887498949, 0.4142135623730950};
  double Key(const double* p) const {
    double key = 0.0;
    for (int c = 0; c < dim_; ++c) key += kProjection[c] * p[c];
    return key;
  }

  int dim_;
  double coincide_;
  std::vector<WallSegment> segments_;
};

// Whether the wall-base pass looks at `block`: planar blocks (one point in k) and volume blocks.
bool HasSolidFaces(const StructuredBlock& block) {
  const int active = ActiveDirections(block.extents());
  return (block.extent(2) == 1 && active == 2) || active == 3;
}

// The in-face directions of `face` (those with more than one point).
std::vector<int> FaceDirections(const StructuredBlock& block, const Face& face) {
  std::vector<int> directions;
  for (int e = 0; e < 3; ++e) {
    if (e != face.normal && block.extent(e) > 1) directions.push_back(e);
  }
  return directions;
}

// The kind bits of wall and outer points.
constexpr uint8_t kWallBit = static_cast<uint8_t>(BoundaryKind::kWall);
constexpr uint8_t kOuterBit = static_cast<uint8_t>(BoundaryKind::kOuter);

// The wall segments along the wall faces of the planar and volume blocks, between neighbouring
// points that both carry the wall kind; points coincide within 1e-9 of the diagonal of those
// blocks' bounding box.
WallSegments CollectWallSegments(const MultiBlockGrid& grid, const BoundaryKinds& kinds) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  int dim = 0;
  for (const StructuredBlock& block : grid.blocks) {
    if (!HasSolidFaces(block)) continue;
    dim = std::max(dim, block.spatial_dim());
    for (int64_t p = 0; p < block.num_points(); ++p) {
      for (int c = 0; c < block.spatial_dim(); ++c) {
        lo[c] = std::min(lo[c], block.coords()[block.spatial_dim() * p + c]);
        hi[c] = std::max(hi[c], block.coords()[block.spatial_dim() * p + c]);
      }
    }
  }
  double diagonal2 = 0.0;
  for (int c = 0; c < dim; ++c) diagonal2 += (hi[c] - lo[c]) * (hi[c] - lo[c]);
  WallSegments walls(dim, 1e-9 * std::sqrt(diagonal2));
  for (int b = 0; b < static_cast<int>(grid.blocks.size()); ++b) {
    const StructuredBlock& block = grid.blocks[b];
    if (!HasSolidFaces(block)) continue;
    const std::vector<Face> faces = BlockFaces(block, b);
    for (size_t f = 0; f < faces.size(); ++f) {
      if (kinds.face_kinds[b][f] != BoundaryKind::kWall) continue;
      for (int e : FaceDirections(block, faces[f])) {
        ForEachFacePoint(block, faces[f], [&](const Extents& x) {
          if (x[e] + 1 >= block.extent(e)) return;
          Extents y = x;
          ++y[e];
          if ((kinds.point_kinds[b][block.Index(x[0], x[1], x[2])] & kWallBit) &&
              (kinds.point_kinds[b][block.Index(y[0], y[1], y[2])] & kWallBit)) {
            walls.Add(At(block, x), At(block, y));
          }
        });
      }
    }
  }
  return walls;
}

// The wall-base pass over one outer face `faces[f]` of block b (WallBasesBetweenWalls).
class FaceBaseScan {
 public:
  FaceBaseScan(const StructuredBlock& block, int b, const std::vector<Face>& faces, size_t f,
               const std::vector<std::vector<uint8_t>>& matched, BoundaryKinds& kinds)
      : block_(block),
        b_(b),
        faces_(faces),
        f_(f),
        face_(faces[f]),
        matched_(matched),
        kinds_(kinds),
        directions_(FaceDirections(block, faces[f])) {}

  // Finds the bases on the face, makes them wall, and the face wall when all its unmatched
  // points are on a base.
  void Run(const WallSegments& walls) {
    const std::vector<uint8_t> base = FindBases(walls);
    bool any_unmatched = false, all_base = true;
    ForEachFacePoint(block_, face_, [&](const Extents& x) {
      if (Unmatched(x)) any_unmatched = true, all_base = all_base && base[Slot(x)];
      if (!base[Slot(x)]) return;
      uint8_t& k = kinds_.point_kinds[b_][Index(x)];
      // The base and its contact points become wall: the outer kind they carry is this
      // face's unless another outer face of the block passes through them.
      if (!OuterElsewhere(x)) k &= static_cast<uint8_t>(~kOuterBit);
      k |= kWallBit;
    });
    if (any_unmatched && all_base) kinds_.face_kinds[b_][f_] = BoundaryKind::kWall;
  }

 private:
  // Point index of x in the block.
  int64_t Index(const Extents& x) const { return block_.Index(x[0], x[1], x[2]); }
  // Whether x has no match across this face.
  bool Unmatched(const Extents& x) const { return !(matched_[b_][Index(x)] & FaceBit(face_)); }
  // The neighbour of face point x into the block.
  const double* Inward(Extents x) const {
    x[face_.normal] += face_.upper ? -1 : 1;
    return At(block_, x);
  }
  // Whether another face of the block through x gives x the outer kind (an unmatched point
  // of an outer face): that kind stays when x becomes wall.
  bool OuterElsewhere(const Extents& x) const {
    for (int e : directions_) {
      for (const bool upper : {false, true}) {
        if (x[e] != (upper ? block_.extent(e) - 1 : 0)) continue;
        const Face other{b_, e, upper};
        const size_t g =
            static_cast<size_t>(std::find(faces_.begin(), faces_.end(), other) - faces_.begin());
        if (g < faces_.size() && kinds_.face_kinds[b_][g] == BoundaryKind::kOuter &&
            !(matched_[b_][Index(x)] & FaceBit(other))) {
          return true;
        }
      }
    }
    return false;
  }
  // The place of face point x on the face (the directions' indices).
  int64_t Slot(const Extents& x) const {
    int64_t s = 0;
    for (auto it = directions_.rbegin(); it != directions_.rend(); ++it) {
      s = s * block_.extent(*it) + x[*it];
    }
    return s;
  }

  // Per slot, whether the point lies on a base: a run of unmatched points along a line of
  // either direction with a solid behind the face at both its contact points.
  std::vector<uint8_t> FindBases(const WallSegments& walls) const {
    int64_t face_points = 1;
    for (int e : directions_) face_points *= block_.extent(e);
    std::vector<uint8_t> base(face_points, 0);
    for (int e : directions_) {
      const int n = block_.extent(e);
      ForEachFacePoint(block_, face_, [&](const Extents& start) {
        if (start[e] != 0) return;  // one line per start point
        auto point = [&](int r) {
          Extents x = start;
          x[e] = r;
          return x;
        };
        for (int r0 = 0; r0 < n;) {
          if (!Unmatched(point(r0))) {
            ++r0;
            continue;
          }
          int r1 = r0;
          while (r1 + 1 < n && Unmatched(point(r1 + 1))) ++r1;
          // The contact points: the matched neighbours of the run, or its own ends at edges.
          const int c0 = r0 > 0 ? r0 - 1 : r0, c1 = r1 + 1 < n ? r1 + 1 : r1;
          if (walls.SolidBehind(At(block_, point(c0)), Inward(point(c0))) &&
              walls.SolidBehind(At(block_, point(c1)), Inward(point(c1)))) {
            for (int r = c0; r <= c1; ++r) base[Slot(point(r))] = 1;
          }
          r0 = r1 + 1;
        }
      });
    }
    return base;
  }

  const StructuredBlock& block_;
  const int b_;
  const std::vector<Face>& faces_;
  const size_t f_;
  const Face& face_;
  const std::vector<std::vector<uint8_t>>& matched_;
  BoundaryKinds& kinds_;
  const std::vector<int> directions_;
};

// Second pass of ClassifyBoundaries for planar and volume blocks: along every grid line of a face
// classified outer by clustering, a run of unmatched points is a wall when a solid lies behind
// the face at both ends of the run (WallSegments::SolidBehind), as at the blunt base of a nozzle
// lip or a thick trailing edge: the run then joins two walls of one solid across the side of the
// face away from the flow. A point is wall when a run along either direction of the face says
// so (on the base of a 3D lip the lines across the base end on the lip's walls, those along the
// span on the side planes); the face is a wall when all its unmatched points are. The clustering
// test misses such bases when the grid is not clustered towards them. Overridden faces are left
// as given. Cost: O(wall points log wall points) to sort the segments, O(log) per run end, and
// O(points) per outer face.
void WallBasesBetweenWalls(const MultiBlockGrid& grid, std::span<const FaceKindOverride> overrides,
                           const std::vector<std::vector<uint8_t>>& matched, BoundaryKinds& kinds) {
  WallSegments walls = CollectWallSegments(grid, kinds);
  if (walls.empty()) return;
  walls.Sort();
  for (int b = 0; b < static_cast<int>(grid.blocks.size()); ++b) {
    const StructuredBlock& block = grid.blocks[b];
    if (!HasSolidFaces(block)) continue;
    const std::vector<Face> faces = BlockFaces(block, b);
    for (size_t f = 0; f < faces.size(); ++f) {
      const Face& face = faces[f];
      const bool overridden =
          std::any_of(overrides.begin(), overrides.end(),
                      [&](const FaceKindOverride& o) { return o.face == face; });
      if (overridden || kinds.face_kinds[b][f] != BoundaryKind::kOuter) continue;
      FaceBaseScan(block, b, faces, f, matched, kinds).Run(walls);
    }
  }
}

// INVALID_ARGUMENT for an override naming a face that `grid` does not have.
absl::Status CheckOverrides(const MultiBlockGrid& grid,
                            std::span<const FaceKindOverride> overrides) {
  const int num_blocks = static_cast<int>(grid.blocks.size());
  for (const FaceKindOverride& o : overrides) {
    if (o.face.block < 0 || o.face.block >= num_blocks || o.face.normal < 0 || o.face.normal > 2 ||
        grid.blocks[o.face.block].extent(o.face.normal) == 1) {
      return absl::InvalidArgumentError(absl::StrCat(
          "face kind override: block ", o.face.block, " face ",
          o.face.normal >= 0 && o.face.normal <= 2 ? FaceName(o.face) : "?", " does not exist"));
    }
  }
  return absl::OkStatus();
}

// Marks the matched points interface in `kinds` and returns, per point, a bit per face
// (FaceBit) on which a match covers it: a point at the end of a match (a corner, an edge of a
// volume face) also lies on the neighbouring face, whose kind it still carries.
std::vector<std::vector<uint8_t>> MarkMatched(const MultiBlockGrid& grid,
                                              const Connectivity& connectivity,
                                              BoundaryKinds& kinds) {
  const int num_blocks = static_cast<int>(grid.blocks.size());
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
  return matched;
}

// The kind of every face of block b (surface blocks: wall; else by clustering, or as
// overridden), given to the face's points that are unmatched on it or border one.
void ClassifyFaces(const StructuredBlock& block, int b, std::span<const FaceKindOverride> overrides,
                   const BoundaryKindOptions& options,
                   const std::vector<std::vector<uint8_t>>& matched, BoundaryKinds& kinds) {
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
  SG_RETURN_IF_ERROR(CheckOverrides(grid, overrides));
  const int num_blocks = static_cast<int>(grid.blocks.size());
  BoundaryKinds kinds;
  kinds.point_kinds.resize(num_blocks);
  kinds.face_kinds.resize(num_blocks);
  // Matched points first: they are interface whatever their face is.
  const std::vector<std::vector<uint8_t>> matched = MarkMatched(grid, connectivity, kinds);
  for (int b = 0; b < num_blocks; ++b) {
    ClassifyFaces(grid.blocks[b], b, overrides, options, matched, kinds);
  }
  WallBasesBetweenWalls(grid, overrides, matched, kinds);
  return kinds;
}

absl::Status BoundaryTolerances::Validate() const {
  const std::pair<const char*, double> fields[] = {
      {"wall", wall}, {"interface", interface}, {"outer", outer}};
  for (const auto& [name, value] : fields) {
    if (!(value > 0.0) || !std::isfinite(value)) {
      return absl::InvalidArgumentError(absl::StrCat("boundary_tolerances.", name, " = ", value,
                                                     "; tolerances must be positive and finite"));
    }
  }
  if (!(interior > 0.0)) {
    return absl::InvalidArgumentError(absl::StrCat("boundary_tolerances.interior = ", interior,
                                                   "; must be positive (or infinite)"));
  }
  if (!(edge >= 0.0 && edge <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("boundary_tolerances.edge = ", edge, " is outside [0, 1]"));
  }
  if (!(first_layer >= 0.0 && first_layer <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("boundary_tolerances.first_layer = ", first_layer, " is outside [0, 1]"));
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

std::vector<double> PointEdgeTolerances(const StructuredBlock& block, const BoundaryKinds& kinds,
                                        int b, const BoundaryTolerances& tolerances) {
  const std::vector<uint8_t>& point_kinds = kinds.point_kinds[b];
  std::vector<double> tol(point_kinds.size(), tolerances.edge);
  if (!(tolerances.first_layer > 0.0)) return tol;
  const double tight = tolerances.edge > 0.0 ? std::min(tolerances.edge, tolerances.first_layer)
                                             : tolerances.first_layer;
  ForEachFirstLayerEdge(block, point_kinds, [&](int64_t p, int64_t q) { tol[p] = tol[q] = tight; });
  return tol;
}

}  // namespace splinegrid
