// The tolerance mode of FitGrid (grid_fit.h), internal: a watertight fit of a multi-block grid
// to tolerances by boundary kind, with valid cells. Its settings are GridFitOptions' (validated
// by FitGrid); the adaptive engine's are built from them once, here.
//
//  1. Connectivity: which face ranges of the blocks coincide (connectivity.h).
//  2. Boundary kinds and per-point tolerances: wall, interface, outer, interior
//     (boundary_kinds.h; defaults are the QUADFLOW paper's 0.15e-3, 2e-3, 8e-3 in the grid's
//     unit, and 8e-3 inside).
//  3. A SegmentModel: matched segments share parameters and knots (segment_model.h).
//  4. Knot refinement until every point is within its tolerance; then every block is evaluated
//     at the original resolution and at refinement levels 1 and 2, and where a cell folds or
//     changes its size by more than `quality.max_size_ratio`, the tolerance around it is halved
//     and refinement resumes ("refine locally"); then unnecessary knots are removed
//     (adaptive_engine.h).
//  5. Watertightness: the boundary control points of every matched face range are made
//     bitwise identical in all blocks that share them (they are the same fit up to rounding).
//     Poles (edges collapsed to a point, faces collapsed to a line or point: poles.h) are no
//     match and no segment boundary; every line of controls along a pole's collapsed direction
//     is given one value (the constrained least-squares fit: multiblock_fit.cc), shared by all
//     blocks that meet there, so the pole stays exactly collapsed at every resolution.
#ifndef SPLINEGRID_CORE_FIT_ADAPTIVE_MULTIBLOCK_FIT_H_
#define SPLINEGRID_CORE_FIT_ADAPTIVE_MULTIBLOCK_FIT_H_

#include <vector>

#include "absl/status/statusor.h"
#include "core/fit/grid_fit.h"
#include "core/grid/poles.h"

namespace splinegrid::internal {

// The tolerance mode's result: the fit, and what it leaves besides.
struct MultiBlockRun {
  // Its blocks (each with its deviation by kind, cell quality and whether its tolerances are
  // met), connectivity, kinds and every report field but those FitGrid adds (num_matches,
  // reference, adjustments, seconds).
  GridFit fit;
  // Faired to tolerance: the same knots without fairing, to compare (else empty).
  std::vector<FittedBlock> unfaired;
  // Block boundaries collapsed to a point or a line (poles.h); every line of controls along a
  // pole's collapsed direction holds one control point, bitwise, in every block.
  std::vector<Pole> poles;
};

// Fits `grid`, whose `connectivity` is FindConnectivity's and `kinds` ClassifyBoundaries' (with
// options.face_kinds), to `tolerances` (in the grid's unit) with `options` (valid for `grid`:
// GridFitOptions::Validate). Not meeting a tolerance is reported, not an error. Errors:
// INVALID_ARGUMENT for a first_layer to hold on a grid with no first-layer edge off a pole;
// FAILED_PRECONDITION for blocks that touch inconsistently (naming the match), CANCELLED.
absl::StatusOr<MultiBlockRun> FitMultiBlock(
    const MultiBlockGrid& grid, const Connectivity& connectivity, const BoundaryKinds& kinds,
    const GridFitOptions& options, const BoundaryTolerances& tolerances, const CancelCheck& cancel);

}  // namespace splinegrid::internal

#endif  // SPLINEGRID_CORE_FIT_ADAPTIVE_MULTIBLOCK_FIT_H_
