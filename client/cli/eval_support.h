// The parts of `splinegrid eval` around the evaluation: output options from the flags, what
// the output needs to know about the grid (GetGrid, and the source points for --deviation),
// and the ParaView time series of --steps.
#ifndef SPLINEGRID_CLIENT_CLI_EVAL_SUPPORT_H_
#define SPLINEGRID_CLIENT_CLI_EVAL_SUPPORT_H_

#include <string>

#include "absl/status/statusor.h"
#include "client/cli/eval_output.h"
#include "client/client.h"
#include "splinegrid/v1/splinegrid_service.pb.h"

namespace splinegrid::cli {

// Whether `out` asks for a time series (ends in .pvd).
bool IsSeriesPath(const std::string& out);

// --dist DIR=KIND[,...] (see the flag's help) into request->distributions; INVALID_ARGUMENT
// naming the part that is not understood. The server checks the rest (one measured direction,
// spacings against the lines' lengths).
absl::Status ParseDistributionFlag(const std::string& text, v1::EvaluateGridRequest* request);

// Whether `request` asks for another distribution than the original clustering in some
// direction (--dist with a kind other than original).
bool Redistributes(const v1::EvaluateGridRequest& request);

// The output options of --derivs, --jacobian, --quality, --deviation and --compress; sets
// request->derivatives when the derivatives or the Jacobian need them. INVALID_ARGUMENT, before
// any call, for VTK fields or an explicit --compress/--nocompress with a file that is not VTK,
// --deviation other than at --level 0 without --box, and --steps without a .pvd -o (or a .pvd
// without --steps).
absl::StatusOr<EvalOutputOptions> EvalOutputOptionsFromFlags(const std::string& out,
                                                             v1::EvaluateGridRequest* request);

// What the output of `request` needs to know about the grid: one GetGrid (BASIC view) of the
// requested revision or step, and with options.deviation the stored source points (fetched
// with ExportGrid into a temporary file, read up to the source, removed).
absl::StatusOr<EvalGridFacts> FetchEvalFacts(client::Client& client,
                                             const v1::EvaluateGridRequest& request,
                                             const EvalOutputOptions& options);

// --steps a:b -o NAME.pvd: evaluates the latest deformed revision of every time step from a to
// b (as --step does) and writes the series (WriteSeries). Steps without a deformed revision are
// skipped and named in the returned summary; none at all is NOT_FOUND. Returns the line to
// print.
absl::StatusOr<std::string> RunEvalSeries(client::Client& client, v1::EvaluateGridRequest request,
                                          const std::string& out, const EvalGridFacts& facts,
                                          const EvalOutputOptions& options);

}  // namespace splinegrid::cli

#endif  // SPLINEGRID_CLIENT_CLI_EVAL_SUPPORT_H_
