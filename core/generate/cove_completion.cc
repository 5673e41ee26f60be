#include "core/generate/cove_completion.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/generate/loop_geometry.h"
#include "core/generate/offset_march.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

// Whether every cell of rows from .. nj - 2 of the clockwise O-grid `g` has a positive signed
// area (as MeasureOGrid counts it).
bool PositiveFrom(const StructuredBlock& g, int from) {
  for (int j = from; j + 1 < g.extent(1); ++j) {
    for (int i = 0; i + 1 < g.extent(0); ++i) {
      if (!(SignedCellArea(g, i, j) > 0.0)) return false;
    }
  }
  return true;
}

}  // namespace

absl::StatusOr<AlgebraicGrid> AlgebraicOGrid(const WallLoop& wall, OuterSpacing spacing,
                                             const CompletionOptions& completion,
                                             const CancelCheck& cancel) {
  const Circle circle = EnclosingCircle(wall.points, completion.distance);
  AlgebraicGrid out;
  SG_ASSIGN_OR_RETURN(
      out.block, TransfiniteGrid(wall, PointsOnCircle(circle, wall.points, spacing), completion));
  if (PositiveFrom(out.block, 0)) return out;

  OffsetOptions offsets;
  offsets.layers = completion.layers;
  offsets.first_height = completion.first_height;
  offsets.distance = completion.distance;
  offsets.cancel = cancel;
  SG_ASSIGN_OR_RETURN(const OffsetGrid marched, MarchOffsets(wall, offsets));
  const std::vector<double> heights = LayerHeights(completion);
  const int n = marched.block.extent(0);
  StructuredBlock& grid = out.block;
  std::copy(marched.block.coords().begin(), marched.block.coords().end(), grid.coords().begin());
  std::vector<Point2> inner(n), directions(n);
  for (int k = 1; k < completion.layers; ++k) {
    SG_RETURN_IF_ERROR(PollCancel(cancel));
    for (int i = 0; i < n; ++i) {
      const double* p = marched.block.Point(i, k, 0);
      const double* below = marched.block.Point(i, k - 1, 0);
      const double length = std::hypot(p[0] - below[0], p[1] - below[1]);
      inner[i] = {p[0], p[1]};
      directions[i] = {(p[0] - below[0]) / length, (p[1] - below[1]) / length};
    }
    InterpolateLines(inner, directions, PointsOnCircle(circle, inner, OuterSpacing::kFollowWall),
                     heights, completion, k, grid);
    // Row k - 1 .. k is the offsets' own (valid) cell row; the rest is interpolated.
    if (PositiveFrom(grid, k)) {
      out.marched_layers = k;
      return out;
    }
    // The next candidate's row k is the offsets' again.
    for (int i = 0; i < n; ++i) {
      std::copy_n(marched.block.Point(i, k + 1, 0), 2, grid.Point(i, k + 1, 0));
    }
  }
  return absl::FailedPreconditionError(
      absl::StrCat("the transfinite lines fold from the wall and from every one of the ",
                   completion.layers, " offset layers; use the offsets method"));
}

}  // namespace splinegrid
