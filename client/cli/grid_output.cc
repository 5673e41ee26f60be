#include "client/cli/grid_output.h"

#include <filesystem>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/cli/cgns_output.h"
#include "core/io/plot3d.h"
#include "core/io/vtk.h"
#include "core/util/status_macros.h"

namespace splinegrid::cli {

absl::Status CheckGridOutput(const std::string& out) {
  const std::string ext = std::filesystem::path(out).extension().string();
  if (ext != ".vts" && ext != ".vtm" && ext != ".x" && ext != ".xyz" && ext != ".cgns") {
    return absl::InvalidArgumentError(
        absl::StrCat("-o ", out, ": the extension must be .vts, .vtm, .x, .xyz or .cgns"));
  }
  return absl::OkStatus();
}

absl::StatusOr<int64_t> WriteEvaluatedGrid(const std::string& out,
                                           const client::EvaluatedGrid& result) {
  const std::string ext = std::filesystem::path(out).extension().string();
  // Points only (eval passes its grid's boundary conditions to WriteCgnsOutput itself).
  if (ext == ".cgns") return WriteCgnsOutput(out, result, nullptr);
  MultiBlockGrid grid;
  std::vector<std::vector<VtkPointArray>> arrays;
  int64_t points = 0;
  for (const client::EvaluatedBlock& block : result.blocks) {
    points += block.points.num_points();
    std::vector<VtkPointArray> fields;
    if (!block.du.empty()) {
      const int s = block.points.spatial_dim();
      fields = {{"dX_du", s, block.du}, {"dX_dv", s, block.dv}, {"dX_dw", s, block.dw}};
    }
    arrays.push_back(std::move(fields));
    grid.blocks.push_back(block.points);
  }
  if (ext == ".vts") {
    if (grid.blocks.size() != 1) {
      return absl::InvalidArgumentError(
          absl::StrCat(grid.blocks.size(), " blocks: write .vtm, or choose one with --block"));
    }
    SG_RETURN_IF_ERROR(WriteVts(out, grid.blocks[0], arrays[0]));
  } else if (ext == ".vtm") {
    SG_RETURN_IF_ERROR(WriteVtm(out, grid, arrays));
  } else {
    SG_RETURN_IF_ERROR(
        WritePlot3dFile(out, grid,
                        DefaultPlot3dFormat(grid, ext == ".x" ? Plot3dEncoding::kBinaryLittleEndian
                                                              : Plot3dEncoding::kAscii)));
  }
  return points;
}

}  // namespace splinegrid::cli
