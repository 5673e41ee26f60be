// What each boundary point of a multi-block grid is: wall, interface or outer boundary.
//
// Fitting tolerances differ by kind (the QUADFLOW paper held 0.15e-3 chord on the wing, 2e-3 on
// common block edges and 8e-3 on outer edges). Kinds come from, in order of precedence:
//  1. explicit per-face kinds given by the user (FaceKindOverride);
//  2. the connectivity: points of a face range that matches another face are interface;
//  3. the geometry: a surface block in 3D is a body surface, so all its points are wall; a face
//     of a planar or volume block is a wall when the grid is clustered towards it (its first
//     layer's median spacing is below `wall_spacing_ratio` times the median spacing of that
//     direction in the block), otherwise an outer boundary.
// Points on several faces (corners, edges) carry every kind that applies, and so do the points
// at the border of a match on a face (the end of a C-grid's wake cut is also the first point of
// its airfoil).
#ifndef SPLINEGRID_CORE_GRID_BOUNDARY_KINDS_H_
#define SPLINEGRID_CORE_GRID_BOUNDARY_KINDS_H_

#include <cstdint>
#include <limits>
#include <span>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "core/grid/connectivity.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

enum class BoundaryKind : uint8_t {
  kWall = 1,
  kInterface = 2,
  kOuter = 4,
};

// "wall", "interface", "outer".
std::string_view BoundaryKindName(BoundaryKind kind);

// An explicit kind for the points of a face that no match makes interface.
struct FaceKindOverride {
  Face face;
  BoundaryKind kind = BoundaryKind::kWall;
};

struct BoundaryKindOptions {
  double wall_spacing_ratio = 0.05;
};

// Per block, per point (point order): a bit mask of BoundaryKind values; 0 = interior.
struct BoundaryKinds {
  std::vector<std::vector<uint8_t>> point_kinds;
  // Per block, per face (BlockFaces order): the kind given to its unmatched points.
  std::vector<std::vector<BoundaryKind>> face_kinds;
};

// Classifies every boundary point of `grid`: matched points are interface; a face's other
// points are wall when the grid clusters towards the face (first spacing below
// wall_spacing_ratio times the block's median spacing in that direction), else outer; an
// override sets a face's kind. Then, in planar and volume blocks, a run of unmatched points
// along a grid line of an outer face (not overridden) becomes wall when a solid lies behind the
// face at both ends of the run: a wall that meets the run's end point leaves it on the side of
// the face away from the block's interior. That is a blunt base (a nozzle lip, a thick trailing
// edge, in 2D or across the span in 3D) joining two walls of one solid, which the clustering
// test misses when the grid is not clustered towards it; an inlet between two walls (the walls
// run along the block) and a far field stay outer; a face all of whose unmatched points are on
// such runs is a wall face. Errors:
// INVALID_ARGUMENT for an override naming a block or face that does not exist.
absl::StatusOr<BoundaryKinds> ClassifyBoundaries(const MultiBlockGrid& grid,
                                                 const Connectivity& connectivity,
                                                 std::span<const FaceKindOverride> overrides = {},
                                                 const BoundaryKindOptions& options = {});

// Tolerance of each kind, in the grid's length unit; `interior` applies to points on no boundary
// (infinity: none). `edge` bounds the error of every grid edge vector relative to the edge's
// length (refinement.h, AssessErrors): it keeps the spacing and shape of cells inside blocks,
// where the paper binds no absolute tolerance; 0 switches it off. An edge within half its length
// keeps almost every cell within the factor 2 the cell-quality check allows (grid_quality.h),
// which catches the rest; 0.25 gave the same quality on the shared C-grids at 30-40% less
// compression.
struct BoundaryTolerances {
  double wall = 0.15e-3;
  double interface = 2e-3;
  double outer = 8e-3;
  double interior = std::numeric_limits<double>::infinity();
  double edge = 0.5;
  // The first layer at the walls, whose height a solver's y+ follows: the edge criterion above
  // with this relative accuracy on the first-layer edges (ForEachFirstLayerEdge below) and,
  // since an edge's limit is the looser of its ends', on the edges among their ends: along the
  // wall and along the first layer. 0: off, those edges have `edge` like the rest. Held, it
  // bounds the relative change of every first-layer height (fit_deviation.h first_layer), but
  // not at poles, where the fit switches the edge criterion off to keep them collapsed.
  double first_layer = 0.0;

  // INVALID_ARGUMENT naming the field: wall, interface and outer must be positive and finite,
  // interior positive (infinity allowed), edge and first_layer in [0, 1].
  absl::Status Validate() const;
  // The tightest tolerance of the kinds in `mask` (interior for 0).
  double For(uint8_t mask) const;
};

// Per-point tolerances of block b.
std::vector<double> PointTolerances(const BoundaryKinds& kinds, int b,
                                    const BoundaryTolerances& tolerances);

// The first-layer edges of `block` (its points' kinds `point_kinds`): from every wall point on a
// face of the block to its neighbour one step inward across that face, unless that neighbour
// is a wall point too (a block two points thick between walls). Their lengths are the heights
// a solver's y+ follows; the inner end may lie on another boundary (an O-grid's seam, an
// interface to the next block). Calls visit(p, q) with the point indices of wall point and
// neighbour; an edge from a point on two faces is visited for each.
template <typename Visit>
void ForEachFirstLayerEdge(const StructuredBlock& block, const std::vector<uint8_t>& point_kinds,
                           Visit visit) {
  const uint8_t wall = static_cast<uint8_t>(BoundaryKind::kWall);
  for (int k = 0; k < block.extent(2); ++k) {
    for (int j = 0; j < block.extent(1); ++j) {
      for (int i = 0; i < block.extent(0); ++i) {
        const int64_t p = block.Index(i, j, k);
        if (!(point_kinds[p] & wall)) continue;
        const Extents at = {i, j, k};
        for (int d = 0; d < 3; ++d) {
          const int n = block.extent(d);
          if (n < 2) continue;
          for (const int face : {0, n - 1}) {
            if (at[d] != face) continue;
            Extents in = at;
            in[d] += face == 0 ? 1 : -1;
            const int64_t q = block.Index(in[0], in[1], in[2]);
            if (!(point_kinds[q] & wall)) visit(p, q);
          }
        }
      }
    }
  }
}

// The first-layer edges a fit holds: those of ForEachFirstLayerEdge with neither end on a pole
// (`on_pole`, per point, poles.h PointsOnPoles; empty: no pole), where the fit switches the
// edge criterion off to keep the pole collapsed.
template <typename Visit>
void ForEachHeldFirstLayerEdge(const StructuredBlock& block,
                               const std::vector<uint8_t>& point_kinds,
                               std::span<const uint8_t> on_pole, Visit visit) {
  ForEachFirstLayerEdge(block, point_kinds, [&](int64_t p, int64_t q) {
    if (on_pole.empty() || !(on_pole[p] || on_pole[q])) visit(p, q);
  });
}

// Per-point edge tolerances of `block`, block b of `kinds`: `edge` everywhere, and
// first_layer (where it is tighter, or `edge` is off) at both ends of the first-layer edges;
// refinement tightens them locally.
std::vector<double> PointEdgeTolerances(const StructuredBlock& block, const BoundaryKinds& kinds,
                                        int b, const BoundaryTolerances& tolerances);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GRID_BOUNDARY_KINDS_H_
