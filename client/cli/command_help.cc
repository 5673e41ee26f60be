#include "client/cli/command_help.h"

#include <algorithm>
#include <vector>

#include "absl/flags/reflection.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"

namespace splinegrid::cli {
namespace {

constexpr size_t kWidth = 80;

// `text` wrapped at word boundaries to kWidth columns, every line indented by `indent`.
std::string Wrap(absl::string_view text, absl::string_view indent) {
  std::string out;
  std::string line(indent);
  for (absl::string_view word : absl::StrSplit(text, ' ', absl::SkipEmpty())) {
    if (line.size() > indent.size() && line.size() + 1 + word.size() > kWidth) {
      absl::StrAppend(&out, line, "\n");
      line = std::string(indent);
    }
    absl::StrAppend(&line, line.size() > indent.size() ? " " : "", word);
  }
  if (line.size() > indent.size()) absl::StrAppend(&out, line, "\n");
  return out;
}

// "  --name=VALUE (default: "x")" and its help text below; bool flags take no value.
std::string DescribeFlag(const std::string& name) {
  const absl::CommandLineFlag* flag = absl::FindCommandLineFlag(name);
  if (flag == nullptr) return absl::StrCat("  --", name, "\n");  // cli_tests forbids this
  const bool is_bool = flag->IsOfType<bool>();
  const std::string dashes = name.size() == 1 ? "-" : "--";
  std::string default_value = flag->DefaultValue();
  if (flag->IsOfType<std::string>()) default_value = absl::StrCat("\"", default_value, "\"");
  if (default_value.empty()) default_value = "unset";
  return absl::StrCat("  ", dashes, name, is_bool ? "" : " VALUE", "  (default: ", default_value,
                      ")\n", Wrap(flag->Help(), "      "));
}

}  // namespace

std::string OverviewHelp(absl::string_view version) {
  std::string out =
      absl::StrCat("splinegrid ", version,
                   ": structured CFD grids as B-spline mappings, served over gRPC.\n\n"
                   "usage: splinegrid COMMAND [ARGUMENTS] [FLAGS]\n"
                   "       splinegrid help COMMAND   (or splinegrid COMMAND --help): its flags\n"
                   "       splinegrid --version\n\nCommands:\n");
  size_t width = 0;
  for (const CommandSpec& command : Commands()) width = std::max(width, command.name.size());
  for (const CommandSpec& command : Commands()) {
    absl::StrAppend(&out, "  ", command.name, std::string(width + 2 - command.name.size(), ' '),
                    command.summary, "\n");
  }
  absl::StrAppend(&out, "\n",
                  Wrap("Client commands (all but serve and airfoil) talk to --server host:port "
                       "(default $SPLINEGRID_SERVER, else localhost:50051) and take --json, "
                       "--timeout, and for a secured "
                       "server --token (or $SPLINEGRID_TOKEN), --tls_ca, --tls_cert, --tls_key "
                       "and --tls_server_name. Exit status: 0 success, 1 a failed call, 2 a "
                       "usage error, 3 a revision stored whose quality is not met "
                       "(--allow_folds).",
                       ""));
  return out;
}

std::string CommandHelp(const CommandSpec& command) {
  std::string out =
      absl::StrCat("usage: splinegrid ", command.usage, "\n", Wrap(command.summary, "  "));
  for (const std::string& note : command.notes) absl::StrAppend(&out, Wrap(note, "  "));
  if (!command.flags.empty()) absl::StrAppend(&out, "\nFlags:\n");
  for (const std::string& name : command.flags) absl::StrAppend(&out, DescribeFlag(name));
  if (command.client) {
    absl::StrAppend(&out, "\nConnection flags (every command that talks to a server):\n");
    for (const std::string& name : ClientFlags()) {
      if (std::find(command.flags.begin(), command.flags.end(), name) == command.flags.end()) {
        absl::StrAppend(&out, DescribeFlag(name));
      }
    }
  }
  return out;
}

}  // namespace splinegrid::cli
