#include "server/ops/wall_curvature.h"

#include <memory>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid::server::ops {

absl::StatusOr<WallCurvatureResult> WallCurvature(const OpsContext& context,
                                                  const WallCurvatureRequest& request,
                                                  const CancelCheck& cancel) {
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> grid,
                      context.store.Get(request.grid_id));
  const int level = request.level;
  if (level < 0 || level > kMaxCurvatureLevel) {
    return absl::InvalidArgumentError(
        absl::StrCat("refinement_level = ", level, " is outside [0, ", kMaxCurvatureLevel, "]"));
  }
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const GridRevision> revision,
                      grid->ResolveRevision(request.revision));
  const int num_blocks = static_cast<int>(revision->blocks.size());
  std::vector<bool> wanted(num_blocks, request.blocks.empty());
  for (int b : request.blocks) {
    if (b < 0 || b >= num_blocks) {
      return absl::InvalidArgumentError(
          absl::StrCat("blocks: ", b, " is outside [0, ", num_blocks - 1, "]"));
    }
    wanted[b] = true;
  }
  std::vector<FittedBlock> blocks;
  for (const BlockFit& b : revision->blocks) blocks.push_back(b.fitted);
  std::vector<WallLine> lines;
  for (const WallLine& line : FindWallLines(blocks, revision->kinds)) {
    if (wanted[line.block]) lines.push_back(line);
  }
  // Refuse before sampling what cannot be sent: arc length, curvature and the point per sample.
  const int dim = grid->source->grid().blocks.front().spatial_dim();
  int64_t samples = 0;
  for (const WallLine& line : lines) samples += (int64_t{line.length} - 1) * (1 << level) + 1;
  const int64_t bytes = samples * (dim + 2) * static_cast<int64_t>(sizeof(double));
  if (bytes > request.max_bytes) {
    return absl::ResourceExhaustedError(
        absl::StrCat(lines.size(), " wall lines at refinement_level ", level, " are ", samples,
                     " samples, about ", bytes >> 10, " KiB, over the ",
                     (request.max_bytes + (1 << 20) - 1) >> 20,
                     " MiB message limit; ask for a lower level or fewer blocks"));
  }
  WallCurvatureResult result;
  result.revision = revision->number;
  result.spatial_dim = dim;
  for (const WallLine& line : lines) {
    SG_RETURN_IF_ERROR(PollCancel(cancel));
    std::vector<CurvatureSample> curve = SampleWallCurvature(blocks[line.block], line, level);
    AccumulateCurvature(curve, result.metrics);
    result.lines.push_back({line, std::move(curve)});
  }
  return result;
}

}  // namespace splinegrid::server::ops
