// GetWallCurvature: the request converted and handed to the operation
// (server/ops/wall_curvature.h), on the pool; the samples encoded into the response.
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"
#include "server/grid_encoding.h"
#include "server/ops/wall_curvature.h"
#include "server/service.h"

namespace splinegrid::server {

grpc::ServerUnaryReactor* SplineGridService::GetWallCurvature(
    grpc::CallbackServerContext* context, const v1::GetWallCurvatureRequest* request,
    v1::GetWallCurvatureResponse* response) {
  CallLog log("GetWallCurvature", request->name(), state_->options);
  CancelCheck cancel = CallCancelCheck(context);
  return RunOnPool(context, log, Role::kRead, WorkKind::kLong,
                   [this, request, response, cancel](const Caller&) -> absl::Status {
                     ops::WallCurvatureRequest wall;
                     SG_ASSIGN_OR_RETURN(wall.grid_id, ParseGridName(request->name(), "name"));
                     wall.revision = request->revision();
                     wall.level = request->refinement_level();
                     wall.blocks.assign(request->blocks().begin(), request->blocks().end());
                     wall.max_bytes = kMaxMessageBytes;
                     SG_ASSIGN_OR_RETURN(const ops::WallCurvatureResult result,
                                         ops::WallCurvature(Ops(), wall, cancel));
                     EncodeWallCurvature(result, response);
                     return absl::OkStatus();
                   });
}

}  // namespace splinegrid::server
