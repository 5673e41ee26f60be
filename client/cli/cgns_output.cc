#include "client/cli/cgns_output.h"

#include <cstdio>
#include <filesystem>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/cli/eval_support.h"
#include "core/util/status_macros.h"
#include "io/cgns/cgns_io.h"
#include "proto/convert/archive_convert.h"
#include "proto/convert/convert.h"
#include "proto/convert/source_boundaries_convert.h"

namespace splinegrid::cli {

bool IsCgnsPath(const std::string& path) {
  return std::filesystem::path(path).extension() == ".cgns";
}

absl::StatusOr<CgnsOutputContext> FetchCgnsOutputContext(client::Client& client,
                                                         const v1::EvaluateGridRequest& request) {
  if (request.has_counts() || request.has_index_box()) {
    return absl::InvalidArgumentError(
        "-o *.cgns writes whole blocks at a refinement level (boundary conditions and "
        "connectivity map by index): use --level, not --res or --box");
  }
  if (request.derivatives()) {
    return absl::InvalidArgumentError(
        "-o *.cgns holds grid points only: --derivs has no place in it (write .vts/.vtm)");
  }
  if (Redistributes(request)) {
    return absl::InvalidArgumentError(
        "-o *.cgns maps boundary conditions and connectivity by index at the original "
        "clustering; --dist moves points along block interfaces differently in each block: "
        "write .vts/.vtm/.x instead");
  }
  if (request.refinement_level() > 20) {
    return absl::InvalidArgumentError(
        absl::StrCat("--level ", request.refinement_level(), " is beyond CGNS index ranges"));
  }
  CgnsOutputContext context;
  context.level = request.refinement_level();
  context.single_precision = request.precision() == v1::PRECISION_FLOAT;
  v1::GetGridRequest get;
  get.set_name(request.name());
  get.set_view(v1::GRID_VIEW_BASIC);  // the connectivity and boundaries, not the nets
  if (request.has_step()) {
    get.set_step(request.step());
  } else {
    get.set_revision(request.revision());
  }
  SG_ASSIGN_OR_RETURN(context.grid, client.Get(get));
  return context;
}

absl::StatusOr<int64_t> WriteCgnsOutput(const std::string& out, client::EvaluatedGrid result,
                                        const CgnsOutputContext* context) {
  MultiBlockGrid grid;
  CgnsWriteOptions options;
  int64_t points = 0;
  for (client::EvaluatedBlock& block : result.blocks) {
    options.source_blocks.push_back(block.block);
    points += block.points.num_points();
    grid.blocks.push_back(std::move(block.points));
  }
  if (context != nullptr) {
    const v1::SourceGrid& source = context->grid.source();
    options.index_scale = 1 << context->level;
    options.single_precision = context->single_precision;
    for (const v1::Extents& e : source.blocks()) options.source_extents.push_back(ParseExtents(e));
    SG_ASSIGN_OR_RETURN(
        const SourceBoundaries boundaries,
        ParseSourceBoundaries(source.boundaries(), options.source_extents, "source.boundaries"));
    if (source.connectivity_size() != source.num_matches()) {  // an older server sent none
      return absl::FailedPreconditionError(
          absl::StrCat("-o *.cgns: the server listed ", source.connectivity_size(),
                       " of the grid's ", source.num_matches(),
                       " matched boundary ranges; the file would lack connectivity "
                       "(write .vtm or .x, or update the server)"));
    }
    v1::StoredConnectivity stored;
    *stored.mutable_matches() = source.connectivity();
    SG_ASSIGN_OR_RETURN(
        const Connectivity connectivity,
        ParseStoredConnectivity(stored, options.source_extents, "source.connectivity"));
    options.block_names = boundaries.block_names;
    options.base_name = boundaries.base_name;
    options.data_class = boundaries.data_class;
    options.units = boundaries.units;
    options.conditions = boundaries.conditions;
    options.matches = connectivity.matches;
  }
  std::vector<std::string> notes;
  // A gap of rounding (an interpolating fit's 2e-15) is no news.
  if (context != nullptr && !options.matches.empty() &&
      context->grid.revision().report().max_gap() >
          1e-12 * context->grid.revision().report().reference_length()) {
    // Tolerance fits are watertight (gap 0); a fit to control counts may not be.
    notes.push_back(absl::StrCat(
        "revision ", context->grid.revision().revision(), " leaves its matched boundaries up to ",
        context->grid.revision().report().max_gap(),
        " apart (its report's max_gap); the 1-to-1 connections are written by index, so their "
        "points differ by that much"));
  }
  SG_RETURN_IF_ERROR(WriteCgnsFile(out, grid, options, &notes));
  for (const std::string& note : notes) std::fprintf(stderr, "note: %s\n", note.c_str());
  return points;
}

}  // namespace splinegrid::cli
