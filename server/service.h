// The splinegrid.v1.SplineGrid service: short callback handlers that validate, hand the work
// to the worker pool and Finish. The numerics live in core/, the conversions in proto/convert.
#ifndef SPLINEGRID_SERVER_SERVICE_H_
#define SPLINEGRID_SERVER_SERVICE_H_

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/status.h"
#include "grpcpp/grpcpp.h"
#include "server/auth/authenticator.h"
#include "server/auth/caller.h"
#include "server/call_log.h"
#include "server/decoded_request.h"
#include "server/deformer_cache.h"
#include "server/grid_id.h"
#include "server/grid_store.h"
#include "server/memory_budget.h"
#include "server/open_watches.h"
#include "server/ops/ops_context.h"
#include "server/scheduler.h"
#include "server/server_options.h"
#include "server/stream_limits.h"
#include "splinegrid/v1/splinegrid_service.grpc.pb.h"

namespace splinegrid::server {

// What every call may use: the store, the scheduler, the budget and the configuration.
struct ServiceState {
  // The store is opened by the server (store/open_store.h), with this state's budget.
  explicit ServiceState(const ServerOptions& opts);

  ServerOptions options;
  MemoryBudget budget;
  Authenticator authenticator;
  std::unique_ptr<GridStore> store;
  StreamLimits streams;  // open streaming calls per principal
  OpenWatches watches;   // woken when the tokens are reloaded
  Scheduler pool;        // the worker threads, cheap work first, long work fair across callers
  DeformerCache deformers;
  std::atomic<bool> draining{false};  // set on shutdown: new calls get UNAVAILABLE

  // The operations' view of the state (server/ops).
  ops::OpsContext Ops() { return {*store, budget, deformers}; }
};

// Admits a call that needs `needed`: UNAVAILABLE while draining, UNAUTHENTICATED without valid
// credentials, PERMISSION_DENIED for a role below `needed`; sets the log's principal.
absl::StatusOr<Caller> AdmitCall(const ServiceState& state, grpc::CallbackServerContext* context,
                                 Role needed, CallLog* log);

// A streaming call admitted by AdmitCall and holding one of its caller's stream slots.
struct AdmittedStream {
  Caller caller;
  StreamSlot slot;
};

// AdmitCall, then a stream slot of the caller (RESOURCE_EXHAUSTED when all are open).
absl::StatusOr<AdmittedStream> AdmitStream(ServiceState& state,
                                           grpc::CallbackServerContext* context, Role needed,
                                           CallLog* log);

// absl::Status -> grpc::Status (the codes are the same numbers).
grpc::Status ToGrpcStatus(const absl::Status& status);

// A check for the kernel's cancellation polls: the call was cancelled or its deadline passed.
CancelCheck CallCancelCheck(grpc::CallbackServerContext* context);

// Why a call that stopped early (a failed write, OnCancel, a cancelled kernel) ended:
// UNAVAILABLE "the server is shutting down" while draining, DEADLINE_EXCEEDED when its deadline
// passed, else CANCELLED "the client cancelled".
absl::Status WhyCallEnded(const ServiceState& state, grpc::CallbackServerContext* context);

// `status`, except that a CANCELLED one (the kernel only knows "stop") says why: WhyCallEnded.
absl::Status ExplainCancellation(const ServiceState& state, grpc::CallbackServerContext* context,
                                 absl::Status status);

// "grids/{id}" -> id, or INVALID_ARGUMENT naming `field` and the value.
absl::StatusOr<std::string> ParseGridName(const std::string& name, const std::string& field);

// The optional `step` field of a request that selects a revision.
template <typename Request>
std::optional<int64_t> OptionalStep(const Request& request) {
  if (!request.has_step()) return std::nullopt;
  return request.step();
}

class SplineGridService final : public v1::SplineGrid::CallbackService {
 public:
  // Registers every method with a handler that decodes its requests (server/decoded_request.h).
  explicit SplineGridService(ServiceState* state) : state_(state) { DecodeRequests(); }

  // The client streams read Decoded<Request> messages: not overrides of the generated
  // ImportGrid and ImportArchive, but registered in their place by DecodeRequests.
  grpc::ServerReadReactor<Decoded<v1::ImportGridRequest>>* ImportGridStream(
      grpc::CallbackServerContext* context, v1::Grid* response);
  grpc::ServerReadReactor<Decoded<v1::ImportArchiveRequest>>* ImportArchiveStream(
      grpc::CallbackServerContext* context, v1::Grid* response);

