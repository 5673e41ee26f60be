// SplineGridService::EvaluatePoints: a batch of (block, u, v, w) parameter points
// (server/ops/evaluate_points.h).
#include "server/ops/evaluate_points.h"

#include "core/util/status_macros.h"
#include "server/grid_encoding.h"
#include "server/service.h"

namespace splinegrid::server {
namespace {

// Requests of at most this many points are evaluated on the gRPC thread that received them.
constexpr int kInlinePoints = 16;

void CopyTo(const std::vector<double>& values, google::protobuf::RepeatedField<double>* out) {
  out->Add(values.begin(), values.end());
}

}  // namespace

grpc::ServerUnaryReactor* SplineGridService::EvaluatePoints(
    grpc::CallbackServerContext* context, const v1::EvaluatePointsRequest* request,
    v1::EvaluatePointsResponse* response) {
  CallLog log("EvaluatePoints", request->name(), state_->options);
  Work work = [this, request, response](const Caller&) -> absl::Status {
    ops::PointsRequest points;
    SG_ASSIGN_OR_RETURN(points.grid_id, ParseGridName(request->name(), "name"));
    points.revision = request->revision();
    points.step = OptionalStep(*request);
    points.blocks = {request->blocks().data(), static_cast<size_t>(request->blocks_size())};
    points.parameters = {request->parameters().data(),
                         static_cast<size_t>(request->parameters_size())};
    points.derivatives = request->derivatives();
    points.max_points = state_->options.max_output_points;
    points.max_bytes = kMaxMessageBytes;
    SG_ASSIGN_OR_RETURN(const ops::EvaluatedPoints evaluated, ops::EvaluatePoints(Ops(), points));
    response->set_revision(evaluated.revision);
    response->set_spatial_dim(evaluated.spatial_dim);
    CopyTo(evaluated.points, response->mutable_points());
    CopyTo(evaluated.du, response->mutable_du());
    CopyTo(evaluated.dv, response->mutable_dv());
    CopyTo(evaluated.dw, response->mutable_dw());
    return absl::OkStatus();
  };
  // A few points from memory cost less than handing them to the pool (a thread switch each
  // way: 0.63x of a raw gRPC service's unary rate through the pool, 0.99x inline).
  if (request->parameters_size() <= 3 * kInlinePoints && state_->store->ReadsAreLocal()) {
    return RunInline(context, log, Role::kRead, work);
  }
  return RunOnPool(context, log, Role::kRead, WorkKind::kCheap, std::move(work));
}

}  // namespace splinegrid::server
