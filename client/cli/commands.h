// The `splinegrid` subcommands. Each takes its positional arguments (after the subcommand) and
// reads the global flags; it prints its result to stdout (human-readable, or JSON with --json)
// and returns the status that decides the exit code.
//
// One file per command or family: serve_command.cc, fit_commands.cc (fit, fair),
// grid_commands.cc (get, list, rm, health), eval_command.cc, curvature_commands.cc (curvature,
// airfoil), deform_command.cc, offset_command.cc, watch_command.cc, archive_commands.cc (export,
// import); the helpers they share are command_util.h, PrepareConnection is command_util.cc.
#ifndef SPLINEGRID_CLIENT_CLI_COMMANDS_H_
#define SPLINEGRID_CLIENT_CLI_COMMANDS_H_

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/cord.h"

namespace splinegrid::cli {

using Args = std::vector<std::string>;

// Exit statuses: 0 success, 1 a failed call (nothing stored), 2 usage (INVALID_ARGUMENT), and
// kExitQualityNotMet when a revision was stored whose quality is not met (folded cells, accepted
// with --allow_folds): fit, fair and offset print its report and exit 3.
inline constexpr int kExitQualityNotMet = 3;
// The payload of a status that names its exit status (ExitCodeOf).
inline constexpr char kExitCodePayload[] = "type.splinegrid.dev/cli.exit_code";

// `status` (not OK) with exit status `code`.
inline absl::Status WithExitCode(absl::Status status, int code) {
  status.SetPayload(kExitCodePayload, absl::Cord(std::to_string(code)));
  return status;
}

// The exit status of a command's status: its payload's, else 0 (OK), 2 (INVALID_ARGUMENT), 1.
inline int ExitCodeOf(const absl::Status& status) {
  if (status.ok()) return 0;
  if (const auto code = status.GetPayload(kExitCodePayload)) {
    if (*code == "3") return kExitQualityNotMet;
  }
  return status.code() == absl::StatusCode::kInvalidArgument ? 2 : 1;
}

// Reads the client commands' --token (or $SPLINEGRID_TOKEN) and --tls_* flags, with the PEM
// files they name; every later client command connects with them. Errors name the flag.
absl::Status PrepareConnection();

absl::Status Serve(const Args& args);
absl::Status Fit(const Args& args);
absl::Status Get(const Args& args);
absl::Status List(const Args& args);
absl::Status Eval(const Args& args);
absl::Status Fair(const Args& args);
absl::Status Curvature(const Args& args);
// Local (no server): fits an airfoil's coordinates (core/fit/airfoil/airfoil_fit.h).
absl::Status Airfoil(const Args& args);
// Rigidly moves part of a grid's boundary (DeformGrid) and prints the new revision's report.
absl::Status Deform(const Args& args);
// Generates an O-grid around an airfoil file's profile (GenerateGrid), prints the report and
// with -o writes the new grid at its original resolution.
absl::Status Offset(const Args& args);
// Prints one line per new revision of a grid (WatchGrid) until interrupted or it is deleted.
absl::Status Watch(const Args& args);
// Writes a grid with its source points and revisions to a .sgrid archive (ExportGrid).
absl::Status Export(const Args& args);
// Creates a grid from a .sgrid archive (ImportArchive), under --name or the archive's id.
absl::Status Import(const Args& args);
absl::Status Remove(const Args& args);
absl::Status Health(const Args& args);

}  // namespace splinegrid::cli

#endif  // SPLINEGRID_CLIENT_CLI_COMMANDS_H_
