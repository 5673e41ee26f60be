// Which control points of a fitted grid carry which part of its boundary, for deformation.
//
// The boundary of a planar block or a volume block is its faces; a surface block in 3D (a wall
// patch such as a wing's) is a boundary itself. A face of a tensor-product spline is a spline of
// the face's own controls (normal index 0 or n - 1) with the face's knots, so the part of the
// face over some grid cells is a combination of exactly those face controls whose supports
// overlap those cells. Boundary points mark face cells (neighbouring face points that are all
// marked: a segment on an edge, a quadrilateral on a face), and a control takes the role of the
// cells its support overlaps with positive measure, in parameter space:
//  - moved: it overlaps a cell of moved points; moving these controls rigidly moves that part of
//    the boundary exactly (B-splines are affine invariant) and nothing else of it, except across
//    the end of a moved range where no break separates it from its neighbour: there the
//    neighbouring span moves too (a free boundary, such as a wake cut, follows smoothly);
//  - fixed: it overlaps a cell of fixed points (outer boundaries, walls that do not move) and no
//    moved one: fixed boundaries stay exactly where they are;
//  - free: everything else (interfaces between blocks, a C-grid's wake cut, the interior): the
//    deformation moves them smoothly.
#ifndef SPLINEGRID_CORE_DEFORM_BOUNDARY_CONTROLS_H_
#define SPLINEGRID_CORE_DEFORM_BOUNDARY_CONTROLS_H_

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/grid/boundary_kinds.h"
#include "core/grid/connectivity.h"

namespace splinegrid {

enum class ControlRole : uint8_t { kFree = 0, kFixed = 1, kMoved = 2 };

// The boundary points that move: every point of the kinds in `kinds` (a BoundaryKind mask),
// or, when `ranges` is not empty, the points of those face ranges. A range whose normal is a
// direction of one point (k for a surface block) covers the block itself.
struct BoundarySelection {
  uint8_t kinds = static_cast<uint8_t>(BoundaryKind::kWall);
  std::vector<FaceRange> ranges;
};

// Per block, per point (point order): whether it moves, by `selection` (validated: ranges must
// name existing faces of existing blocks, inside their extents).
absl::StatusOr<std::vector<std::vector<uint8_t>>> SelectedPoints(
    const std::vector<Extents>& extents, const BoundaryKinds& kinds,
    const BoundarySelection& selection);

// Per block, per control point (control order): its role (file comment). Fixed points are the
// outer and wall points that are not selected. `selected` is SelectedPoints' result.
std::vector<std::vector<ControlRole>> ClassifyControls(
    const std::vector<FittedBlock>& blocks, const BoundaryKinds& kinds,
    const std::vector<std::vector<uint8_t>>& selected);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_DEFORM_BOUNDARY_CONTROLS_H_
