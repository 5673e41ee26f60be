#include "client/cli/command_line.h"

#include <algorithm>
#include <optional>

#include "absl/flags/reflection.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/time/time.h"

namespace splinegrid::cli {
namespace {

// A flag as written: its name without dashes and "=value".
struct GivenFlag {
  std::string name;
  std::string spelled;               // as typed, for messages ("-o", "--levl")
  std::optional<std::string> value;  // after '=' or as the next argument
};

bool IsBoolFlag(absl::string_view name) {
  const absl::CommandLineFlag* flag = absl::FindCommandLineFlag(name);
  return flag != nullptr && flag->IsOfType<bool>();
}

bool Contains(const std::vector<std::string>& names, absl::string_view name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

// The name the command reads `given` as: itself, or for --noFLAG of a bool flag, FLAG.
std::optional<std::string> AcceptedName(const std::string& given,
                                        const std::vector<std::string>& accepted) {
  if (Contains(accepted, given)) return given;
  if (absl::StartsWith(given, "no") && Contains(accepted, given.substr(2)) &&
      IsBoolFlag(given.substr(2))) {
    return given.substr(2);
  }
  return std::nullopt;
}

// The commands other than `command` that read `name` (or, as --noNAME, the bool flag NAME).
std::vector<std::string> OwnersOf(const std::string& name, const CommandSpec& command) {
  std::vector<std::string> owners;
  for (const CommandSpec& other : Commands()) {
    if (&other != &command && AcceptedName(name, AcceptedFlags(other))) {
      owners.push_back(other.name);
    }
  }
  return owners;
}

absl::Status ForeignOrUnknownFlag(const GivenFlag& flag, const CommandSpec& command) {
  const std::string help = absl::StrCat(" (splinegrid help ", command.name, " lists its flags)");
  const std::vector<std::string> owners = OwnersOf(flag.name, command);
  if (!owners.empty()) {
    // A connection flag belongs to every client command: name the group, not fifteen commands.
    std::string whose = absl::StrJoin(owners, ", ");
    if (Contains(ClientFlags(), flag.name)) {
      whose = Contains(owners, "serve") ? "the commands that talk to a server, and serve"
                                        : "the commands that talk to a server";
    }
    return absl::InvalidArgumentError(absl::StrCat(flag.spelled, " is not a flag of ", command.name,
                                                   "; it belongs to ", whose, help));
  }
  std::string message = absl::StrCat("unknown flag ", flag.spelled, " for ", command.name);
  if (const std::string close = ClosestName(flag.name, AcceptedFlags(command)); !close.empty()) {
    absl::StrAppend(&message, "; did you mean --", close, "?");
  }
  return absl::InvalidArgumentError(absl::StrCat(message, help));
}

std::vector<std::string> CommandNames() {
  std::vector<std::string> names;
  for (const CommandSpec& command : Commands()) names.push_back(command.name);
  return names;
}

absl::StatusOr<const CommandSpec*> Command(const std::string& name) {
  if (const CommandSpec* command = FindCommand(name)) return command;
  std::string message = absl::StrCat("unknown command '", name, "'");
  if (const std::string close = ClosestName(name, CommandNames()); !close.empty()) {
    absl::StrAppend(&message, "; did you mean ", close, "?");
  }
  return absl::InvalidArgumentError(absl::StrCat(message, " (splinegrid help lists them)"));
}

}  // namespace

int EditDistance(absl::string_view a, absl::string_view b) {
  // The optimal string alignment distance (Damerau-Levenshtein, each substring edited once):
  // d[i][j] of a's first i and b's first j characters, O(|a| |b|); names are short.
  std::vector<std::vector<int>> d(a.size() + 1, std::vector<int>(b.size() + 1));
  for (size_t i = 0; i <= a.size(); ++i) d[i][0] = static_cast<int>(i);
  for (size_t j = 0; j <= b.size(); ++j) d[0][j] = static_cast<int>(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    for (size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min(
          {d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);  // two neighbours swapped
      }
    }
  }
  return d[a.size()][b.size()];
}

std::string ClosestName(absl::string_view typed, const std::vector<std::string>& candidates) {
  const int limit = std::max<int>(1, static_cast<int>(typed.size()) / 3);
  std::string best;
  int best_distance = limit + 1;
  for (const std::string& candidate : candidates) {
    const int distance = EditDistance(typed, candidate);
    if (distance < best_distance) {
      best = candidate;
      best_distance = distance;
    }
  }
  return best;
}

absl::StatusOr<CommandLine> CheckCommandLine(const std::vector<std::string>& args) {
  std::vector<std::string> positional;
  std::vector<GivenFlag> flags;
  bool help = false;
  bool version = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--") {  // the rest is positional (Abseil's rule)
      positional.insert(positional.end(), args.begin() + i + 1, args.end());
      break;
    }
    if (arg.size() < 2 || arg[0] != '-') {
      positional.push_back(arg);
      continue;
    }
    const absl::string_view body = absl::string_view(arg).substr(arg[1] == '-' ? 2 : 1);
    const size_t equals = body.find('=');
    const std::string name(body.substr(0, equals));
    if (name == "help" || name == "h" || name == "helpfull") {
      help = true;
      continue;
    }
    if (name == "version") {
      version = true;
      continue;
    }
    GivenFlag& flag =
        flags.emplace_back(GivenFlag{name, std::string(arg.substr(0, arg.find('=')))});
    if (equals != absl::string_view::npos) flag.value = std::string(body.substr(equals + 1));
    // `--name VALUE`: the next argument is the value, except for bool flags (and --noFLAG).
    const bool stands_alone = IsBoolFlag(name) || (absl::StartsWith(name, "no") &&
                                                   IsBoolFlag(absl::string_view(name).substr(2)));
    if (equals == absl::string_view::npos && !stands_alone &&
        absl::FindCommandLineFlag(name) != nullptr && i + 1 < args.size()) {
      flag.value = args[++i];
    }
  }

