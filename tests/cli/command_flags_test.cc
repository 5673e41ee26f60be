// The command table of the CLI (client/cli/command_flags.h) against the flags really defined,
// and the command-line check (command_line.h) on the forms users type, including every
// `splinegrid ...` span the READMEs quote.
#include "client/cli/command_flags.h"

#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "absl/flags/reflection.h"
#include "absl/strings/match.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "client/cli/command_help.h"
#include "client/cli/command_line.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace splinegrid::cli {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

std::set<std::string> ListedFlags() {
  std::set<std::string> listed;
  for (const CommandSpec& command : Commands()) {
    for (const std::string& flag : AcceptedFlags(command)) listed.insert(flag);
  }
  return listed;
}

// Every flag this project defines in the binary's sources (not Abseil's own --flagfile ...).
std::vector<std::string> ProjectFlags() {
  std::vector<std::string> names;
  for (const auto& [name, flag] : absl::GetAllFlags()) {
    // Abseil reports the defining file without its leading slashes.
    if (absl::StrContains(flag->Filename(), absl::StripPrefix(SPLINEGRID_SOURCE_DIR, "/"))) {
      names.push_back(std::string(name));
    }
  }
  return names;
}

TEST(CommandFlags, EveryDefinedFlagIsListedForSomeCommand) {
  const std::set<std::string> listed = ListedFlags();
  const std::vector<std::string> defined = ProjectFlags();
  ASSERT_GT(defined.size(), 50u) << "the CLI's flags are not linked in";
  for (const std::string& name : defined) {
    EXPECT_TRUE(listed.count(name))
        << "--" << name << " is defined but listed for no command in client/cli/command_flags.cc";
  }
}

TEST(CommandFlags, EveryListedNameIsADefinedFlag) {
  for (const std::string& name : ListedFlags()) {
    EXPECT_NE(absl::FindCommandLineFlag(name), nullptr)
        << "client/cli/command_flags.cc lists --" << name << ", which is not a flag";
  }
}

TEST(CommandFlags, CommandsAreUniqueAndDescribed) {
  std::set<std::string> names;
  for (const CommandSpec& command : Commands()) {
    EXPECT_TRUE(names.insert(command.name).second) << command.name;
    EXPECT_TRUE(absl::StartsWith(command.usage, command.name)) << command.usage;
    EXPECT_FALSE(command.summary.empty()) << command.name;
  }
  EXPECT_EQ(FindCommand("nosuch"), nullptr);
  ASSERT_NE(FindCommand("fit"), nullptr);
}

absl::StatusOr<CommandLine> Check(const std::string& line) {
  return CheckCommandLine(absl::StrSplit(line, ' ', absl::SkipEmpty()));
}

