// DeformGrid: the request converted (proto/convert/deform_convert.h) and handed to the
// operation (server/ops/deform.h), on the pool.
#include "core/util/status_macros.h"
#include "proto/convert/deform_convert.h"
#include "server/grid_encoding.h"
#include "server/ops/deform.h"
#include "server/service.h"

namespace splinegrid::server {
namespace {

absl::StatusOr<ops::DeformRequest> ParseRequest(const v1::DeformGridRequest& request) {
  ops::DeformRequest out;
  SG_ASSIGN_OR_RETURN(out.grid_id, ParseGridName(request.name(), "name"));
  out.base_revision = request.base_revision();
  out.reference_revision = request.reference_revision();
  SG_ASSIGN_OR_RETURN(out.options, ParseDeformOptions(request));
  SG_ASSIGN_OR_RETURN(out.motion, ParseDeformMotion(request));
  out.check_level = request.check_level();
  out.max_boundary_error = request.max_boundary_error();
  out.time = request.time();
  out.step = request.step();
  return out;
}

}  // namespace

grpc::ServerUnaryReactor* SplineGridService::DeformGrid(grpc::CallbackServerContext* context,
                                                        const v1::DeformGridRequest* request,
                                                        v1::DeformGridResponse* response) {
  CallLog log("DeformGrid", request->name(), state_->options);
  CancelCheck cancel = CallCancelCheck(context);
  // Converted before admission only to schedule it: a deform with a kept deformer is cheap work
  // (ops::HasKeptDeformer); any other is sized once its grid is read (ops::DeformIsSmall): a
  // small one runs in that slice, a large one on the long workers. Errors are answered after
  // admission, on the pool.
  auto parsed = std::make_shared<absl::StatusOr<ops::DeformRequest>>(ParseRequest(*request));
  Work deform = [this, parsed, response, cancel](const Caller& caller) -> absl::Status {
    SG_RETURN_IF_ERROR(parsed->status());
    SG_ASSIGN_OR_RETURN(const std::shared_ptr<const GridRevision> published,
                        ops::Deform(Ops(caller), **parsed, cancel));
    response->set_revision(published->number);
    EncodeDeformReport(published->deform, response->mutable_report());
    return absl::OkStatus();
  };
  if (parsed->ok() && ops::HasKeptDeformer(Ops(), **parsed)) {
    return RunOnPool(context, log, Role::kWrite, WorkKind::kCheap, std::move(deform));
  }
  SizeUp small = [this, parsed](const Caller& caller) -> absl::StatusOr<bool> {
    SG_RETURN_IF_ERROR(parsed->status());
    return ops::DeformIsSmall(Ops(caller), **parsed);
  };
  return RunSizedOnPool(context, log, Role::kWrite, WorkKind::kSlice, std::move(small),
                        std::move(deform));
}

}  // namespace splinegrid::server
