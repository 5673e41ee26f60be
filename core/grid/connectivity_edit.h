// Working with a connectivity by index arithmetic: its matched point pairs, checks that a given
// connectivity holds for a grid, and the connectivities of grids made from other grids derived
// from theirs instead of found again by geometry (FindConnectivity costs O(boundary points)
// hashing plus growing every match, 50 s on a volume of 15 million points with 1e-6 layers).
#ifndef SPLINEGRID_CORE_GRID_CONNECTIVITY_EDIT_H_
#define SPLINEGRID_CORE_GRID_CONNECTIVITY_EDIT_H_

#include <string>

#include "absl/status/status.h"
#include "core/grid/connectivity.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

// The connectivity of volume blocks ni x nj x (layers + 1) extruded from surface blocks
// ni x nj x 1 whose matches are `surface`'s: every match gains k in [0, layers] on both sides,
// k running along k. Precondition: the matches are of surface blocks (k = 0 only).
Connectivity Extruded(const Connectivity& surface, int layers);

// Renumbers `connectivity` for block `block` (of `extents`) with its direction `direction`
// reversed (index x -> n - 1 - x): its faces across that direction swap, its ranges along it
// flip, and the orientation of every match along it turns.
void ReverseBlockDirection(Connectivity& connectivity, int block, int direction,
                           const Extents& extents);

// Calls f(x, y) for every point x of `match`'s range a with the point y of range b it coincides
// with (BoundaryMatch::MapToB).
template <typename F>
void ForEachMatchedPoint(const BoundaryMatch& match, F f) {
  const Extents& lo = match.a.begin;
  const Extents& hi = match.a.end;
  for (int k = lo[2]; k <= hi[2]; ++k) {
    for (int j = lo[1]; j <= hi[1]; ++j) {
      for (int i = lo[0]; i <= hi[0]; ++i) f(Extents{i, j, k}, match.MapToB({i, j, k}));
    }
  }
}

// OK when both ranges of `match` lie inside their blocks of `grid`; INVALID_ARGUMENT naming
// the match ("... does not fit " + `what`, e.g. "the grid") otherwise: a connectivity of
// another grid.
absl::Status CheckMatchFits(const MultiBlockGrid& grid, const BoundaryMatch& match,
                            const std::string& what);

// OK when every match of `connectivity` lies inside `grid`'s blocks and its points coincide
// within `tolerance` (in the grid's unit); INVALID_ARGUMENT naming the match otherwise.
absl::Status CheckConnectivity(const MultiBlockGrid& grid, const Connectivity& connectivity,
                               double tolerance);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GRID_CONNECTIVITY_EDIT_H_