TEST(CommandLineCheck, RefusesAFlagOfAnotherCommandNamingItsOwner) {
  const auto line = Check("list --rotate 10 --level 3");
  ASSERT_FALSE(line.ok());
  EXPECT_EQ(line.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(line.status().message(),
              HasSubstr("--rotate is not a flag of list; it belongs to deform"));
  // A connection flag given to serve or to the local airfoil (which would only ignore it): the
  // group is named.
  const auto serve = Check("serve --server localhost:1");
  ASSERT_FALSE(serve.ok());
  EXPECT_THAT(serve.status().message(),
              HasSubstr("--server is not a flag of serve; it belongs to the commands that "
                        "talk to a server"));
  for (const char* line : {"airfoil a.dat --server localhost:1", "airfoil a.dat --json",
                           "airfoil a.dat --tls_ca=ca.pem"}) {
    const auto airfoil = Check(line);
    ASSERT_FALSE(airfoil.ok()) << line;
    EXPECT_THAT(airfoil.status().message(), HasSubstr("is not a flag of airfoil; it belongs to "
                                                      "the commands that talk to a server"))
        << line;
  }
}

TEST(CommandLineCheck, SuggestsTheClosestFlagOfTheCommand) {
  const auto line = Check("eval g --levl 2 -o x.vts");
  ASSERT_FALSE(line.ok());
  EXPECT_THAT(line.status().message(), HasSubstr("unknown flag --levl for eval"));
  EXPECT_THAT(line.status().message(), HasSubstr("did you mean --level?"));
  const auto far = Check("list --zzzzzzzz");
  ASSERT_FALSE(far.ok());
  EXPECT_THAT(far.status().message(), Not(HasSubstr("did you mean")));
}

TEST(CommandLineCheck, SuggestsTheClosestCommand) {
  const auto line = Check("evl g");
  ASSERT_FALSE(line.ok());
  EXPECT_THAT(line.status().message(), HasSubstr("unknown command 'evl'; did you mean eval?"));
  EXPECT_FALSE(Check("help nosuch").ok());
  EXPECT_FALSE(Check("").ok());  // no command
}

TEST(CommandLineCheck, SkipsValuesAndKnowsBoolFlags) {
  // A value that looks like a command or a flag is a value.
  const auto fit = Check("fit --name list grid.x --kinds --nokinds --allow_folds=false");
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_EQ(fit->command->name, "fit");
  const auto deform = Check("deform g --translate -0.1,0 --rotate=-3");
  ASSERT_TRUE(deform.ok()) << deform.status();
  // A bool flag takes no separate value: `list` here is the command.
  const auto json = Check("--json list");
  ASSERT_TRUE(json.ok()) << json.status();
  EXPECT_EQ(json->command->name, "list");
  // After --, everything is positional.
  const auto rm = Check("rm -- --rotate");
  ASSERT_TRUE(rm.ok()) << rm.status();
  // --noFLAG only for bool flags.
  EXPECT_FALSE(Check("eval g --nolevel -o x.vts").ok());
}

// A value its flag cannot take is a usage error naming the flag, the value and what it takes;
// Abseil alone printed "Illegal value '2' specified for flag 'timeout'" and exited 1.
TEST(CommandLineCheck, ValuesAreParsedBeforeAbseilWouldExit) {
  const auto line = Check("list --timeout 2 --json");
  ASSERT_TRUE(line.ok()) << line.status();
  ASSERT_EQ(line->flag_values.size(), 1u);  // --json stands alone
  EXPECT_EQ(line->flag_values[0], std::make_pair(std::string("timeout"), std::string("2")));
  // The status as text: code and message.
  auto refusal = [](const std::string& command) {
    return ParseFlagValues(Check(command).value()).ToString();
  };
  EXPECT_EQ(ParseFlagValues(*line).ToString(),
            "INVALID_ARGUMENT: --timeout = '2' is not a valid value: give a duration with its "
            "unit (30s, 500ms, 2m)");
  EXPECT_EQ(refusal("serve --threads=1.5"),
            "INVALID_ARGUMENT: --threads = '1.5' is not a valid value: give an integer");
  EXPECT_THAT(refusal("offset x.dat --first abc"), HasSubstr("'abc' is not a valid value: give a "
                                                             "number"));
  EXPECT_THAT(refusal("fit x --allow_folds=maybe"), HasSubstr("give true or false"));
}

TEST(CommandLineCheck, HelpAndVersionForms) {
  for (const char* form : {"help", "--help", "-h", "-help"}) {
    const auto line = Check(form);
    ASSERT_TRUE(line.ok()) << form;
    EXPECT_EQ(line->action, CommandLine::Action::kHelp) << form;
    EXPECT_EQ(line->command, nullptr) << form;
  }
  for (const char* form : {"help fit", "fit --help", "fit -h", "fit --tol 3 --help"}) {
    const auto line = Check(form);
    ASSERT_TRUE(line.ok()) << form;
    EXPECT_EQ(line->action, CommandLine::Action::kHelp) << form;
    ASSERT_NE(line->command, nullptr) << form;
    EXPECT_EQ(line->command->name, "fit") << form;
  }
  const auto version = Check("--version");
  ASSERT_TRUE(version.ok());
  EXPECT_EQ(version->action, CommandLine::Action::kVersion);
}

TEST(CommandHelp, ListsTheCommandsFlagsWithHelpAndDefaults) {
  const std::string fit = CommandHelp(*FindCommand("fit"));
  EXPECT_THAT(fit, HasSubstr("usage: splinegrid fit FILE"));
  EXPECT_THAT(fit, HasSubstr("--tol VALUE  (default: 0)"));
  EXPECT_THAT(fit, HasSubstr("largest allowed deviation"));
  EXPECT_THAT(fit, HasSubstr("--server VALUE  (default: \"\")"));
  EXPECT_THAT(fit, HasSubstr("$SPLINEGRID_SERVER, else"));
  EXPECT_THAT(fit, Not(HasSubstr("--rotate")));
  const std::string airfoil = CommandHelp(*FindCommand("airfoil"));
  EXPECT_THAT(airfoil, Not(HasSubstr("--server VALUE")));  // local: refused, not listed
  const std::string overview = OverviewHelp("9.9.9");
  EXPECT_THAT(overview, HasSubstr("splinegrid 9.9.9"));
  for (const CommandSpec& command : Commands()) EXPECT_THAT(overview, HasSubstr(command.name));
}

TEST(EditDistance, CountsEdits) {
  EXPECT_EQ(EditDistance("level", "level"), 0);
  EXPECT_EQ(EditDistance("levl", "level"), 1);
  EXPECT_EQ(EditDistance("", "abc"), 3);
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3);
  EXPECT_EQ(ClosestName("revison", {"revision", "reference"}), "revision");
  EXPECT_EQ(ClosestName("xyz", {"revision"}), "");
  // Two neighbours swapped are one edit, so short names get their suggestion too.
  EXPECT_EQ(EditDistance("nmae", "name"), 1);
  EXPECT_EQ(EditDistance("ca", "abc"), 3);  // each substring edited once
  EXPECT_EQ(ClosestName("nmae", {"name", "level"}), "name");
  EXPECT_EQ(ClosestName("levle", {"name", "level"}), "level");
}

