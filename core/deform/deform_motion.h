// How a boundary moves, in the three forms a Deformer applies: a rigid motion, displacements of
// some boundary controls (named by block and control index, as a client sends them), or new
// positions of boundary points.
#ifndef SPLINEGRID_CORE_DEFORM_DEFORM_MOTION_H_
#define SPLINEGRID_CORE_DEFORM_DEFORM_MOTION_H_

#include <cstdint>
#include <span>
#include <variant>
#include <vector>

#include "absl/status/statusor.h"
#include "core/deform/deformer.h"
#include "core/deform/rigid_motion.h"

namespace splinegrid {

// Displacements of some controls of one block: control controls[q] (its index in the block's
// control order) moves by values[s q .. s q + s), s the spatial dimension.
struct BlockControlDisplacements {
  int block = 0;
  std::vector<int64_t> controls;
  std::vector<double> values;
};

// One of the three motions.
using DeformMotion =
    std::variant<RigidMotion, std::vector<BlockControlDisplacements>, std::vector<BoundaryPoints>>;

// The grid `deformer` makes of `motion` (Rigid, DisplaceControls or MoveBoundaryPoints).
absl::StatusOr<std::vector<FittedBlock>> ApplyMotion(const Deformer& deformer,
                                                     const DeformMotion& motion);

// `given` in the order Deformer::DisplaceControls takes (deformer.moved_controls(); controls not
// given stay). INVALID_ARGUMENT naming blocks[e] for a block outside the grid, a count of values
// that does not match the controls, a control that does not carry the moved boundary, or a
// non-finite value.
absl::StatusOr<std::vector<double>> DisplacementsInDeformerOrder(
    const Deformer& deformer, std::span<const BlockControlDisplacements> given);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_DEFORM_DEFORM_MOTION_H_