  CommandLine line;
  if (!positional.empty() && positional[0] == "help") {
    line.action = CommandLine::Action::kHelp;
    if (positional.size() > 2) {
      return absl::InvalidArgumentError("usage: splinegrid help [COMMAND]");
    }
    if (positional.size() == 2) {
      auto command = Command(positional[1]);
      if (!command.ok()) return command.status();
      line.command = *command;
    }
    return line;
  }
  if (help) {
    line.action = CommandLine::Action::kHelp;
    if (!positional.empty()) {
      auto command = Command(positional[0]);
      if (!command.ok()) return command.status();
      line.command = *command;
    }
    return line;
  }
  if (version) {
    line.action = CommandLine::Action::kVersion;
    return line;
  }
  if (positional.empty()) {
    return absl::InvalidArgumentError("no command given (splinegrid help lists them)");
  }
  auto command = Command(positional[0]);
  if (!command.ok()) return command.status();
  line.command = *command;
  const std::vector<std::string> accepted = AcceptedFlags(**command);
  for (const GivenFlag& flag : flags) {
    const std::optional<std::string> name = AcceptedName(flag.name, accepted);
    if (!name) return ForeignOrUnknownFlag(flag, **command);
    line.given_flags.push_back(*name);
    if (flag.value && *name == flag.name) line.flag_values.emplace_back(*name, *flag.value);
  }
  return line;
}

absl::Status ParseFlagValues(const CommandLine& line) {
  for (const auto& [name, value] : line.flag_values) {
    absl::CommandLineFlag* flag = absl::FindCommandLineFlag(name);
    std::string error;
    if (flag == nullptr || flag->ParseFrom(value, &error)) continue;
    std::string expected;
    if (flag->IsOfType<absl::Duration>()) {
      expected = "give a duration with its unit (30s, 500ms, 2m)";
    } else if (flag->IsOfType<int>() || flag->IsOfType<int64_t>() ||
               flag->IsOfType<std::optional<int>>() || flag->IsOfType<std::optional<int64_t>>()) {
      expected = "give an integer";
    } else if (flag->IsOfType<double>() || flag->IsOfType<std::optional<double>>()) {
      expected = "give a number";
    } else if (flag->IsOfType<bool>() || flag->IsOfType<std::optional<bool>>()) {
      expected = "give true or false";
    }
    return absl::InvalidArgumentError(
        absl::StrCat("--", name, " = '", value,
                     "' is not a valid value: ", expected.empty() ? error : expected));
  }
  return absl::OkStatus();
}

namespace {

// The names RememberGivenFlags recorded (main.cc sets them once, before any thread starts).
std::vector<std::string>& GivenFlagNames() {
  static std::vector<std::string>* const names = new std::vector<std::string>();
  return *names;
}

}  // namespace

void RememberGivenFlags(const CommandLine& line) { GivenFlagNames() = line.given_flags; }

bool FlagGiven(absl::string_view name) { return Contains(GivenFlagNames(), name); }

}  // namespace splinegrid::cli
