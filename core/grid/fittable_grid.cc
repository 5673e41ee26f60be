#include "core/grid/fittable_grid.h"

#include "absl/strings/str_cat.h"
#include "core/grid/connectivity_edit.h"
#include "core/util/status_macros.h"

namespace splinegrid {

absl::StatusOr<FittableGrid> FittableGrid::Check(MultiBlockGrid grid,
                                                 const ConnectivityOptions& options,
                                                 const CancelCheck& cancel) {
  if (grid.blocks.empty()) return absl::InvalidArgumentError("the grid has no blocks");
  SG_RETURN_IF_ERROR(ValidateFittableBlocks(grid));
  FittableGrid checked;
  SG_ASSIGN_OR_RETURN(checked.connectivity_, FindConnectivity(grid, options, cancel));
  checked.grid_ = std::move(grid);
  return checked;
}

absl::StatusOr<FittableGrid> FittableGrid::CheckWithConnectivity(MultiBlockGrid grid,
                                                                 Connectivity connectivity,
                                                                 double tolerance) {
  if (grid.blocks.empty()) return absl::InvalidArgumentError("the grid has no blocks");
  SG_RETURN_IF_ERROR(ValidateFittableBlocks(grid));
  SG_RETURN_IF_ERROR(CheckConnectivity(grid, connectivity, tolerance));
  FittableGrid checked;
  checked.connectivity_ = std::move(connectivity);
  checked.grid_ = std::move(grid);
  return checked;
}

absl::Status ValidateFittableBlocks(const MultiBlockGrid& grid) {
  for (size_t b = 0; b < grid.blocks.size(); ++b) {
    SG_RETURN_IF_ERROR(ValidateFittable(grid.blocks[b], absl::StrCat("block ", b)));
  }
  return absl::OkStatus();
}

}  // namespace splinegrid
