// A C++ client of the splinegrid.v1 service: StatusOr results, a deadline on every call, and
// streaming kept inside (uploads in 1 MiB pieces, results reassembled from chunks).
#ifndef SPLINEGRID_CLIENT_CLIENT_H_
#define SPLINEGRID_CLIENT_CLIENT_H_

#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "core/grid/structured_grid.h"
#include "grpcpp/grpcpp.h"
#include "splinegrid/v1/splinegrid_service.grpc.pb.h"

namespace splinegrid::client {

struct ClientOptions {
  // Deadline of every call, measured from its start.
  absl::Duration timeout = absl::Seconds(120);
};

// Progress of a transfer: bytes done and the total (0 when unknown).
using ProgressFn = std::function<void(int64_t done, int64_t total)>;

// Points (and derivatives) of one evaluated block.
struct EvaluatedBlock {
  int block = 0;
  StructuredBlock points;
  std::vector<double> du, dv, dw;  // same layout as points.coords(), when asked for
};

struct EvaluatedGrid {
  int64_t revision = 0;
  std::vector<EvaluatedBlock> blocks;
};

// "name" or "grids/name" -> "grids/name".
std::string GridName(const std::string& name_or_id);

// Stops a watch (Client::Watch) from any thread, also before the call has started or after it
// ended. Shared between the caller and the watch.
class WatchCancel {
 public:
  // Cancels the call: a Next() blocked in another thread returns false, the watch's status is
  // CANCELLED (Client::Watch with a callback returns OK). Thread-safe; idempotent.
  void Cancel();
  bool cancelled() const;

 private:
  friend class RevisionStream;
  // Registers the call's context (nullptr: the call is over); cancels it at once when Cancel
  // came first.
  void Attach(grpc::ClientContext* context);

  mutable std::mutex mu_;
  bool cancelled_ = false;
  grpc::ClientContext* context_ = nullptr;
};

// A WatchGrid call: the grid's revisions as they are stored, read one at a time.
//
//   auto watch = client.Watch("naca", 0);
//   v1::WatchGridResponse message;
//   while (watch->Next(&message)) Use(message.revision());
//   absl::Status why = watch->Finish();
//
// Next() blocks until the server sends the next revision. Cancel() (or cancel()->Cancel()) may
// be called from any other thread while Next() blocks; the stream must outlive those calls.
// Destroying an unfinished stream cancels the call.
class RevisionStream {
 public:
  RevisionStream(std::unique_ptr<grpc::ClientContext> context,
                 std::unique_ptr<grpc::ClientReader<v1::WatchGridResponse>> reader,
                 std::shared_ptr<WatchCancel> cancel);
  ~RevisionStream();
  RevisionStream(const RevisionStream&) = delete;
  RevisionStream& operator=(const RevisionStream&) = delete;

  // The next message; false when the stream has ended (the grid was deleted, the server
  // stopped, the call failed or was cancelled): then Finish() says why.
  bool Next(v1::WatchGridResponse* message);
  // Thread-safe: ends the call, a blocked Next() returns false.
  void Cancel() { cancel_->Cancel(); }
  const std::shared_ptr<WatchCancel>& cancel() const { return cancel_; }
  // The call's status once Next() has returned false (cancels the call first otherwise): OK
  // when the server ended the stream (the grid was deleted, or the server is stopping),
  // CANCELLED after Cancel(), the error otherwise (NOT_FOUND for an unknown grid, ...).
  absl::Status Finish();

 private:
  std::unique_ptr<grpc::ClientContext> context_;
  std::unique_ptr<grpc::ClientReader<v1::WatchGridResponse>> reader_;
  std::shared_ptr<WatchCancel> cancel_;
  bool ended_ = false;
  std::optional<absl::Status> status_;
};

// grpc::Status -> absl::Status.
absl::Status FromGrpc(const grpc::Status& status);

class Client {
 public:
  Client(std::shared_ptr<grpc::Channel> channel, ClientOptions options = {});
  // An insecure channel to host:port.
  static std::unique_ptr<Client> Connect(const std::string& target, ClientOptions options = {});

