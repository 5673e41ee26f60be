// Where `splinegrid eval` and `offset` write an evaluated grid: the one check of -o's extension
// and the one dispatch by it, to the CGNS writer (cgns_output.h) or to the VTK and Plot3D writers
// (eval_output.h). A .pvd time series is eval's own (WriteSeries).
#ifndef SPLINEGRID_CLIENT_CLI_GRID_OUTPUT_H_
#define SPLINEGRID_CLIENT_CLI_GRID_OUTPUT_H_

#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "client/cli/cgns_output.h"
#include "client/cli/eval_output.h"
#include "client/client.h"

namespace splinegrid::cli {

// OK when `out` ends in an extension WriteGridOutput writes (.vts, .vtm, .x, .xyz, .cgns) and
// its directory exists; INVALID_ARGUMENT (extension) or NOT_FOUND (directory) naming it
// otherwise. Checked before any call, so a bad -o fails before the work is done. `also` is
// appended to the list of extensions in the message (eval: ", or .pvd with --steps A:B").
absl::Status CheckGridOutput(const std::string& out, absl::string_view also = "");

// How many copies of an evaluation's values writing `out` holds at its peak, the received
// values included: the writers convert whole blocks before they write. Measured (peak RSS over
// the values, RAE 2822 at 3000 x 3000 and level 4): .cgns 2.0, .vts/.vtm 4.2-4.6 compressed
// and 6.0 with `compress` off, .x 6.3, .xyz 8.8; rounded up here.
double OutputCopies(const std::string& out, bool compress);

// `status` with what writing `out` holds appended when it is the client's refusal of an
// evaluation too large to hold here (ConnectForEvaluation); anything else unchanged.
absl::Status ExplainEvaluationLimit(absl::Status status, const std::string& out, bool compress);

// Writes `result` to `out` by its extension: .cgns with WriteCgnsOutput (boundary conditions and
// connectivity from `cgns`, points only when it is null), the others with WriteEvaluation
// (`facts` and `options`; empty facts: the default Plot3D layout, parametric dimensions from the
// blocks' extents). Returns the number of points written. Takes `result` by value and moves
// its blocks into the writer (pass it with std::move).
absl::StatusOr<int64_t> WriteGridOutput(const std::string& out, client::EvaluatedGrid result,
                                        const EvalGridFacts& facts,
                                        const EvalOutputOptions& options,
                                        const CgnsOutputContext* cgns);

}  // namespace splinegrid::cli

#endif  // SPLINEGRID_CLIENT_CLI_GRID_OUTPUT_H_
