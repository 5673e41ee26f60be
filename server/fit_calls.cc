// FitGrid and FairGrid: the requests converted (proto/convert) and handed to the operations
// (server/ops/fit.h), on the pool.
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"
#include "server/grid_encoding.h"
#include "server/ops/fit.h"
#include "server/service.h"

namespace splinegrid::server {

grpc::ServerUnaryReactor* SplineGridService::FitGrid(grpc::CallbackServerContext* context,
                                                     const v1::FitGridRequest* request,
                                                     v1::FitGridResponse* response) {
  CallLog log("FitGrid", request->name(), state_->options);
  CancelCheck cancel = CallCancelCheck(context);
  return RunOnPool(context, log, Role::kWrite, WorkKind::kLong,
                   [this, request, response, cancel](const Caller& caller) -> absl::Status {
                     SG_ASSIGN_OR_RETURN(const std::string id,
                                         ParseGridName(request->name(), "name"));
                     SG_ASSIGN_OR_RETURN(GridFitOptions options, ParseFitSpec(request->spec()));
                     SG_ASSIGN_OR_RETURN(const std::shared_ptr<const GridRevision> revision,
                                         ops::Fit(Ops(caller), id, std::move(options), cancel));
                     EncodeFitResponse(*revision, response);
                     return absl::OkStatus();
                   });
}

grpc::ServerUnaryReactor* SplineGridService::FairGrid(grpc::CallbackServerContext* context,
                                                      const v1::FairGridRequest* request,
                                                      v1::FitGridResponse* response) {
  CallLog log("FairGrid", request->name(), state_->options);
  CancelCheck cancel = CallCancelCheck(context);
  return RunOnPool(context, log, Role::kWrite, WorkKind::kLong,
                   [this, request, response, cancel](const Caller& caller) -> absl::Status {
                     ops::FairRequest fair;
                     SG_ASSIGN_OR_RETURN(fair.grid_id, ParseGridName(request->name(), "name"));
                     fair.revision = request->revision();
                     if (request->has_fairing()) {
                       SG_ASSIGN_OR_RETURN(fair.fairing,
                                           ParseFairing(request->fairing(), "fairing"));
                     }
                     fair.allow_folds = request->allow_folds();
                     SG_ASSIGN_OR_RETURN(const std::shared_ptr<const GridRevision> revision,
                                         ops::Fair(Ops(caller), fair, cancel));
                     EncodeFitResponse(*revision, response);
                     return absl::OkStatus();
                   });
}

}  // namespace splinegrid::server
