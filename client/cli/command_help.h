// The text of `splinegrid help` and `splinegrid help CMD` (also --help, -h), built from the
// command table (command_flags.h) and the flags' own help strings and defaults (ABSL_FLAG in
// flags.cc), so that a flag's default is written in one place only.
#ifndef SPLINEGRID_CLIENT_CLI_COMMAND_HELP_H_
#define SPLINEGRID_CLIENT_CLI_COMMAND_HELP_H_

#include <string>

#include "absl/strings/string_view.h"
#include "client/cli/command_flags.h"

namespace splinegrid::cli {

// Every command with its summary, and how to get more; `version` heads it.
std::string OverviewHelp(absl::string_view version);

// The usage line, summary and notes of `command`, then each flag it accepts with its help text
// and default; the connection flags of a client command in a section of their own.
std::string CommandHelp(const CommandSpec& command);

}  // namespace splinegrid::cli

#endif  // SPLINEGRID_CLIENT_CLI_COMMAND_HELP_H_
