// The command line checked against the command table (command_flags.h) before Abseil parses the
// flags: which command, whether help or the version is asked for, and that every flag given is
// one the command reads. Abseil alone accepts any defined flag with any command and answers
// --help with "No flags matched" (exit 1); this check refuses a foreign or mistyped flag with a
// suggestion instead, so that `list --rotate 10` is an error rather than a silent no-op.
#ifndef SPLINEGRID_CLIENT_CLI_COMMAND_LINE_H_
#define SPLINEGRID_CLIENT_CLI_COMMAND_LINE_H_

#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "client/cli/command_flags.h"

namespace splinegrid::cli {

struct CommandLine {
  enum class Action {
    kRun,      // run `command`
    kHelp,     // print the help of `command`, or the overview when it is null
    kVersion,  // print the version
  };
  Action action = Action::kRun;
  const CommandSpec* command = nullptr;
  // The flags given (kRun), by the name the command reads: --noFLAG and --FLAG=false as FLAG.
  std::vector<std::string> given_flags;
  // The values given with them (`--name=V` or `--name V`; not --noFLAG), by the same names.
  std::vector<std::pair<std::string, std::string>> flag_values;
};

// Checks argv[1..] (the arguments after the program name). `help`, `help CMD`, `--help`, `-h`
// and `CMD --help` ask for help; `--version` for the version. Errors are INVALID_ARGUMENT
// (usage, exit 2) and name the command and the flag: an unknown command or flag with the
// closest known name ("did you mean --level?"), a flag of another command with the commands
// that take it. A flag's value given as the next argument (`--name N`) is skipped; only bool
// flags stand alone (Abseil's rule).
absl::StatusOr<CommandLine> CheckCommandLine(const std::vector<std::string>& args);

// Parses every value of line.flag_values into its flag, as Abseil will: INVALID_ARGUMENT (usage,
// exit 2) naming the flag, the value and what it takes ("--timeout = '2' is not a valid value:
// give a duration with its unit (30s, 500ms, 2m)"). Abseil's own parse prints its error and
// exits 1.
absl::Status ParseFlagValues(const CommandLine& line);

// Records line.given_flags for FlagGiven (main.cc, once, before the command runs).
void RememberGivenFlags(const CommandLine& line);

// Whether flag `name` was written on this process's command line, in any spelling (--planar,
// --planar=true, --noplanar), per RememberGivenFlags. For flags whose value cannot tell a
// default from an explicit choice: `fit x.cgns --planar` (default true) is refused as a flag
// CGNS ignores, while the default is not.
bool FlagGiven(absl::string_view name);

// Edit distance of `a` and `b`: insertions, deletions, substitutions and swaps of two
// neighbouring characters ("nmae" is one edit from "name"), each substring edited once.
int EditDistance(absl::string_view a, absl::string_view b);

// The candidate closest to `typed` by EditDistance when it is close enough to be a typo (at
// most one edit in three characters, at least one), else "".
std::string ClosestName(absl::string_view typed, const std::vector<std::string>& candidates);

}  // namespace splinegrid::cli

#endif  // SPLINEGRID_CLIENT_CLI_COMMAND_LINE_H_
