// SplineGridService::DecodeRequests: every method behind a handler over Decoded<Request>, so
// that a request that does not decode is answered INVALID_ARGUMENT (server/decoded_request.h).
#include "core/util/check.h"
#include "google/protobuf/descriptor.h"
#include "server/service.h"

namespace splinegrid::server {
namespace {

// The index of `method` among the service's methods as the generated code numbers them: the
// order of the .proto file, which is the descriptor's.
int MethodIndex(const char* method) {
  const google::protobuf::ServiceDescriptor* service =
      google::protobuf::DescriptorPool::generated_pool()->FindServiceByName(
          v1::SplineGrid::service_full_name());
  SG_CHECK(service != nullptr);
  const google::protobuf::MethodDescriptor* found = service->FindMethodByName(method);
  SG_CHECK(found != nullptr);
  return found->index();
}

// A server stream refused before its first write.
template <typename Response>
class RefusedWriter : public grpc::ServerWriteReactor<Response> {
 public:
  explicit RefusedWriter(const grpc::Status& status) { this->Finish(status); }
  void OnDone() override { delete this; }
};

}  // namespace

absl::Status SplineGridService::RefuseUndecodable(grpc::CallbackServerContext* context,
                                                  const char* method,
                                                  const absl::Status& decode_status) {
  CallLog log(method, "", state_->options);
  const absl::StatusOr<Caller> caller = AdmitCall(*state_, context, Role::kRead, &log);
  const absl::Status status = caller.ok() ? decode_status : caller.status();
  log.Finish(status);
  return status;
}

template <typename Request, typename Response>
void SplineGridService::DecodeUnary(const char* method,
                                    grpc::ServerUnaryReactor* (SplineGridService::*handler)(
                                        grpc::CallbackServerContext*, const Request*, Response*)) {
  MarkMethodCallback(
      MethodIndex(method),
      new grpc::internal::CallbackUnaryHandler<Decoded<Request>, Response>(
          [this, method, handler](grpc::CallbackServerContext* context,
                                  const Decoded<Request>* request, Response* response) {
            if (request->status.ok()) return (this->*handler)(context, &request->message, response);
            grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
            reactor->Finish(ToGrpcStatus(RefuseUndecodable(context, method, request->status)));
            return reactor;
          }));
}

template <typename Request, typename Response>
void SplineGridService::DecodeServerStream(
    const char* method,
    grpc::ServerWriteReactor<Response>* (SplineGridService::*handler)(grpc::CallbackServerContext*,
                                                                      const Request*)) {
  MarkMethodCallback(
      MethodIndex(method),
      new grpc::internal::CallbackServerStreamingHandler<Decoded<Request>, Response>(
          [this, method, handler](
              grpc::CallbackServerContext* context,
              const Decoded<Request>* request) -> grpc::ServerWriteReactor<Response>* {
            if (request->status.ok()) return (this->*handler)(context, &request->message);
            return new RefusedWriter<Response>(
                ToGrpcStatus(RefuseUndecodable(context, method, request->status)));
          }));
}

void SplineGridService::DecodeRequests() {
  using S = SplineGridService;
  DecodeUnary("FitGrid", &S::FitGrid);
  DecodeUnary("FairGrid", &S::FairGrid);
  DecodeUnary("GetWallCurvature", &S::GetWallCurvature);
  DecodeUnary("DeformGrid", &S::DeformGrid);
  DecodeUnary("GenerateGrid", &S::GenerateGrid);
  DecodeUnary("GetGrid", &S::GetGrid);
  DecodeUnary("ListGrids", &S::ListGrids);
  DecodeUnary("DeleteGrid", &S::DeleteGrid);
  DecodeUnary("EvaluatePoints", &S::EvaluatePoints);
  DecodeServerStream("WatchGrid", &S::WatchGrid);
  DecodeServerStream("EvaluateGrid", &S::EvaluateGrid);
  DecodeServerStream("ExportGrid", &S::ExportGrid);
  // The client streams check each message themselves (ImportReactor, ImportArchiveReactor).
  MarkMethodCallback(
      MethodIndex("ImportGrid"),
      new grpc::internal::CallbackClientStreamingHandler<Decoded<v1::ImportGridRequest>, v1::Grid>(
          [this](grpc::CallbackServerContext* context, v1::Grid* response) {
            return ImportGridStream(context, response);
          }));
  MarkMethodCallback(
      MethodIndex("ImportArchive"),
      new grpc::internal::CallbackClientStreamingHandler<Decoded<v1::ImportArchiveRequest>,
                                                         v1::Grid>(
          [this](grpc::CallbackServerContext* context, v1::Grid* response) {
            return ImportArchiveStream(context, response);
          }));
}

}  // namespace splinegrid::server
