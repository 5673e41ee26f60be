// Connectivities of grids made from other grids, derived from theirs by index arithmetic
// instead of found again by geometry (FindConnectivity costs O(boundary points) hashing plus
// growing every match, 50 s on a volume of 15 million points with 1e-6 layers).
#ifndef SPLINEGRID_CORE_GRID_CONNECTIVITY_EDIT_H_
#define SPLINEGRID_CORE_GRID_CONNECTIVITY_EDIT_H_

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

// OK when every match of `connectivity` lies inside `grid`'s blocks and its points coincide
// within `tolerance` (in the grid's unit); INVALID_ARGUMENT naming the match otherwise.
absl::Status CheckConnectivity(const MultiBlockGrid& grid, const Connectivity& connectivity,
                               double tolerance);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GRID_CONNECTIVITY_EDIT_H_
