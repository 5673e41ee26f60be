// The command table of the `splinegrid` tool: for each subcommand its usage line, a one-line
// summary and the flags it reads. main.cc checks a command line against it before any flag is
// parsed (command_line.h), and `splinegrid help CMD` prints it (command_help.h).
//
// The flags themselves stay Abseil flags (ABSL_FLAG in flags.cc, read with absl::GetFlag in the
// command files, *_command(s).cc and command_util.cc); this table only says which command reads
// which. When a command starts reading a
// flag, add its name here: cli_tests fails for a flag that is defined but listed for no command,
// and for a listed name that is not a defined flag.
#ifndef SPLINEGRID_CLIENT_CLI_COMMAND_FLAGS_H_
#define SPLINEGRID_CLIENT_CLI_COMMAND_FLAGS_H_

#include <string>
#include <vector>

#include "absl/strings/string_view.h"

namespace splinegrid::cli {

struct CommandSpec {
  std::string name;     // "fit"
  std::string usage;    // after "splinegrid ": "fit FILE [--name N] ..."
  std::string summary;  // one line: what it does
  // Whether it talks to a server: main.cc reads the connection flags (ClientFlags(): --server,
  // --json, TLS ...) for it, and its help lists them.
  bool client = true;
  std::vector<std::string> flags;  // the command's own flags, without the leading "--"
  std::vector<std::string> notes;  // further lines printed by `help CMD`
};

// Every subcommand, in the order `splinegrid help` lists them.
const std::vector<CommandSpec>& Commands();

// The flags every client command takes: connection, security and output.
const std::vector<std::string>& ClientFlags();

// The command named `name`, or nullptr.
const CommandSpec* FindCommand(absl::string_view name);

// The flags `command` accepts: its own, then ClientFlags() when it talks to a server
// (command.client; not serve, not the local airfoil).
std::vector<std::string> AcceptedFlags(const CommandSpec& command);

}  // namespace splinegrid::cli

#endif  // SPLINEGRID_CLIENT_CLI_COMMAND_FLAGS_H_
