// The 2D view of a 2D grid stored as two planes, as CFL3D and other 3D solvers store 2D cases.
//
// A two-plane block is a 3D block (spatial_dim 3) with extent 2 in one index direction d whose
// two planes (index 0 and 1 along d) hold the same points except for one coordinate c, which is
// constant on each plane and differs between them: e.g. rae2822_257x97.fmt is 2 x 257 x 97 with
// y = 0 on plane i = 0 and y = -1 on plane i = 1. "Same" and "constant" are judged with the
// absolute tolerance  tol = relative_tolerance * (diagonal of the block's bounding box),  and the
// two plane values must differ by more than tol. The planar view of such a block is the 2D block
// (spatial_dim 2) of plane 0 with the other two coordinates in their order (x, z for c = y) and
// extents (n_a, n_b, 1), a < b the remaining index directions. Cost: O(points), no allocation
// except the result.
#ifndef SPLINEGRID_CORE_IO_PLANAR_VIEW_H_
#define SPLINEGRID_CORE_IO_PLANAR_VIEW_H_

#include <vector>

#include "absl/status/statusor.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

// How two-plane blocks are recognized.
struct PlanarViewOptions {
  // Tolerance relative to the block's bounding-box diagonal (dimensionless, see file comment).
  double relative_tolerance = 1e-8;
};

// How a two-plane block is laid out.
struct TwoPlaneLayout {
  int plane_direction = 0;          // index direction with the two planes (0 = i, 1 = j, 2 = k)
  int normal_coordinate = 1;        // coordinate constant on each plane (0 = x, 1 = y, 2 = z)
  double plane_values[2] = {0, 0};  // that coordinate on plane 0 and plane 1
};

// The layout of `block` if it is a two-plane block; otherwise INVALID_ARGUMENT saying why
// (no direction with extent 2, planes differ in an in-plane coordinate at a named point, ...).
// When several directions have extent 2 the first that works is taken.
absl::StatusOr<TwoPlaneLayout> DetectTwoPlaneBlock(const StructuredBlock& block,
                                                   const PlanarViewOptions& options = {});

// Whether `block` is a two-plane block. O(points), no allocation.
bool IsTwoPlaneBlock(const StructuredBlock& block, const PlanarViewOptions& options = {});

// Whether `grid` has blocks and every one is a two-plane block. O(points), no allocation.
bool IsTwoPlaneGrid(const MultiBlockGrid& grid, const PlanarViewOptions& options = {});

// The planar view of two-plane `block` (see file comment); its iblank is plane 0's.
absl::StatusOr<StructuredBlock> PlanarBlock(const StructuredBlock& block,
                                            const PlanarViewOptions& options = {});

// The planar view of every block of `grid`; INVALID_ARGUMENT naming the first block that is not
// a two-plane block (and why).
absl::StatusOr<MultiBlockGrid> PlanarView(const MultiBlockGrid& grid,
                                          const PlanarViewOptions& options = {});
// The same, with every block's layout in `*layouts` (one per block, in block order), which
// TwoPlaneBlock needs to restore the file's 3D form.
absl::StatusOr<MultiBlockGrid> PlanarView(const MultiBlockGrid& grid,
                                          const PlanarViewOptions& options,
                                          std::vector<TwoPlaneLayout>* layouts);

// The inverse of PlanarBlock: the 3D block with extent 2 along layout.plane_direction whose
// plane p holds the points of 2D `planar` (extents (n_a, n_b, 1), any resolution) with the
// normal coordinate set to layout.plane_values[p]; iblank, when present, on both planes.
// INVALID_ARGUMENT when `planar` is not 2D with nk = 1 or the layout's indices are out of range.
// Writing an evaluated planar grid back as the two-plane file it came from uses this.
absl::StatusOr<StructuredBlock> TwoPlaneBlock(const StructuredBlock& planar,
                                              const TwoPlaneLayout& layout);

// The 2D grid of `grid` whether stored in 2D or as two planes: blocks with spatial_dim 2 are
// copied unchanged, 3D blocks must be two-plane blocks and are replaced by their planar view.
absl::StatusOr<MultiBlockGrid> AsPlanarGrid(const MultiBlockGrid& grid,
                                            const PlanarViewOptions& options = {});

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_IO_PLANAR_VIEW_H_
