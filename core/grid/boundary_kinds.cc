#include "core/grid/boundary_kinds.h"

#include <algorithm>
#include <cmath>

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
