// A C++ client of the splinegrid.v1 service: StatusOr results, a deadline on every call, and
// streaming kept inside (uploads in 1 MiB pieces, results reassembled from chunks).
#ifndef SPLINEGRID_CLIENT_CLIENT_H_
#define SPLINEGRID_CLIENT_CLIENT_H_

#include <functional>
#include <memory>
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
  // Deforms a grid (request.name may be an id); see DeformGridRequest.
  absl::StatusOr<v1::DeformGridResponse> Deform(v1::DeformGridRequest request);
  // Curvature samples along the walls of `revision` at `refinement_level`.
  absl::StatusOr<v1::GetWallCurvatureResponse> WallCurvature(const std::string& name,
                                                             int64_t revision, int refinement_level,
                                                             const std::vector<int>& blocks = {});
  absl::StatusOr<v1::Grid> Get(const std::string& name, int64_t revision = 0,
                               v1::GridView view = v1::GRID_VIEW_BASIC,
                               const std::vector<int>& blocks = {});
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

  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::SplineGrid::Stub> stub_;
  ClientOptions options_;
};

// grpc::Status -> absl::Status.
absl::Status FromGrpc(const grpc::Status& status);

}  // namespace splinegrid::client

#endif  // SPLINEGRID_CLIENT_CLIENT_H_
