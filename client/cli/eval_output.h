// Writing `splinegrid eval` results: VTK (.vts/.vtm) with optional fields, Plot3D written back
// in the layout of the grid's source file with derivatives in a function file beside it, and
// ParaView time series (.pvd) of deformed revisions. grid_output.h dispatches here (eval and
// offset), CGNS aside.
#ifndef SPLINEGRID_CLIENT_CLI_EVAL_OUTPUT_H_
#define SPLINEGRID_CLIENT_CLI_EVAL_OUTPUT_H_

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "client/client.h"
#include "core/grid/structured_grid.h"
#include "core/io/plot3d_source_format.h"
#include "splinegrid/v1/grid.pb.h"

namespace splinegrid::cli {

// What the output needs to know about the evaluated grid (from GetGrid).
struct EvalGridFacts {
  // How the source Plot3D file was laid out (Plot3D imports; absent for others or old stores).
  std::optional<Plot3dSourceFormat> plot3d;
  // Parametric dimension of every block of the revision (directions with more than one control
  // point): 3 volume, 2 surface/planar, 1 curve. Missing blocks are judged by their extents.
  std::map<int, int> parametric_dim;
  // The stored source points (for the deviation field); empty unless asked for.
  MultiBlockGrid source;
};

// The facts of `grid` (a GetGrid answer with its revision, BASIC view). INVALID_ARGUMENT when
// its Plot3D format is damaged.
absl::StatusOr<EvalGridFacts> EvalFactsFromGrid(const v1::Grid& grid);

// Which optional VTK fields and storage to write.
struct EvalOutputOptions {
  bool derivatives = false;  // dX_du, dX_dv[, dX_dw] (only directions the block has)
  bool jacobian = false;     // point field "jacobian" (needs the derivatives in the result)
  bool quality = false;      // cell field "scaled_jacobian"
  bool deviation = false;    // point field "deviation" (needs facts.source; level 0 only)
  bool compress = true;      // zlib in VTK XML files
};

// The Plot3D function file beside grid file `grid_path`: its extension replaced by ".f"
// ("out/wing.x" -> "out/wing.f").
std::string FunctionFilePath(const std::string& grid_path);

// Writes `result` to `out` (.vts, .vtm, .x or .xyz; see the README). VTK: block files and names
// carry the blocks' indices in the grid; fields as `options` say. Plot3D: in the source's
// layout when `facts.plot3d` is known (ToPlot3dSourceForm), else the default; with
// options.derivatives the function file FunctionFilePath(out) too. Returns the number of points
// written. INVALID_ARGUMENT for VTK-only fields with a Plot3D file, a deviation without source
// points or at another resolution, and whatever the writers refuse. Takes `result` by value and
// moves its blocks into the written grid (pass it with std::move).
absl::StatusOr<int64_t> WriteEvaluation(const std::string& out, client::EvaluatedGrid result,
                                        const EvalGridFacts& facts,
                                        const EvalOutputOptions& options);

// One time step of a series: a deformed revision.
struct SeriesStep {
  int64_t step = 0;
  double time = 0.0;
  int64_t revision = 0;
};

// Writes the steps as `pvd` (which ends in ".pvd", say out/run.pvd): out/run/run_<step>.vts
// (one block) or .vtm, and the .pvd listing them with TimeValue = each revision's time. When
// times repeat (revisions deformed without --time), the steps are used as TimeValue and
// `*note` says so. Each step is evaluated by `evaluate` and written before the next is asked
// for, so a series takes the memory of one step however many it has. Returns the points
// written over all steps.
absl::StatusOr<int64_t> WriteSeries(
    const std::string& pvd, const std::vector<SeriesStep>& steps,
    const std::function<absl::StatusOr<client::EvaluatedGrid>(const SeriesStep&)>& evaluate,
    const EvalGridFacts& facts, const EvalOutputOptions& options, std::string* note);

}  // namespace splinegrid::cli

#endif  // SPLINEGRID_CLIENT_CLI_EVAL_OUTPUT_H_
