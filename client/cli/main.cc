// splinegrid: the command-line tool of the splinegrid service.
//
//   splinegrid COMMAND [ARGUMENTS] [FLAGS]     splinegrid help [COMMAND]     splinegrid --version
//
// The commands, their usage lines and the flags each reads are the table in command_flags.cc;
// `splinegrid help CMD` prints it. The command line is checked against that table before Abseil
// parses the flags (command_line.h), so a flag of another command or a typo is a usage error
// (exit 2) with a suggestion rather than silently ignored.
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/strings/str_cat.h"
#include "client/cli/command_help.h"
#include "client/cli/command_line.h"
#include "client/cli/commands.h"

#ifndef SPLINEGRID_VERSION
#error "SPLINEGRID_VERSION is defined by client/CMakeLists.txt from project(VERSION)"
#endif

int main(int argc, char** argv) {
  using splinegrid::cli::CommandLine;
  absl::SetProgramUsageMessage("splinegrid COMMAND [ARGUMENTS] [FLAGS]; splinegrid help");
  const std::vector<std::string> arguments(argv + 1, argv + argc);
  const absl::StatusOr<CommandLine> line = splinegrid::cli::CheckCommandLine(arguments);
  if (!line.ok()) {
    std::fprintf(stderr, "splinegrid: %s\n", std::string(line.status().message()).c_str());
    return 2;
  }
  switch (line->action) {
    case CommandLine::Action::kHelp: {
      const std::string text = line->command == nullptr
                                   ? splinegrid::cli::OverviewHelp(SPLINEGRID_VERSION)
                                   : splinegrid::cli::CommandHelp(*line->command);
      std::fwrite(text.data(), 1, text.size(), stdout);
      return 0;
    }
    case CommandLine::Action::kVersion:
      std::printf("splinegrid %s\n", SPLINEGRID_VERSION);
      return 0;
    case CommandLine::Action::kRun:
      break;
  }

  if (const absl::Status values = splinegrid::cli::ParseFlagValues(*line); !values.ok()) {
    std::fprintf(stderr, "splinegrid: %s\n", std::string(values.message()).c_str());
    return 2;
  }
  splinegrid::cli::RememberGivenFlags(*line);  // FlagGiven: explicit flags vs defaults
  std::vector<char*> positional = absl::ParseCommandLine(argc, argv);
  using Command = absl::Status (*)(const splinegrid::cli::Args&);
  const std::map<std::string, Command> commands = {
      {"serve", splinegrid::cli::Serve},     {"fit", splinegrid::cli::Fit},
      {"get", splinegrid::cli::Get},         {"list", splinegrid::cli::List},
      {"eval", splinegrid::cli::Eval},       {"rm", splinegrid::cli::Remove},
      {"fair", splinegrid::cli::Fair},       {"curvature", splinegrid::cli::Curvature},
      {"airfoil", splinegrid::cli::Airfoil}, {"health", splinegrid::cli::Health},
      {"deform", splinegrid::cli::Deform},   {"watch", splinegrid::cli::Watch},
      {"offset", splinegrid::cli::Offset},   {"export", splinegrid::cli::Export},
      {"import", splinegrid::cli::Import}};
  // The table (command_flags.cc) and this map name the same commands; a command in the table
  // without a function here is a bug caught by the CLI tests (every command's help and a run).
  const auto command = commands.find(line->command->name);
  if (command == commands.end()) {
    std::fprintf(stderr, "splinegrid: command '%s' has no implementation\n",
                 line->command->name.c_str());
    return 1;
  }
  const splinegrid::cli::Args args(positional.begin() + 2, positional.end());
  absl::Status status =
      line->command->client ? splinegrid::cli::PrepareConnection() : absl::OkStatus();
  if (status.ok()) status = command->second(args);
  if (!status.ok()) {
    // Code and message, without payloads (the exit status is one). A revision stored but not as
    // asked (exit 3) is no failed call: its message alone.
    const int exit_code = splinegrid::cli::ExitCodeOf(status);
    const std::string code = exit_code == splinegrid::cli::kExitQualityNotMet
                                 ? std::string()
                                 : absl::StrCat(absl::StatusCodeToString(status.code()), ": ");
    std::fprintf(stderr, "splinegrid %s: %s%s\n", command->first.c_str(), code.c_str(),
                 std::string(status.message()).c_str());
    return exit_code;
  }
  return 0;
}
