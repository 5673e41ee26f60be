// GetWallCurvature: curvature samples along every wall grid line of a revision.
#include "absl/strings/str_cat.h"
#include "core/fit/report/wall_curvature.h"
#include "core/grid/sampling.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"
#include "server/grid_encoding.h"
#include "server/service.h"

namespace splinegrid::server {
namespace {

// Highest level served: 15 samples between grid points are plenty to see wriggles.
constexpr int kMaxCurvatureLevel = 4;

absl::Status WallCurvature(const StoredGrid& grid, const v1::GetWallCurvatureRequest& request,
                           const CancelCheck& cancel, v1::GetWallCurvatureResponse* response) {
  const int level = request.refinement_level();
  if (level < 0 || level > kMaxCurvatureLevel) {
    return absl::InvalidArgumentError(
        absl::StrCat("refinement_level = ", level, " is outside [0, ", kMaxCurvatureLevel, "]"));
  }
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const GridRevision> revision,
                      grid.ResolveRevision(request.revision()));
  const int num_blocks = static_cast<int>(revision->blocks.size());
  std::vector<bool> wanted(num_blocks, request.blocks().empty());
  for (int b : request.blocks()) {
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
  const int dim = grid.source->grid.blocks.front().spatial_dim();
  int64_t samples = 0;
  for (const WallLine& line : lines) samples += (int64_t{line.length} - 1) * (1 << level) + 1;
  const int64_t bytes = samples * (dim + 2) * static_cast<int64_t>(sizeof(double));
  if (bytes > kMaxMessageBytes) {
    return absl::ResourceExhaustedError(
        absl::StrCat(lines.size(), " wall lines at refinement_level ", level, " are ", samples,
                     " samples, about ", bytes >> 10,
                     " KiB, over the 4 MiB message limit; ask for a lower level or fewer blocks"));
  }
  response->set_revision(revision->number);
  response->set_spatial_dim(dim);
  CurvatureMetrics metrics;
  for (const WallLine& line : lines) {
    SG_RETURN_IF_ERROR(PollCancel(cancel));
    const std::vector<CurvatureSample> curve = SampleWallCurvature(blocks[line.block], line, level);
    AccumulateCurvature(curve, metrics);
    v1::WallCurvatureLine* out = response->add_lines();
    out->set_block(line.block);
    out->set_direction(line.direction);
    EncodeExtents(line.start, out->mutable_start());
    out->set_length(line.length);
    for (const CurvatureSample& s : curve) {
      out->add_arc_length(s.arc_length);
      for (int c = 0; c < dim; ++c) out->add_points(s.point[c]);
      out->add_curvature(s.curvature);
    }
  }
  EncodeCurvature(metrics, response->mutable_metrics());
  return absl::OkStatus();
}

}  // namespace

grpc::ServerUnaryReactor* SplineGridService::GetWallCurvature(
    grpc::CallbackServerContext* context, const v1::GetWallCurvatureRequest* request,
    v1::GetWallCurvatureResponse* response) {
  CallLog log("GetWallCurvature", request->name(), state_->options);
  CancelCheck cancel = CallCancelCheck(context);
  return RunOnPool(
      context, log, Role::kRead, WorkKind::kLong,
      [this, request, response, cancel](const Caller&) -> absl::Status {
        SG_ASSIGN_OR_RETURN(const std::string id, ParseGridName(request->name(), "name"));
        SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> grid, state_->store->Get(id));
        return WallCurvature(*grid, *request, cancel, response);
      });
}

}  // namespace splinegrid::server
