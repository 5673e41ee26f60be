// raw_baseline_server --address=HOST:PORT: a minimal gRPC callback server (raw_baseline.proto)
// with gRPC's defaults and nothing else: no admission, metrics, logging or store. Its unary call
// replies 24 bytes, its stream sends prebuilt chunks as fast as the transport takes them.
// splinegrid_service_bench starts it like `splinegrid serve` (pinned to one core) and reports
// the service's rates as ratios to it.
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "bench/service/raw_baseline.grpc.pb.h"
#include "grpcpp/grpcpp.h"

namespace splinegrid::bench {
namespace {

// Writes `total_bytes` of payload in chunks of `chunk_bytes`, one message in flight.
class ChunkWriter final : public grpc::ServerWriteReactor<StreamChunk> {
 public:
  explicit ChunkWriter(const StreamRequest& request) : remaining_(request.total_bytes()) {
    if (request.chunk_bytes() <= 0 || request.total_bytes() < 0) {
      Finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                          "chunk_bytes must be positive and total_bytes non-negative"));
      return;
    }
    chunk_.mutable_values()->Resize(request.chunk_bytes() / 8, 0.5);
    WriteNext();
  }
  void OnWriteDone(bool ok) override {
    if (!ok) return Finish(grpc::Status(grpc::StatusCode::CANCELLED, "write failed"));
    WriteNext();
  }
  void OnDone() override { delete this; }

 private:
  void WriteNext() {
    if (remaining_ <= 0) return Finish(grpc::Status::OK);
    if (remaining_ < 8 * int64_t{chunk_.values_size()}) {
      chunk_.mutable_values()->Truncate(static_cast<int>(remaining_ / 8));
    }
    remaining_ -= 8 * int64_t{chunk_.values_size()};
    StartWrite(&chunk_);
  }

  int64_t remaining_;
  StreamChunk chunk_;
};

class RawBaselineService final : public RawBaseline::CallbackService {
  grpc::ServerUnaryReactor* Unary(grpc::CallbackServerContext* context, const UnaryRequest* request,
                                  UnaryReply* reply) override {
    for (int c = 0; c < 3; ++c) {
      reply->add_values(c < request->parameters_size() ? request->parameters(c) : 0.0);
    }
    grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
    reactor->Finish(grpc::Status::OK);
    return reactor;
  }
  grpc::ServerWriteReactor<StreamChunk>* Stream(grpc::CallbackServerContext*,
                                                const StreamRequest* request) override {
    return new ChunkWriter(*request);
  }
};

}  // namespace
}  // namespace splinegrid::bench

int main(int argc, char** argv) {
  constexpr char kFlag[] = "--address=";
  std::string address;
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], kFlag, sizeof(kFlag) - 1) == 0) address = argv[i] + sizeof(kFlag) - 1;
  }
  if (address.empty()) {
    std::fprintf(stderr, "usage: raw_baseline_server --address=HOST:PORT\n");
    return 2;
  }
  splinegrid::bench::RawBaselineService service;
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort(address, grpc::InsecureServerCredentials(), &port);
  builder.RegisterService(&service);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  if (!server || port == 0) {
    std::fprintf(stderr, "raw_baseline_server: cannot listen on %s\n", address.c_str());
    return 1;
  }
  server->Wait();
  return 0;
}
