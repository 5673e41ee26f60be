// `eval -o FILE.cgns`: an evaluated grid as CGNS with the grid's boundary conditions (from its
// CGNS import) and 1-to-1 connectivity (the matches found at import), at the evaluation's
// refinement level: source index i is written as i * 2^level.
#ifndef SPLINEGRID_CLIENT_CLI_CGNS_OUTPUT_H_
#define SPLINEGRID_CLIENT_CLI_CGNS_OUTPUT_H_

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "client/client.h"

namespace splinegrid::cli {

// True for a path ending in .cgns.
bool IsCgnsPath(const std::string& path);

// What the file carries besides points: the grid's FULL view (source extents, boundaries and
// connectivity) and the level of the evaluation.
struct CgnsOutputContext {
  int level = 0;
  bool single_precision = false;
  v1::Grid grid;
};

// INVALID_ARGUMENT unless `request` evaluates whole blocks at a refinement level without
// derivatives (a CGNS grid file holds points, and BCs need the level's index mapping); then
// fetches the grid's source description.
absl::StatusOr<CgnsOutputContext> FetchCgnsOutputContext(client::Client& client,
                                                         const v1::EvaluateGridRequest& request);

// Writes `result` to `out`; with a context also the boundary conditions and 1-to-1 connections
// of the written blocks (what cannot be written, e.g. hanging-node matches, is printed as a
// note on stderr). Returns the number of points written. Takes `result` by value and moves its
// blocks into the written grid (pass it with std::move: an evaluation can be gigabytes).
absl::StatusOr<int64_t> WriteCgnsOutput(const std::string& out, client::EvaluatedGrid result,
                                        const CgnsOutputContext* context);

}  // namespace splinegrid::cli

#endif  // SPLINEGRID_CLIENT_CLI_CGNS_OUTPUT_H_
