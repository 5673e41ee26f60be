// SplineGridService::ImportGrid: a client stream of a header and then Plot3D bytes or points.
// Data are appended on gRPC's thread (copies only); parsing and validation run on the pool.
#include "absl/strings/str_cat.h"
#include "core/io/planar_view.h"
#include "core/io/plot3d.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"
#include "server/grid_encoding.h"
#include "server/happens_before.h"
#include "server/service.h"

namespace splinegrid::server {
namespace {

class ImportReactor : public grpc::ServerReadReactor<v1::ImportGridRequest> {
 public:
  ImportReactor(ServiceState* state, grpc::CallbackServerContext* context, v1::Grid* response)
      : state_(state), response_(response), log_("ImportGrid", "", state->options.log_calls) {
    absl::StatusOr<Caller> caller = AdmitCall(*state_, context, Role::kWrite, &log_);
    if (!caller.ok()) {
      Fail(caller.status());
      return;
    }
    caller_ = *std::move(caller);
    SG_HAPPENS_BEFORE(this);
    StartRead(&message_);
  }

  void OnReadDone(bool ok) override {
    SG_HAPPENS_AFTER(this);
    if (!ok) {  // the client closed its side: everything has arrived
      if (!state_->pool.TrySubmit(caller_.principal, WorkKind::kLong, [this] { Complete(); })) {
        Fail(absl::ResourceExhaustedError("the server is busy: its work queue is full"));
      }
      return;
    }
    if (absl::Status status = Accept(message_); !status.ok()) {
      Fail(status);
      return;
    }
    SG_HAPPENS_BEFORE(this);
    StartRead(&message_);
  }

  void OnDone() override {
    SG_HAPPENS_AFTER(this);
    delete this;
  }

 private:
  void Fail(const absl::Status& status) {
    log_.Finish(status);
    SG_HAPPENS_BEFORE(this);
    Finish(ToGrpcStatus(status));
  }

  absl::Status Accept(const v1::ImportGridRequest& message) {
    if (!have_header_) {
      if (message.part_case() != v1::ImportGridRequest::kHeader) {
        return absl::InvalidArgumentError("the first message of ImportGrid must be the header");
      }
      have_header_ = true;
      return AcceptHeader(message.header());
    }
    switch (message.part_case()) {
      case v1::ImportGridRequest::kPlot3DChunk:
        return AcceptBytes(message.plot3d_chunk());
      case v1::ImportGridRequest::kPoints:
        return AcceptPoints(message.points());
      default:
        return absl::InvalidArgumentError("a second header, or an empty message, after the first");
    }
  }

  absl::Status AcceptHeader(const v1::ImportHeader& header) {
    header_ = header;
    if (!header.grid_id().empty() && !IsValidGridId(header.grid_id())) {
      return absl::InvalidArgumentError(
          absl::StrCat("header.grid_id = '", header.grid_id(),
                       "' is not valid: 1-63 characters of [a-z0-9-], starting with a letter"));
    }
    log_.set_grid(header.grid_id().empty() ? "" : absl::StrCat("grids/", header.grid_id()));
    if (header.display_name().size() > 1024) {
      return absl::InvalidArgumentError("header.display_name is longer than 1024 bytes");
    }
    if (header.has_plot3d()) {
      const int64_t total = header.plot3d().total_bytes();
      if (total <= 0) {
        return absl::InvalidArgumentError(
            absl::StrCat("header.plot3d.total_bytes = ", total, "; must be positive"));
      }
      SG_ASSIGN_OR_RETURN(upload_, state_->budget.Reserve(total, "the Plot3D upload"));
      bytes_.reserve(total);
      return absl::OkStatus();
    }
    if (!header.has_points()) {
      return absl::InvalidArgumentError("header: set plot3d or points as the source");
    }
    const int s = header.points().spatial_dim();
    if (s != 2 && s != 3) {
      return absl::InvalidArgumentError(
          absl::StrCat("header.points.spatial_dim = ", s, "; must be 2 or 3"));
    }
    if (header.points().blocks_size() == 0) {
      return absl::InvalidArgumentError("header.points.blocks is empty: a grid needs a block");
    }
    int64_t values = 0;
    for (int b = 0; b < header.points().blocks_size(); ++b) {
      const Extents extents = ParseExtents(header.points().blocks(b));
      SG_RETURN_IF_ERROR(ValidateExtents(extents, absl::StrCat("header.points.blocks[", b, "]")));
      values += s * NumPoints(extents);
    }
    SG_ASSIGN_OR_RETURN(upload_,
                        state_->budget.Reserve(values * int64_t{sizeof(double)}, "the points"));
    for (int b = 0; b < header.points().blocks_size(); ++b) {
      points_.blocks.emplace_back(ParseExtents(header.points().blocks(b)), s);
    }
    filled_.assign(points_.blocks.size(), 0);
    return absl::OkStatus();
  }

