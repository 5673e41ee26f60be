// Derived fields of an evaluated block for visual inspection in ParaView: the Jacobian of the
// spline mapping at every point and a cell quality (the scaled Jacobian).
#ifndef SPLINEGRID_CORE_IO_VTK_FIELDS_H_
#define SPLINEGRID_CORE_IO_VTK_FIELDS_H_

#include <span>
#include <vector>

#include "absl/status/statusor.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

// The Jacobian determinant of the mapping (u, v[, w]) -> X at every point of `block`, from the
// analytic first derivatives du, dv, dw (same layout as block.coords()):
//   parametric_dim 3 (volume): det[X_u X_v X_w];
//   parametric_dim 2: X_u x X_v (its z component, signed) for 2D points; |X_u x X_v| (the area
//   element, unsigned: a surface has no inside) for surfaces in 3D;
//   parametric_dim 1 (curve): |X_u| (the arc-length element).
// Units: length^parametric_dim per unit parameter^parametric_dim. INVALID_ARGUMENT when a
// needed derivative array has the wrong size or parametric_dim is not 1 to 3 (or 3 with 2D
// points). O(points).
absl::StatusOr<std::vector<double>> JacobianField(const StructuredBlock& block,
                                                  std::span<const double> du,
                                                  std::span<const double> dv,
                                                  std::span<const double> dw, int parametric_dim);

// The scaled Jacobian of every cell of `block` (VTK cell order, VtkNumCells cells): the minimum
// over the cell's corners of det(edge vectors) / product(edge lengths), with the edges along
// increasing i, j[, k] (Knupp, "Achieving finite element mesh quality via optimization of the
// Jacobian matrix norm", 2000; VTK's verdict "Scaled Jacobian"). Values are in [-1, 1]: 1 for
// a rectangle/box, -> 0 for degenerate cells, < 0 for folded ones, relative to the block's own
// orientation (a left-handed block is not all "folded"); 0 for cells with a collapsed edge.
// Hexahedra for 3D blocks with nk > 1, quadrilaterals otherwise (for surfaces in 3D the
// corner cross products are measured along the cell's normal, the cross product of its
// diagonals). Blocks with fewer than two index directions of extent > 1 (curves) have no
// quality: INVALID_ARGUMENT. O(points).
absl::StatusOr<std::vector<double>> ScaledJacobianCells(const StructuredBlock& block);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_IO_VTK_FIELDS_H_
