// A multi-block grid checked once for fitting.
#ifndef SPLINEGRID_CORE_GRID_FITTABLE_GRID_H_
#define SPLINEGRID_CORE_GRID_FITTABLE_GRID_H_

#include "absl/status/statusor.h"
#include "core/grid/connectivity.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

// A grid whose every block passed ValidateFittable (finite points, not collapsed to a point or
// along a direction, cells of positive measure), with its block-to-block connectivity
// (FindConnectivity). Both are O(points) passes; FitGrid on a FittableGrid does neither, so a
// caller that fits one grid many times (the service keeps one per imported grid) checks it
// once. Immutable once checked.
class FittableGrid {
 public:
  // No blocks; FitGrid refuses it.
  FittableGrid() = default;

  // Checks every block of `grid` and finds its connectivity (polling `cancel`). INVALID_ARGUMENT
  // naming the block ("block 2: ...") for one that cannot be fitted or for a grid without
  // blocks; the connectivity's errors; CANCELLED.
  static absl::StatusOr<FittableGrid> Check(MultiBlockGrid grid,
                                            const ConnectivityOptions& options = {},
                                            const CancelCheck& cancel = {});

  // Checks every block of `grid` and takes `connectivity` as its connectivity, each match checked
  // to fit the blocks and its points to coincide within `tolerance` (CheckConnectivity): for a
  // grid made from another whose connectivity is derived (connectivity_edit.h), where finding
  // it again would cost far more. INVALID_ARGUMENT as Check and for a match that does not hold.
  static absl::StatusOr<FittableGrid> CheckWithConnectivity(MultiBlockGrid grid,
                                                            Connectivity connectivity,
                                                            double tolerance);

  const MultiBlockGrid& grid() const { return grid_; }
  const Connectivity& connectivity() const { return connectivity_; }

 private:
  MultiBlockGrid grid_;
  Connectivity connectivity_;
};

// ValidateFittable of every block, naming it ("block 2: ..."): the first error.
absl::Status ValidateFittableBlocks(const MultiBlockGrid& grid);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GRID_FITTABLE_GRID_H_
