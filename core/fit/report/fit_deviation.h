// Two measures of a fitted multi-block grid for its report: the largest deviation from the data
// per boundary kind, and the largest gap between the two sides of every matched boundary.
#ifndef SPLINEGRID_CORE_FIT_REPORT_FIT_DEVIATION_H_
#define SPLINEGRID_CORE_FIT_REPORT_FIT_DEVIATION_H_

#include <cstdint>
#include <span>
#include <vector>

#include "absl/status/statusor.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/grid/connectivity.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

// Largest deviation per boundary kind (negative: the block has no point of that kind).
struct KindDeviation {
  double wall = -1.0;
  double interface = -1.0;
  double outer = -1.0;
  double interior = -1.0;
  // The largest relative change of a first-layer height: over the first-layer edges
  // (boundary_kinds.h ForEachFirstLayerEdge; the heights a solver's y+ follows) that a fit
  // holds, | |fitted edge| - |data edge| | / |data edge| at the data parameters. Negative: the
  // block has no such edge.
  double first_layer = -1.0;
  Extents first_layer_at = {0, 0, 0};  // the wall point of that edge
};

// Largest distance of `fitted` from `block` at the data parameters, per kind of point (`kinds`:
// the block's BoundaryKinds::point_kinds), and the largest change of a first-layer height over
// the first-layer edges with neither end on a pole (`on_pole`, per point; empty: none) and
// longer than `collapsed` (poles.h PoleTolerance): the edges the fit holds (the edge criterion
// is off at poles, multiblock_fit.cc SwitchOffPoleEdges, which keeps them collapsed).
absl::StatusOr<KindDeviation> DeviationByKind(const FittedBlock& fitted,
                                              const StructuredBlock& block,
                                              const std::vector<uint8_t>& kinds,
                                              std::span<const uint8_t> on_pole = {},
                                              double collapsed = 0.0);

// Largest distance between the coinciding points of every match of `connectivity` in `blocks`,
// evaluated at refinement levels 0..max_level (hanging nodes: at the coarse side's points).
double MaxBoundaryGap(const Connectivity& connectivity, const std::vector<FittedBlock>& blocks,
                      int max_level);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_REPORT_FIT_DEVIATION_H_
