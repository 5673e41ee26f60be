// SplineGridService::ImportGrid: a client stream of a header and then Plot3D or CGNS bytes, or
// points. CGNS files are decoded in a child process (server/cgns_decoder.h).
// Data are appended on gRPC's thread (copies only); parsing and validation run on the pool.
// Memory is allocated and charged to the budget as data arrive, never from the header's
// announced sizes; a stream that sends nothing for --import_idle_timeout is ended.
#include <algorithm>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"
#include "proto/convert/plot3d_format_convert.h"
#include "server/cgns_decoder.h"
#include "server/grid_encoding.h"
#include "server/ops/import.h"
#include "server/service.h"
#include "server/upload_reactor.h"

namespace splinegrid::server {
namespace {

class ImportReactor : public UploadReactor<v1::ImportGridRequest> {
 public:
  ImportReactor(ServiceState* state, grpc::CallbackServerContext* context, v1::Grid* response)
      : UploadReactor(state, context, "ImportGrid"), response_(response) {
    Start();
  }

 private:
  // Makes room for `more` elements in `into` (growing by doubling, capped at `limit` elements:
  // at most twice what arrived, never more than announced), charging the growth first. While
  // the elements move both buffers exist, so both are charged until the old one is freed.
  template <typename Container>
  absl::Status MakeRoom(Container& into, size_t more, size_t limit, const char* what) {
    const size_t needed = into.size() + more;
    if (needed <= into.capacity()) return absl::OkStatus();
    constexpr int64_t kSize = sizeof(typename Container::value_type);
    const size_t capacity = std::min(limit, std::max(needed, 2 * into.capacity()));
    const int64_t old_bytes = static_cast<int64_t>(into.capacity()) * kSize;
    // libstdc++'s std::string::reserve allocates at least twice the old capacity: charge the
    // larger of the two, then what was allocated.
    const int64_t bound = static_cast<int64_t>(std::max(capacity, 2 * into.capacity())) * kSize;
    SG_RETURN_IF_ERROR(state_->budget.Extend(&upload_, bound, what));
    into.reserve(capacity);
    const int64_t allocated = static_cast<int64_t>(into.capacity()) * kSize;
    return state_->budget.Resize(&upload_, upload_.bytes() - bound + allocated - old_bytes,
                                 what);  // a release
  }

  absl::Status Accept(const v1::ImportGridRequest& message) override {
    if (!have_header_) {
      if (message.part_case() != v1::ImportGridRequest::kHeader) {
        return absl::InvalidArgumentError("the first message of ImportGrid must be the header");
      }
      have_header_ = true;
      return AcceptHeader(message.header());
    }
    switch (message.part_case()) {
      case v1::ImportGridRequest::kPlot3DChunk:
        return AcceptBytes(message.plot3d_chunk(), /*cgns=*/false);
      case v1::ImportGridRequest::kCgnsChunk:
        return AcceptBytes(message.cgns_chunk(), /*cgns=*/true);
      case v1::ImportGridRequest::kPoints:
        return AcceptPoints(message.points());
      default:
        return absl::InvalidArgumentError("a second header, or an empty message, after the first");
    }
  }