  grpc::ServerUnaryReactor* FitGrid(grpc::CallbackServerContext* context,
                                    const v1::FitGridRequest* request,
                                    v1::FitGridResponse* response) override;
  grpc::ServerUnaryReactor* FairGrid(grpc::CallbackServerContext* context,
                                     const v1::FairGridRequest* request,
                                     v1::FitGridResponse* response) override;
  grpc::ServerUnaryReactor* GetWallCurvature(grpc::CallbackServerContext* context,
                                             const v1::GetWallCurvatureRequest* request,
                                             v1::GetWallCurvatureResponse* response) override;
  grpc::ServerUnaryReactor* DeformGrid(grpc::CallbackServerContext* context,
                                       const v1::DeformGridRequest* request,
                                       v1::DeformGridResponse* response) override;
  grpc::ServerUnaryReactor* GenerateGrid(grpc::CallbackServerContext* context,
                                         const v1::GenerateGridRequest* request,
                                         v1::GenerateGridResponse* response) override;
  grpc::ServerWriteReactor<v1::WatchGridResponse>* WatchGrid(
      grpc::CallbackServerContext* context, const v1::WatchGridRequest* request) override;
  grpc::ServerUnaryReactor* GetGrid(grpc::CallbackServerContext* context,
                                    const v1::GetGridRequest* request, v1::Grid* response) override;
  grpc::ServerUnaryReactor* ListGrids(grpc::CallbackServerContext* context,
                                      const v1::ListGridsRequest* request,
                                      v1::ListGridsResponse* response) override;
  grpc::ServerUnaryReactor* DeleteGrid(grpc::CallbackServerContext* context,
                                       const v1::DeleteGridRequest* request,
                                       google::protobuf::Empty* response) override;
  grpc::ServerWriteReactor<v1::EvaluateGridResponse>* EvaluateGrid(
      grpc::CallbackServerContext* context, const v1::EvaluateGridRequest* request) override;
  grpc::ServerUnaryReactor* EvaluatePoints(grpc::CallbackServerContext* context,
                                           const v1::EvaluatePointsRequest* request,
                                           v1::EvaluatePointsResponse* response) override;
  grpc::ServerWriteReactor<v1::ExportGridResponse>* ExportGrid(
      grpc::CallbackServerContext* context, const v1::ExportGridRequest* request) override;

 private:
  using Work = std::function<absl::Status(const Caller& caller)>;

  // Puts a handler over Decoded<Request> in front of each method (request_decoding.cc).
  void DecodeRequests();
  template <typename Request, typename Response>
  void DecodeUnary(const char* method,
                   grpc::ServerUnaryReactor* (SplineGridService::*handler)(
                       grpc::CallbackServerContext*, const Request*, Response*));
  template <typename Request, typename Response>
  void DecodeServerStream(const char* method,
                          grpc::ServerWriteReactor<Response>* (SplineGridService::*handler)(
                              grpc::CallbackServerContext*, const Request*));
  // The status of a call to `method` whose request did not decode (`decode_status`), after
  // admission (a caller that may not call gets UNAUTHENTICATED first), logged.
  absl::Status RefuseUndecodable(grpc::CallbackServerContext* context, const char* method,
                                 const absl::Status& decode_status);
  // Admits the call (AdmitCall with `needed`), runs `work` on the worker pool as `kind` and
  // finishes the call with its status (RESOURCE_EXHAUSTED naming the limit when the scheduler
  // refuses it).
  grpc::ServerUnaryReactor* RunOnPool(grpc::CallbackServerContext* context, CallLog log,
                                      Role needed, WorkKind kind, Work work);
  // The same for work whose cost is known only once the grid is read: `size_up` runs first as
  // `kind` (a slice: any worker, turns across principals); when it answers true (small) or
  // fails, `work` runs in that task (failing early with its own answer), otherwise it is queued
  // for the long workers, counted as the caller's long call like one admitted as long work.
  // Without `size_up` (null), `work` runs in the first task: RunOnPool.
  using SizeUp = std::function<absl::StatusOr<bool>(const Caller&)>;
  grpc::ServerUnaryReactor* RunSizedOnPool(grpc::CallbackServerContext* context, CallLog log,
                                           Role needed, WorkKind kind, SizeUp size_up, Work work);
  // Admits the call and runs cheap, non-numeric `work` right here and finishes the call.
  grpc::ServerUnaryReactor* RunInline(grpc::CallbackServerContext* context, CallLog log,
                                      Role needed, const Work& work);

  ops::OpsContext Ops() const { return state_->Ops(); }
  // The operations' view for `caller`: a writer changes only its own grids (MayChangeGrid).
  ops::OpsContext Ops(const Caller& caller) const;

  ServiceState* state_;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_SERVICE_H_
