// What both GenerateGrid operations (generate.h: around a profile; generate_volume.h: off a
// surface) do with their new grid: check the request's id, name and size before the work, and
// afterwards store the generated blocks as the new grid's source points, fitted as revision 1.
#ifndef SPLINEGRID_SERVER_OPS_GENERATED_GRID_H_
#define SPLINEGRID_SERVER_OPS_GENERATED_GRID_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/fit/grid_fit.h"
#include "core/grid/structured_grid.h"
#include "core/util/cancellation.h"
#include "server/grid_store.h"
#include "server/ops/ops_context.h"

namespace splinegrid::server::ops {

// Who and what the new grid is.
struct NewGridHeader {
  std::string grid_id;  // "": the store picks one
  std::string display_name;
  std::string owner;
};

// The checks that need no work: the id (INVALID_ARGUMENT, ALREADY_EXISTS), the display name's
// length and `points` against the server's cap (OUT_OF_RANGE naming `points_what`, e.g.
// "wall_points * (layers + 1)").
absl::Status CheckNewGrid(const OpsContext& context, const NewGridHeader& header, int64_t points,
                          const std::string& points_what, int64_t max_points);

// The fit of a generated grid's revision 1: `requested`, else `default_fit`; folds allowed when
// either it or `allow_folds` says so; unless it names face kinds, every block's faces across
// direction `outward` (the one leaving the wall) are the wall at index 0 and the outer boundary
// at the last index (other faces: interfaces through the connectivity).
GridFitOptions GeneratedGridFit(const std::optional<GridFitOptions>& requested,
                                GridFitOptions default_fit, bool allow_folds, int num_blocks,
                                int outward);

// Stores `blocks` (whose bytes `source` already holds in the budget, described by `format`) as
// the new grid's source points and fits them as revision 1; `default_name` names the grid when
// the header does not. The grid's connectivity is `connectivity` when given (checked to hold to
// rounding: derived from the generation's, connectivity_edit.h), else found (FindConnectivity).
// FAILED_PRECONDITION when the fit folds (and options.allow_folds is false), ALREADY_EXISTS,
// CANCELLED; nothing is stored on an error.
absl::StatusOr<std::shared_ptr<const StoredGrid>> StoreGenerated(
    const OpsContext& context, const NewGridHeader& header, const std::string& default_name,
    std::shared_ptr<SourcePoints> source, MultiBlockGrid blocks, const GridFitOptions& options,
    const CancelCheck& cancel, std::optional<Connectivity> connectivity = std::nullopt);

}  // namespace splinegrid::server::ops

#endif  // SPLINEGRID_SERVER_OPS_GENERATED_GRID_H_
