// The helpers shared by several `splinegrid` subcommands (one command's own stay in its file).
// Usage errors, the connection, printing a result as text or JSON, and the flags more than one
// command reads: the fit flags of fit and offset, --fair, --revision/--step, a size triple.
#ifndef SPLINEGRID_CLIENT_CLI_COMMAND_UTIL_H_
#define SPLINEGRID_CLIENT_CLI_COMMAND_UTIL_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "absl/flags/flag.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "client/cli/flags.h"
#include "client/client.h"
#include "core/grid/structured_grid.h"
#include "google/protobuf/message.h"
#include "splinegrid/v1/splinegrid_service.pb.h"

namespace splinegrid::cli {

// INVALID_ARGUMENT with `message` (exit status 2).
absl::Status Usage(const std::string& message);

// The server to talk to: --server, else $SPLINEGRID_SERVER (what deploy/local/start.sh
// prints), else localhost:50051.
std::string ServerAddress();

// A client for ServerAddress() with --timeout and the token and TLS settings of
// PrepareConnection; calls that break off are retried under `retry` (default: the client's).
std::unique_ptr<client::Client> Connect(const client::RetryPolicy& retry = {});
// The same for an evaluation written to a file whose writer holds `output_copies` copies of
// the values at its peak (OutputCopies in grid_output.h): the client refuses, at the
// evaluation's header, one whose copies would not fit in --max_memory_mb, by default three
// quarters of the memory available to this process (MemAvailable, or what its cgroup has left
// under its limit if lower).
std::unique_ptr<client::Client> ConnectForEvaluation(double output_copies);

// Prints `human`, or with --json `message` as JSON, to stdout.
void Print(const std::string& human, const google::protobuf::Message& message);

// --level when given (refused below 0, which is no level), else nullopt.
absl::StatusOr<std::optional<int>> LevelFlag();

// --res: "400,120" -> {400, 120, 1}. Each given count is at least 1; missing ones are 1.
absl::StatusOr<Extents> ResolutionFlag();

// "24,16" -> {24, 16, 0}; `what` names the flag in errors.
absl::StatusOr<Extents> ParseTriple(const std::string& text, const std::string& what);

// --revision or --step (not both) into a request.
template <typename SetRevision, typename SetStep>
absl::Status RevisionOrStep(const SetRevision& set_revision, const SetStep& set_step) {
  const std::optional<int64_t> step = absl::GetFlag(FLAGS_step);
  if (step.has_value()) {
    if (absl::GetFlag(FLAGS_revision) != 0) return Usage("give --revision or --step, not both");
    set_step(*step);
  } else {
    set_revision(absl::GetFlag(FLAGS_revision));
  }
  return absl::OkStatus();
}

// A grid id from a file name: lower case, [a-z0-9-], starting with a letter.
std::string IdFromPath(const std::string& path);

// The grid id --name asks for ("grids/ID" or "ID"), "" when it is not given; INVALID_ARGUMENT
// naming --name and its value when the id is not valid, before any file is read or sent.
absl::StatusOr<std::string> NameFlagId();

// --fair: "" (none), "tol" (to tolerance) or a weight.
absl::StatusOr<std::optional<v1::Fairing>> ParseFairFlag();

// The FitSpec of the fit flags.
absl::StatusOr<v1::FitSpec> SpecFromFlags();

// After a stored fit: FAILED_PRECONDITION with exit status kExitQualityNotMet (3) when the
// server stored a revision that is not what was asked: its cells fold (--allow_folds let it), or
// it misses its tolerances (a control cap held it back), so that a script cannot mistake it for
// a good grid, nor for a call that failed (1).
absl::Status StoredNotAsAsked(const std::string& name, const v1::FitGridResponse& fit);

}  // namespace splinegrid::cli

#endif  // SPLINEGRID_CLIENT_CLI_COMMAND_UTIL_H_