// Every `splinegrid CMD ...` the READMEs quote in backticks or in code blocks uses flags its
// command accepts (placeholders such as FILE or [--name NEW] are fine: the check is about
// names). The complete command lines of the quick start also run through the real binary
// (tests/e2e/cli_conventions_test.cc).
std::vector<std::string> ReadmeCommandLines() {
  std::vector<std::string> lines;
  const std::regex span(R"((?:build/)?\bsplinegrid ([a-z]+)((?: [^`\n#&]*)?))");
  for (const char* file :
       {"/README.md", "/python/README.md", "/deploy/README.md", "/docker/README.md",
        "/docs/formats.md", "/docs/c-api.md", "/docs/operations.md"}) {
    std::ifstream in(std::string(SPLINEGRID_SOURCE_DIR) + file);
    std::stringstream text;
    text << in.rdbuf();
    const std::string all = text.str();
    for (std::sregex_iterator it(all.begin(), all.end(), span), end; it != end; ++it) {
      if (FindCommand((*it)[1].str()) == nullptr) continue;  // prose: "splinegrid is a ..."
      // A terminal transcript ("$ build/splinegrid list --rotate 10") shows a refused command
      // next to its error on purpose.
      const size_t newline = all.rfind('\n', static_cast<size_t>(it->position(0)));
      const size_t line_start = newline == std::string::npos ? 0 : newline + 1;
      if (all.compare(line_start, 2, "$ ") == 0) continue;
      lines.push_back((*it)[1].str() + (*it)[2].str());
    }
  }
  return lines;
}

TEST(CommandLineCheck, EveryReadmeCommandUsesFlagsItsCommandAccepts) {
  const std::vector<std::string> lines = ReadmeCommandLines();
  ASSERT_GT(lines.size(), 15u);
  for (std::string line : lines) {
    // Drop the syntax of usage lines: brackets, alternatives, ellipses.
    for (char& c : line) {
      if (c == '[' || c == ']' || c == '(' || c == ')') c = ' ';
    }
    std::vector<std::string> words;
    for (absl::string_view word : absl::StrSplit(line, ' ', absl::SkipEmpty())) {
      if (word == "|" || word == "..." || word == "\\") continue;
      words.emplace_back(word);
    }
    const auto checked = CheckCommandLine(words);
    EXPECT_TRUE(checked.ok()) << "README: splinegrid " << line << "\n  " << checked.status();
  }
}

}  // namespace
}  // namespace splinegrid::cli