  absl::Status AcceptBytes(const std::string& chunk) {
    if (!header_.has_plot3d()) {
      return absl::InvalidArgumentError("plot3d_chunk sent, but the header announced points");
    }
    if (static_cast<int64_t>(bytes_.size() + chunk.size()) > header_.plot3d().total_bytes()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "plot3d_chunk: more than header.plot3d.total_bytes = ", header_.plot3d().total_bytes(),
          " bytes arrived"));
    }
    bytes_.append(chunk);
    return absl::OkStatus();
  }

  absl::Status AcceptPoints(const v1::PointChunk& chunk) {
    if (!header_.has_points()) {
      return absl::InvalidArgumentError("points sent, but the header announced a Plot3D file");
    }
    const int b = chunk.block();
    if (b < 0 || b >= static_cast<int>(points_.blocks.size())) {
      return absl::InvalidArgumentError(
          absl::StrCat("points.block = ", b, " is outside [0, ", points_.blocks.size() - 1, "]"));
    }
    std::span<double> coords = points_.blocks[b].coords();
    if (filled_[b] + chunk.coordinates_size() > static_cast<int64_t>(coords.size())) {
      return absl::InvalidArgumentError(absl::StrCat(
          "points: block ", b, " receives more than its ", coords.size(), " coordinates"));
    }
    std::copy(chunk.coordinates().begin(), chunk.coordinates().end(), coords.begin() + filled_[b]);
    filled_[b] += chunk.coordinates_size();
    return absl::OkStatus();
  }

  // Builds the source grid from what arrived (on the pool).
  absl::StatusOr<MultiBlockGrid> BuildSource(std::string* format) {
    if (!have_header_) return absl::InvalidArgumentError("ImportGrid received no header");
    if (header_.has_plot3d()) {
      if (static_cast<int64_t>(bytes_.size()) != header_.plot3d().total_bytes()) {
        return absl::InvalidArgumentError(absl::StrCat("plot3d: ", bytes_.size(),
                                                       " bytes arrived but the header announced ",
                                                       header_.plot3d().total_bytes()));
      }
      Plot3dFormat detected;
      SG_ASSIGN_OR_RETURN(MultiBlockGrid grid, ParsePlot3d(bytes_, "upload", &detected));
      *format = absl::StrCat("plot3d ", DescribePlot3dFormat(detected));
      if (header_.plot3d().planar_view()) {
        SG_ASSIGN_OR_RETURN(grid, PlanarView(grid));
        absl::StrAppend(format, ", planar view");
      }
      return grid;
    }
    for (size_t b = 0; b < points_.blocks.size(); ++b) {
      if (filled_[b] != static_cast<int64_t>(points_.blocks[b].coords().size())) {
        return absl::InvalidArgumentError(
            absl::StrCat("points: block ", b, " received ", filled_[b], " of its ",
                         points_.blocks[b].coords().size(), " coordinates"));
      }
      SG_RETURN_IF_ERROR(ValidateFinite(points_.blocks[b], absl::StrCat("points: block ", b)));
    }
    *format = "points";
    return std::move(points_);
  }

  absl::Status Store() {
    auto source = std::make_shared<SourcePoints>();
    SG_ASSIGN_OR_RETURN(source->grid, BuildSource(&source->format));
    bytes_ = std::string();
    if (source->grid.blocks.empty()) return absl::InvalidArgumentError("the grid has no blocks");
    upload_ = MemoryReservation();
    SG_ASSIGN_OR_RETURN(source->memory,
                        state_->budget.Reserve(SourceBytes(source->grid), "the imported grid"));
    SG_ASSIGN_OR_RETURN(source->connectivity, FindConnectivity(source->grid));
    auto grid = std::make_shared<StoredGrid>();
    grid->display_name = header_.display_name();
    grid->create_time = absl::Now();
    grid->source = std::move(source);
    SG_RETURN_IF_ERROR(CreateGrid(*state_->store, header_.grid_id(), grid));
    log_.set_grid(absl::StrCat("grids/", grid->id));
    return EncodeGrid(*grid, 0, v1::GRID_VIEW_BASIC, {}, response_);
  }

  void Complete() {
    const absl::Status status = Store();
    log_.Finish(status);
    SG_HAPPENS_BEFORE(this);
    Finish(ToGrpcStatus(status));
  }

  ServiceState* state_;
  v1::Grid* response_;
  CallLog log_;
  Caller caller_;
  v1::ImportGridRequest message_;
  bool have_header_ = false;
  v1::ImportHeader header_;
  MemoryReservation upload_;
  std::string bytes_;            // Plot3D file
  MultiBlockGrid points_;        // points source
  std::vector<int64_t> filled_;  // coordinates received per block
};

}  // namespace

grpc::ServerReadReactor<v1::ImportGridRequest>* SplineGridService::ImportGrid(
    grpc::CallbackServerContext* context, v1::Grid* response) {
  return new ImportReactor(state_, context, response);
}

}  // namespace splinegrid::server