  absl::Status AcceptHeader(const v1::ImportHeader& header) {
    header_ = header;
    SG_RETURN_IF_ERROR(CheckRequestedGridId(header.grid_id(), "header.grid_id"));
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
      if (header.plot3d().planar_view() && header.plot3d().planar_view_if_two_planes()) {
        return absl::InvalidArgumentError(
            "header.plot3d.planar_view and header.plot3d.planar_view_if_two_planes are both "
            "true; give one (planar_view fails for a file that is not a two-plane grid, "
            "planar_view_if_two_planes stores such a file as read)");
      }
      return absl::OkStatus();  // charged as the bytes arrive (AcceptBytes)
    }
    if (header.has_cgns()) {
      if (header.cgns().total_bytes() <= 0) {
        return absl::InvalidArgumentError(absl::StrCat(
            "header.cgns.total_bytes = ", header.cgns().total_bytes(), "; must be positive"));
      }
      // A server without its decoder says so before the upload, not after.
      return FindCgnsDecoder(state_->options.cgns_decoder).status();  // bytes: AcceptBytes
    }
    if (!header.has_points()) {
      return absl::InvalidArgumentError("header: set plot3d, cgns or points as the source");
    }
    const int s = header.points().spatial_dim();
    if (s != 2 && s != 3) {
      return absl::InvalidArgumentError(
          absl::StrCat("header.points.spatial_dim = ", s, "; must be 2 or 3"));
    }
    if (header.points().blocks_size() == 0) {
      return absl::InvalidArgumentError("header.points.blocks is empty: a grid needs a block");
    }
    const int num_blocks = header.points().blocks_size();
    SG_RETURN_IF_ERROR(state_->budget.Extend(
        &upload_, num_blocks * int64_t{sizeof(Extents) + sizeof(std::vector<double>)},
        "the header's blocks"));
    for (int b = 0; b < num_blocks; ++b) {
      const Extents extents = ParseExtents(header.points().blocks(b));
      SG_RETURN_IF_ERROR(ValidateExtents(extents, absl::StrCat("header.points.blocks[", b, "]")));
      extents_.push_back(extents);
    }
    coords_.resize(extents_.size());           // empty: they grow as points arrive (AcceptPoints)
    header_.mutable_points()->clear_blocks();  // kept in extents_
    ReleaseMessage();                          // drops the header's capacity
    return absl::OkStatus();
  }

