// splinegrid.h: importing, fitting, describing and deleting grids.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>

#include "absl/strings/str_cat.h"
#include "capi/client_state.h"
#include "capi/splinegrid.h"
#include "client/client.h"
#include "core/grid/sampling.h"
#include "core/grid/structured_grid.h"
#include "core/io/file_util.h"
#include "core/util/status_macros.h"

namespace {

namespace client = splinegrid::client;
namespace v1 = splinegrid::v1;
using splinegrid::capi::Guard;
using splinegrid::capi::RequireString;

splinegrid::capi::ClientState* StateOf(sg_client* c) {
  return c == nullptr ? nullptr : c->state.get();
}

// The basic view of `grid` (its source's shape, latest revision).
absl::StatusOr<v1::Grid> GetGrid(sg_client* c, const char* grid) {
  SG_RETURN_IF_ERROR(RequireString(grid, "grid"));
  SG_ASSIGN_OR_RETURN(client::Client * connected, c->state->Connected());
  return connected->Get(client::GridName(grid));
}

// The file name of `path`, as the new grid's display name.
std::string BaseName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

namespace {

// The body of the file imports: reads `path` and uploads it with `upload` (the client, the
// file's bytes, the wanted id), then copies the new grid's id out.
sg_status ImportFile(sg_client* c, const char* path, const char* grid_id, char* id, size_t id_size,
                     const std::function<absl::StatusOr<v1::Grid>(
                         client::Client&, const std::string&, const std::string&)>& upload) {
  if (c == nullptr) return SG_INVALID_ARGUMENT;
  return Guard(StateOf(c), [&]() -> absl::Status {
    SG_RETURN_IF_ERROR(RequireString(path, "path"));
    SG_ASSIGN_OR_RETURN(client::Client * connected, c->state->Connected());
    SG_ASSIGN_OR_RETURN(const std::string bytes, splinegrid::ReadFileToString(path));
    SG_ASSIGN_OR_RETURN(const v1::Grid grid,
                        upload(*connected, bytes, grid_id == nullptr ? "" : grid_id));
    return splinegrid::capi::CopyOut(client::GridId(grid.name()), id, id_size, "id");
  });
}

}  // namespace

extern "C" {

sg_status sg_import_plot3d(sg_client* c, const char* path, const char* grid_id, int32_t planar_view,
                           char* id, size_t id_size) {
  return ImportFile(
      c, path, grid_id, id, id_size,
      [&](client::Client& connected, const std::string& bytes, const std::string& wanted) {
        return connected.ImportPlot3d(bytes, wanted, BaseName(path), planar_view != 0);
      });
}

sg_status sg_import_cgns(sg_client* c, const char* path, const char* grid_id, char* id,
                         size_t id_size) {
  return ImportFile(
      c, path, grid_id, id, id_size,
      [&](client::Client& connected, const std::string& bytes, const std::string& wanted) {
        return connected.ImportCgns(bytes, wanted, BaseName(path));
      });
}

sg_status sg_import_points(sg_client* c, const char* grid_id, int32_t spatial_dim,
                           const int32_t extents[3], const double* points, int64_t count, char* id,
                           size_t id_size) {
  if (c == nullptr) return SG_INVALID_ARGUMENT;
  return Guard(StateOf(c), [&]() -> absl::Status {
    if (spatial_dim != 2 && spatial_dim != 3) {
      return absl::InvalidArgumentError(absl::StrCat("spatial_dim: ", spatial_dim, " (2 or 3)"));
    }
    if (extents == nullptr) return absl::InvalidArgumentError("extents: NULL");
    const splinegrid::Extents e = {extents[0], extents[1], extents[2]};
    SG_RETURN_IF_ERROR(splinegrid::ValidateExtents(e, "extents"));
    const int64_t needed = splinegrid::NumPoints(e) * spatial_dim;
    if (count != needed) {
      return absl::InvalidArgumentError(
          absl::StrCat("count: ", count, " values in points; extents ", e[0], " x ", e[1], " x ",
                       e[2], " with spatial_dim ", spatial_dim, " need ", needed));
    }
    if (points == nullptr) return absl::InvalidArgumentError("points: NULL");
    SG_ASSIGN_OR_RETURN(client::Client * connected, c->state->Connected());
    splinegrid::MultiBlockGrid source;
    source.blocks.emplace_back(e, spatial_dim);
    std::copy(points, points + needed, source.blocks.front().coords().begin());
    SG_RETURN_IF_ERROR(splinegrid::ValidateFinite(source.blocks.front(), "points"));
    const std::string wanted = grid_id == nullptr ? "" : grid_id;
    SG_ASSIGN_OR_RETURN(const v1::Grid grid, connected->ImportPoints(source, wanted, wanted));
    return splinegrid::capi::CopyOut(client::GridId(grid.name()), id, id_size, "id");
  });
}

sg_status sg_fit(sg_client* c, const char* grid, double tolerance, sg_fit_result* result) {
  const sg_fit_options options{tolerance, 0.0};
  return sg_fit_with(c, grid, &options, result);
}

sg_status sg_fit_with(sg_client* c, const char* grid, const sg_fit_options* options,
                      sg_fit_result* result) {
  if (c == nullptr) return SG_INVALID_ARGUMENT;
  return Guard(StateOf(c), [&]() -> absl::Status {
    SG_RETURN_IF_ERROR(RequireString(grid, "grid"));
    const sg_fit_options o = options == nullptr ? sg_fit_options{0.0, 0.0} : *options;
    v1::FitSpec spec;
    if (o.tolerance > 0.0 && std::isfinite(o.tolerance)) {
      spec.set_tolerance(o.tolerance);
    } else if (o.tolerance == 0.0) {
      spec.mutable_boundary_tolerances();  // the defaults by kind
    } else {
      return absl::InvalidArgumentError(
          absl::StrCat("tolerance: ", o.tolerance,
                       " (give a length > 0, or 0 for tolerances by boundary kind)"));
    }
    if (o.first_layer != 0.0) {
      if (o.tolerance != 0.0) {
        return absl::InvalidArgumentError(absl::StrCat(
            "first_layer: ", o.first_layer, " holds with tolerances by kind only (tolerance 0)"));
      }
      // The server names a value outside [0, 1] and a grid without walls.
      spec.mutable_boundary_tolerances()->set_first_layer(o.first_layer);
    }
    SG_ASSIGN_OR_RETURN(client::Client * connected, c->state->Connected());
    SG_ASSIGN_OR_RETURN(const v1::FitGridResponse fit,
                        connected->Fit(client::GridName(grid), spec));
    if (result != nullptr) {
      double first_layer_change = -1.0;
      for (const v1::BlockFitSummary& block : fit.blocks()) {
        if (block.deviation_by_kind().has_first_layer()) {
          first_layer_change =
              std::max(first_layer_change, block.deviation_by_kind().first_layer());
        }
      }
      *result = sg_fit_result{fit.revision(),      fit.num_points(), fit.num_control_points(),
                              fit.max_deviation(), fit.seconds(),    first_layer_change};
    }
    return absl::OkStatus();
  });
}

sg_status sg_grid_info_get(sg_client* c, const char* grid, sg_grid_info* info) {
  if (c == nullptr) return SG_INVALID_ARGUMENT;
  return Guard(StateOf(c), [&]() -> absl::Status {
    if (info == nullptr) return absl::InvalidArgumentError("info: NULL");
    SG_ASSIGN_OR_RETURN(const v1::Grid got, GetGrid(c, grid));
    *info =
        sg_grid_info{got.latest_revision(), got.source().blocks_size(), got.source().spatial_dim()};
    return absl::OkStatus();
  });
}

sg_status sg_block_extents(sg_client* c, const char* grid, int32_t block, int32_t level,
                           int32_t extents[3]) {
  if (c == nullptr) return SG_INVALID_ARGUMENT;
  return Guard(StateOf(c), [&]() -> absl::Status {
    if (extents == nullptr) return absl::InvalidArgumentError("extents: NULL");
    if (level < 0 || level > splinegrid::kMaxRefinementLevel) {
      return absl::InvalidArgumentError(
          absl::StrCat("level: ", level, " (0 to ", splinegrid::kMaxRefinementLevel, ")"));
    }
    SG_ASSIGN_OR_RETURN(const v1::Grid got, GetGrid(c, grid));
    if (block < 0 || block >= got.source().blocks_size()) {
      return absl::InvalidArgumentError(absl::StrCat("block: ", block, " (the grid has ",
                                                     got.source().blocks_size(), " blocks)"));
    }
    const v1::Extents& e = got.source().blocks(block);
    int32_t refined[3];
    const int64_t counts[3] = {e.i(), e.j(), e.k()};
    for (int d = 0; d < 3; ++d) {
      const int64_t n = counts[d] > 1 ? ((counts[d] - 1) << level) + 1 : counts[d];
      if (n > INT32_MAX) {
        return absl::OutOfRangeError(
            absl::StrCat("level: ", level, " gives ", n, " points in direction ", d));
      }
      refined[d] = static_cast<int32_t>(n);
    }
    std::copy(refined, refined + 3, extents);
    return absl::OkStatus();
  });
}

sg_status sg_delete(sg_client* c, const char* grid) {
  if (c == nullptr) return SG_INVALID_ARGUMENT;
  return Guard(StateOf(c), [&]() -> absl::Status {
    SG_RETURN_IF_ERROR(RequireString(grid, "grid"));
    SG_ASSIGN_OR_RETURN(client::Client * connected, c->state->Connected());
    return connected->Delete(client::GridName(grid));
  });
}

}  // extern "C"