  // Uploads a Plot3D file's bytes as a new grid. grid_id may be empty (the server picks one).
  absl::StatusOr<v1::Grid> ImportPlot3d(const std::string& bytes, const std::string& grid_id,
                                        const std::string& display_name, bool planar_view,
                                        const ProgressFn& progress = {});
  // Uploads in-memory points as a new grid.
  absl::StatusOr<v1::Grid> ImportPoints(const MultiBlockGrid& grid, const std::string& grid_id,
                                        const std::string& display_name,
                                        const ProgressFn& progress = {});
  absl::StatusOr<v1::FitGridResponse> Fit(const std::string& name, const v1::FitSpec& spec);
  // A faired refit of `revision` (0: latest); fairing null: the server's default (to tolerance).
  absl::StatusOr<v1::FitGridResponse> Fair(const std::string& name, int64_t revision,
                                           const v1::Fairing* fairing = nullptr);
  // Deforms a grid (request.name may be an id); see DeformGridRequest. A deformation that
  // folds cells is FAILED_PRECONDITION with the server's message (nothing was stored).
  absl::StatusOr<v1::DeformGridResponse> Deform(v1::DeformGridRequest request);
  // Generates a grid around a profile and fits it (GenerateGrid; see GenerateGridRequest):
  // the new grid with its revision 1, the generation report and the fit's summary. Nothing is
  // stored on an error.
  absl::StatusOr<v1::GenerateGridResponse> Generate(const v1::GenerateGridRequest& request);
  // Watches a grid's revisions (WatchGrid): those after `after_revision` (0: every stored one
  // first, -1: only new ones), then each new one as it is stored. The call has no deadline; it
  // lasts until the grid is deleted, the server stops or the call is cancelled (`cancel`, or
  // the stream's Cancel(), from any thread).
  std::unique_ptr<RevisionStream> Watch(const std::string& name, int64_t after_revision,
                                        std::shared_ptr<WatchCancel> cancel = nullptr);
  // The same with a callback per revision, on the calling thread; returning false stops the
  // watch. Returns OK when the callback stopped it, `cancel` cancelled it or the server ended
  // the stream (the grid was deleted); the call's error otherwise.
  absl::Status Watch(const std::string& name, int64_t after_revision,
                     const std::function<bool(const v1::WatchGridResponse&)>& on_revision,
                     std::shared_ptr<WatchCancel> cancel = nullptr);
  // Curvature samples along the walls of `revision` at `refinement_level`.
  absl::StatusOr<v1::GetWallCurvatureResponse> WallCurvature(const std::string& name,
                                                             int64_t revision, int refinement_level,
                                                             const std::vector<int>& blocks = {});
  absl::StatusOr<v1::Grid> Get(const std::string& name, int64_t revision = 0,
                               v1::GridView view = v1::GRID_VIEW_BASIC,
                               const std::vector<int>& blocks = {});
  // Any GetGridRequest (request.name may be an id), e.g. with `step` instead of a revision.
  absl::StatusOr<v1::Grid> Get(v1::GetGridRequest request);
  // Every grid, following the pages.
  absl::StatusOr<std::vector<v1::Grid>> List();
  absl::Status Delete(const std::string& name);
  // Streams an evaluation and reassembles it (request.name may be an id).
  absl::StatusOr<EvaluatedGrid> Evaluate(v1::EvaluateGridRequest request,
                                         const ProgressFn& progress = {});
  absl::StatusOr<v1::EvaluatePointsResponse> EvaluatePoints(v1::EvaluatePointsRequest request);
  // grpc.health.v1 status of `service` ("" = the whole server): "SERVING", "NOT_SERVING", ...
  absl::StatusOr<std::string> Health(const std::string& service = "");

  v1::SplineGrid::Stub& stub() { return *stub_; }

 private:
  // A context whose deadline is options_.timeout from now.
  std::unique_ptr<grpc::ClientContext> NewContext() const;

  // One unary call of `method` with a fresh deadline: the response, or the call's status.
  template <typename Request, typename Response>
  absl::StatusOr<Response> Unary(grpc::Status (v1::SplineGrid::Stub::*method)(grpc::ClientContext*,
                                                                              const Request&,
                                                                              Response*),
                                 const Request& request) const {
    auto context = NewContext();
    Response response;
    const grpc::Status status = (stub_.get()->*method)(context.get(), request, &response);
    if (!status.ok()) return FromGrpc(status);
    return response;
  }

  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::SplineGrid::Stub> stub_;
  ClientOptions options_;
};

}  // namespace splinegrid::client

#endif  // SPLINEGRID_CLIENT_CLIENT_H_