  // The file's bytes: plot3d_chunk for a Plot3D header, cgns_chunk for a CGNS header.
  absl::Status AcceptBytes(const std::string& chunk, bool cgns) {
    const char* field = cgns ? "cgns" : "plot3d";
    if (cgns ? !header_.has_cgns() : !header_.has_plot3d()) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, "_chunk sent, but the header announced another source"));
    }
    const int64_t total = cgns ? header_.cgns().total_bytes() : header_.plot3d().total_bytes();
    if (static_cast<int64_t>(bytes_.size() + chunk.size()) > total) {
      return absl::InvalidArgumentError(absl::StrCat(field, "_chunk: more than header.", field,
                                                     ".total_bytes = ", total, " bytes arrived"));
    }
    SG_RETURN_IF_ERROR(MakeRoom(bytes_, chunk.size(), static_cast<size_t>(total),
                                cgns ? "the CGNS upload" : "the Plot3D upload"));
    bytes_.append(chunk);
    return absl::OkStatus();
  }

  absl::Status AcceptPoints(const v1::PointChunk& chunk) {
    if (!header_.has_points()) {
      return absl::InvalidArgumentError("points sent, but the header announced a file");
    }
    const int b = chunk.block();
    if (b < 0 || b >= static_cast<int>(extents_.size())) {
      return absl::InvalidArgumentError(
          absl::StrCat("points.block = ", b, " is outside [0, ", extents_.size() - 1, "]"));
    }
    std::vector<double>& coords = coords_[b];
    const size_t total = static_cast<size_t>(BlockValues(b));
    if (coords.size() + chunk.coordinates_size() > total) {
      return absl::InvalidArgumentError(
          absl::StrCat("points: block ", b, " receives more than its ", total, " coordinates"));
    }
    SG_RETURN_IF_ERROR(MakeRoom(coords, chunk.coordinates_size(), total, "the points"));
    coords.insert(coords.end(), chunk.coordinates().begin(), chunk.coordinates().end());
    return absl::OkStatus();
  }

  // Coordinates block `b` of a points source has (spatial_dim per point).
  int64_t BlockValues(size_t b) const {
    return header_.points().spatial_dim() * NumPoints(extents_[b]);
  }

  // Decodes a CGNS upload in a child process (on the pool), with the file's boundaries and its
  // stated 1-to-1 connections (compared with the found ones when stored).
  absl::StatusOr<ops::ImportedSource> BuildCgnsSource() {
    if (static_cast<int64_t>(bytes_.size()) != header_.cgns().total_bytes()) {
      return absl::InvalidArgumentError(absl::StrCat("cgns: ", bytes_.size(),
                                                     " bytes arrived but the header announced ",
                                                     header_.cgns().total_bytes()));
    }
    ops::ImportedSource source;
    SG_ASSIGN_OR_RETURN(source.imported, DecodeCgnsUpload(bytes_, state_->options.cgns_decoder,
                                                          &state_->budget, &grid_memory_, [this] {
                                                            return context_->IsCancelled();
                                                          }));
    source.memory = std::move(grid_memory_);
    return source;
  }

  // The Plot3D upload parsed by the operation (on the pool).
  absl::StatusOr<ops::ImportedSource> BuildPlot3dSource() {
    const v1::Plot3dSource& plot3d = header_.plot3d();
    if (static_cast<int64_t>(bytes_.size()) != plot3d.total_bytes()) {
      return absl::InvalidArgumentError(absl::StrCat("plot3d: ", bytes_.size(),
                                                     " bytes arrived but the header announced ",
                                                     plot3d.total_bytes()));
    }
    Plot3dReadOptions read_options;
    read_options.layout = Plot3dLayoutFromProto(plot3d.layout());
    const ops::PlanarViewChoice planar = plot3d.planar_view() ? ops::PlanarViewChoice::kAlways
                                         : plot3d.planar_view_if_two_planes()
                                             ? ops::PlanarViewChoice::kIfTwoPlanes
                                             : ops::PlanarViewChoice::kNever;
    return ops::ReadPlot3dUpload(state_->Ops(), bytes_, read_options, planar,
                                 std::move(grid_memory_));
  }

  // The blocks of a points source, from the coordinates that arrived.
  absl::StatusOr<ops::ImportedSource> BuildPointsSource() {
    ops::ImportedSource source;
    MultiBlockGrid& grid = source.imported.grid;
    const int s = header_.points().spatial_dim();
    for (size_t b = 0; b < extents_.size(); ++b) {
      const int64_t total = BlockValues(b);
      if (static_cast<int64_t>(coords_[b].size()) != total) {
        return absl::InvalidArgumentError(absl::StrCat("points: block ", b, " received ",
                                                       coords_[b].size(), " of its ", total,
                                                       " coordinates"));
      }
      // The block allocates its own coordinates: one copy, then the arrived ones are freed.
      SG_RETURN_IF_ERROR(state_->budget.Extend(&grid_memory_, total * int64_t{sizeof(double)},
                                               "the imported grid"));
      StructuredBlock block(extents_[b], s);
      std::copy(coords_[b].begin(), coords_[b].end(), block.coords().begin());
      const int64_t freed = static_cast<int64_t>(coords_[b].capacity() * sizeof(double));
      coords_[b] = std::vector<double>();
      SG_RETURN_IF_ERROR(state_->budget.Resize(&upload_, upload_.bytes() - freed, "the points"));
      SG_RETURN_IF_ERROR(ValidateFinite(block, absl::StrCat("points: block ", b)));
      grid.blocks.push_back(std::move(block));
    }
    source.imported.format = "points";
    source.memory = std::move(grid_memory_);
    return source;
  }

  // Builds the source from what arrived and hands it to the operation (on the pool).
  absl::Status Complete() override {
    if (!have_header_) return absl::InvalidArgumentError("ImportGrid received no header");
    absl::StatusOr<ops::ImportedSource> source = header_.has_cgns()     ? BuildCgnsSource()
                                                 : header_.has_plot3d() ? BuildPlot3dSource()
                                                                        : BuildPointsSource();
    bytes_ = std::string();
    upload_ = MemoryReservation();
    if (!source.ok()) return source.status();
    const ops::ImportRequest request = {header_.grid_id(), header_.display_name(), caller_.owner(),
                                        Cancel()};
    SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> grid,
                        ops::StoreImported(state_->Ops(), request, *std::move(source)));
    log_.set_grid(absl::StrCat("grids/", grid->id));
    return EncodeGrid(*grid, 0, v1::GRID_VIEW_BASIC, {}, response_);
  }

  v1::Grid* response_;
  bool have_header_ = false;
  v1::ImportHeader header_;
  MemoryReservation upload_;       // what arrived (capacity), charged as it grows
  MemoryReservation grid_memory_;  // the grid being built: the parser's bound, then its size
  std::string bytes_;              // Plot3D or CGNS file
  std::vector<Extents> extents_;   // points source: the header's blocks
  std::vector<std::vector<double>> coords_;  // and their coordinates so far
};

}  // namespace

grpc::ServerReadReactor<Decoded<v1::ImportGridRequest>>* SplineGridService::ImportGridStream(
    grpc::CallbackServerContext* context, v1::Grid* response) {
  return new ImportReactor(state_, context, response);
}

}  // namespace splinegrid::server
