// Writing evaluated grids to files for `splinegrid eval` and `offset`: the file format follows
// the extension of -o.
#ifndef SPLINEGRID_CLIENT_CLI_GRID_OUTPUT_H_
#define SPLINEGRID_CLIENT_CLI_GRID_OUTPUT_H_

#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "client/client.h"

namespace splinegrid::cli {

// OK when `out` has an extension WriteEvaluatedGrid writes; INVALID_ARGUMENT naming it otherwise.
// Checked before any call, so a bad -o fails before the work is done.
absl::Status CheckGridOutput(const std::string& out);

// Writes an evaluation to `out` (VTK .vts for one block or .vtm, binary .x or text .xyz
// Plot3D); returns the number of points written.
absl::StatusOr<int64_t> WriteEvaluatedGrid(const std::string& out,
                                           const client::EvaluatedGrid& result);

}  // namespace splinegrid::cli

#endif  // SPLINEGRID_CLIENT_CLI_GRID_OUTPUT_H_
