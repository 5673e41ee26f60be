// The algebraic O-grid of a profile, the grid of the transfinite and elliptic methods: the
// transfinite interpolation of transfinite.h between the wall and an outer circle, or, where
// that folds, the same interpolation from an offset layer past the profile's coves.
//
// Why: the interpolated lines leave the wall along its normals and bend off straight by at
// most orthogonal_reach. In a cove deeper than that (the slat's and the main element's of a
// high-lift airfoil) the normals converge on the cove's centre of curvature, the lines cross,
// and no choice of the bump can stop it: the lines need to leave the wall orthogonally and
// spread out of the cove, which straight or bent lines from fixed wall points cannot do. The
// offsets of offset_march.h fill a cove instead (concave_fill.h). So, the paper's Gordon
// completion from offset curves:
//  1. the transfinite grid from the wall; if no cell folds, that is the grid (k = 0);
//  2. else the offsets are marched with the same layer heights, and the grid is their layers
//     0 .. k, then the interpolation from layer k to the outer circle, each line leaving layer k
//     along its last marched step (so it goes on without a kink) at the heights d_k .. d_N of
//     the same stack, for the fewest k at which no cell of the interpolated part folds. The scan
//     builds each candidate's rows k .. N, O(points) each. The circle (the same circle) takes
//     its points at the angles of layer k's arc length whatever `spacing` says: the offsets
//     have already evened out the wall's clustering that kEven avoids, and an evenly spaced
//     circle against layer k's spacing (which still changes 6:1 from one segment to the next
//     beside the slat's cove) made the elliptic solution fold there.
// A cell folds here if its signed area is not positive, as MeasureOGrid counts it.
#ifndef SPLINEGRID_CORE_GENERATE_COVE_COMPLETION_H_
#define SPLINEGRID_CORE_GENERATE_COVE_COMPLETION_H_

#include "absl/status/statusor.h"
#include "core/generate/transfinite.h"
#include "core/generate/wall_loop.h"
#include "core/grid/structured_grid.h"
#include "core/util/cancellation.h"

namespace splinegrid {

struct AlgebraicGrid {
  StructuredBlock block;   // as TransfiniteGrid's: clockwise, the first line repeated
  int marched_layers = 0;  // k: layers 0 .. k are offsets (0: the transfinite grid)
};

// The grid of the file comment between `wall` and its EnclosingCircle at completion.distance,
// the transfinite grid's circle points spaced as `spacing` says (OuterCircle).
// Errors: as TransfiniteGrid and MarchOffsets (the offsets' FAILED_PRECONDITION naming the
// layer); FAILED_PRECONDITION if the interpolation folds from every marched layer; CANCELLED.
absl::StatusOr<AlgebraicGrid> AlgebraicOGrid(const WallLoop& wall, OuterSpacing spacing,
                                             const CompletionOptions& completion,
                                             const CancelCheck& cancel);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GENERATE_COVE_COMPLETION_H_
