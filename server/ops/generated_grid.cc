#include "server/ops/generated_grid.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "core/grid/structured_grid.h"
#include "core/util/status_macros.h"
#include "server/grid_id.h"
#include "server/ops/fit.h"

namespace splinegrid::server::ops {
namespace {

// 1e-12 of the largest coordinate: what a derived connectivity's points may differ by.
double RoundingTolerance(const MultiBlockGrid& grid) { return 1e-12 * LargestCoordinate(grid); }

}  // namespace

absl::Status CheckNewGrid(const OpsContext& context, const NewGridHeader& header, int64_t points,
                          const std::string& points_what, int64_t max_points) {
  const std::string& id = header.grid_id;
  SG_RETURN_IF_ERROR(CheckRequestedGridId(id, "grid_id"));
  if (header.display_name.size() > 1024) {
    return absl::InvalidArgumentError("display_name is longer than 1024 bytes");
  }
  if (!id.empty() && context.store.Get(id).ok()) {  // fail early; Create decides in the end
    return absl::AlreadyExistsError(absl::StrCat("grids/", id, " already exists"));
  }
  if (points > max_points) {
    return absl::OutOfRangeError(absl::StrCat(points_what, " = ", points,
                                              " points, more than the server's cap of ", max_points,
                                              " (flag --max_output_points)"));
  }
  return absl::OkStatus();
}

GridFitOptions GeneratedGridFit(const std::optional<GridFitOptions>& requested,
                                GridFitOptions default_fit, bool allow_folds, int num_blocks,
                                int outward) {
  GridFitOptions options = requested.value_or(std::move(default_fit));
  options.allow_folds = options.allow_folds || allow_folds;
  if (options.face_kinds.empty()) {
    for (int b = 0; b < num_blocks; ++b) {
      options.face_kinds.push_back({Face{b, outward, false}, BoundaryKind::kWall});
      options.face_kinds.push_back({Face{b, outward, true}, BoundaryKind::kOuter});
    }
  }
  return options;
}

absl::StatusOr<std::shared_ptr<const StoredGrid>> StoreGenerated(
    const OpsContext& context, const NewGridHeader& header, const std::string& default_name,
    std::shared_ptr<SourcePoints> source, MultiBlockGrid blocks, const GridFitOptions& options,
    const CancelCheck& cancel, std::optional<Connectivity> connectivity) {
  if (connectivity.has_value()) {
    const double tolerance = RoundingTolerance(blocks);
    SG_ASSIGN_OR_RETURN(source->checked,
                        FittableGrid::CheckWithConnectivity(std::move(blocks),
                                                            *std::move(connectivity), tolerance));
  } else {
    SG_ASSIGN_OR_RETURN(source->checked, FittableGrid::Check(std::move(blocks), {}, cancel));
  }
  SG_ASSIGN_OR_RETURN(GridRevision revision,
                      FitRevision(context, *source, options, RevisionOrigin::kFit, 0, cancel));
  revision.number = 1;
  auto grid = std::make_shared<StoredGrid>();
  grid->display_name = header.display_name.empty() ? default_name : header.display_name;
  grid->owner = header.owner;
  grid->create_time = absl::Now();
  grid->source = std::move(source);
  grid->revisions.push_back(std::make_shared<const GridRevision>(std::move(revision)));
  SG_RETURN_IF_ERROR(PollCancel(cancel));
  SG_RETURN_IF_ERROR(CreateGrid(context.store, header.grid_id, grid));
  return grid;
}

}  // namespace splinegrid::server::ops
