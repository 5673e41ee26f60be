// SplineGridService::ImportGrid: a client stream of a header and then Plot3D or CGNS bytes, or
// points. CGNS files are decoded in a child process (server/cgns_decoder.h).
// Data are appended on gRPC's thread (copies only); parsing and validation run on the pool.
// Memory is allocated and charged to the budget as data arrive, never from the header's
// announced sizes; a stream that sends nothing for --import_idle_timeout is ended.
#include <algorithm>
#include <optional>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/planar_view.h"
#include "core/io/plot3d.h"
#include "core/io/plot3d_memory.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"
#include "proto/convert/plot3d_format_convert.h"
#include "server/cgns_decoder.h"
#include "server/grid_encoding.h"
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

  // Decodes a CGNS upload in a child process (on the pool); its boundaries go to `boundaries`
  // and its stated 1-to-1 connections to connections_ (compared with the found ones in Store).
  absl::StatusOr<MultiBlockGrid> BuildCgnsSource(std::string* format,
                                                 SourceBoundaries* boundaries) {
    if (static_cast<int64_t>(bytes_.size()) != header_.cgns().total_bytes()) {
      return absl::InvalidArgumentError(absl::StrCat("cgns: ", bytes_.size(),
                                                     " bytes arrived but the header announced ",
                                                     header_.cgns().total_bytes()));
    }
    SG_ASSIGN_OR_RETURN(
        ImportedGrid imported,
        DecodeCgnsUpload(bytes_, state_->options.cgns_decoder, &state_->budget, &grid_memory_,
                         [this] { return context_->IsCancelled(); }));
    bytes_ = std::string();
    SG_RETURN_IF_ERROR(
        state_->budget.Resize(&grid_memory_, SourceBytes(imported.grid), "the imported grid"));
    *format = std::move(imported.format);
    *boundaries = std::move(imported.boundaries);
    connections_ = std::move(imported.connections);
    return std::move(imported.grid);
  }

  // Builds the source grid from what arrived (on the pool).
  absl::StatusOr<MultiBlockGrid> BuildSource(std::string* format, SourceBoundaries* boundaries) {
    if (!have_header_) return absl::InvalidArgumentError("ImportGrid received no header");
    if (header_.has_cgns()) return BuildCgnsSource(format, boundaries);
    if (header_.has_plot3d()) {
      if (static_cast<int64_t>(bytes_.size()) != header_.plot3d().total_bytes()) {
        return absl::InvalidArgumentError(absl::StrCat("plot3d: ", bytes_.size(),
                                                       " bytes arrived but the header announced ",
                                                       header_.plot3d().total_bytes()));
      }
      Plot3dFormat detected;
      // The parser's memory, bounded from the bytes before it allocates (text repeats "n*x"
      // make a few bytes stand for gigabytes); then exactly the grid's.
      SG_RETURN_IF_ERROR(state_->budget.Resize(&grid_memory_, Plot3dParseBytesBound(bytes_),
                                               "parsing the Plot3D upload"));
      Plot3dReadOptions read_options;
      read_options.layout = Plot3dLayoutFromProto(header_.plot3d().layout());
      SG_ASSIGN_OR_RETURN(MultiBlockGrid grid,
                          ParsePlot3d(bytes_, "upload", read_options, &detected));
      SG_RETURN_IF_ERROR(
          state_->budget.Resize(&grid_memory_, SourceBytes(grid), "the imported grid"));
      *format = absl::StrCat("plot3d ", DescribePlot3dFormat(detected));
      plot3d_format_.emplace().file = detected;  // kept so evaluations can be written back alike
      if (header_.plot3d().planar_view() ||
          (header_.plot3d().planar_view_if_two_planes() && IsTwoPlaneGrid(grid))) {
        SG_RETURN_IF_ERROR(
            state_->budget.Resize(&grid_memory_, 2 * SourceBytes(grid), "the planar view"));
        SG_ASSIGN_OR_RETURN(grid, PlanarView(grid, {}, &plot3d_format_->two_planes));
        absl::StrAppend(format, ", planar view");
      }
      return grid;
    }
    MultiBlockGrid grid;
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
    *format = "points";
    return grid;
  }

  absl::Status Store() {
    auto source = std::make_shared<SourcePoints>();
    SG_ASSIGN_OR_RETURN(source->grid, BuildSource(&source->format, &source->boundaries));
    source->plot3d = std::move(plot3d_format_);
    bytes_ = std::string();
    if (source->grid.blocks.empty()) return absl::InvalidArgumentError("the grid has no blocks");
    // A grid that cannot be fitted (all points equal, a direction of zero length, cells of no
    // area or volume) is refused here, naming the block, not stored for every fit to fail.
    for (size_t b = 0; b < source->grid.blocks.size(); ++b) {
      SG_RETURN_IF_ERROR(ValidateFittable(source->grid.blocks[b], absl::StrCat("block ", b)));
    }
    upload_ = MemoryReservation();
    SG_RETURN_IF_ERROR(
        state_->budget.Resize(&grid_memory_, SourceBytes(source->grid), "the imported grid"));
    source->memory = std::move(grid_memory_);
    SG_ASSIGN_OR_RETURN(source->connectivity, FindConnectivity(source->grid));
    for (std::string& note :
         CompareConnections(connections_, source->connectivity, source->boundaries.block_names)) {
      source->boundaries.notes.push_back(std::move(note));
    }
    auto grid = std::make_shared<StoredGrid>();
    grid->display_name = header_.display_name();
    grid->owner = caller_.owner();
    grid->create_time = absl::Now();
    grid->source = std::move(source);
    SG_RETURN_IF_ERROR(CreateGrid(*state_->store, header_.grid_id(), grid));
    log_.set_grid(absl::StrCat("grids/", grid->id));
    return EncodeGrid(*grid, 0, v1::GRID_VIEW_BASIC, {}, response_);
  }

  absl::Status Complete() override { return Store(); }

  v1::Grid* response_;
  bool have_header_ = false;
  v1::ImportHeader header_;
  MemoryReservation upload_;       // what arrived (capacity), charged as it grows
  MemoryReservation grid_memory_;  // the grid being built: the parser's bound, then its size
  std::string bytes_;              // Plot3D or CGNS file
  std::optional<Plot3dSourceFormat> plot3d_format_;  // Plot3D source: its layout, once parsed
  std::vector<Extents> extents_;                     // points source: the header's blocks
  std::vector<std::vector<double>> coords_;          // and their coordinates so far
  std::vector<StatedConnection> connections_;        // CGNS source: the file's 1-to-1 connections
};

}  // namespace

grpc::ServerReadReactor<Decoded<v1::ImportGridRequest>>* SplineGridService::ImportGridStream(
    grpc::CallbackServerContext* context, v1::Grid* response) {
  return new ImportReactor(state_, context, response);
}

}  // namespace splinegrid::server
