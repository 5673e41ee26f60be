// The CLI's conventions with the real binary: help forms and --version exit 0 on stdout, a
// foreign or mistyped flag is a usage error (exit 2) with a suggestion, and every complete
// `build/splinegrid ...` line the READMEs show still gets past the command-line check.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/store/server_process.h"

namespace splinegrid::testing {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

const std::string kBinary = SPLINEGRID_BINARY_DIR "/splinegrid";

struct Result {
  int exit_code;
  std::string out;  // stdout only, or stdout and stderr
};

// `splinegrid ARGS` with stdout alone, stderr to /dev/null (help must go to stdout).
Result Stdout(const std::string& args) {
  Result result;
  result.exit_code =
      RunShell(absl::StrCat("timeout 60 ", kBinary, " ", args, " 2>/dev/null"), &result.out);
  return result;
}

// `splinegrid ARGS`, both streams.
Result Both(const std::string& args, const std::string& directory = ".") {
  Result result;
  result.exit_code = RunShell(
      absl::StrCat("cd '", directory, "' && timeout 60 ", kBinary, " ", args), &result.out);
  return result;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(CliConventions, HelpFormsExitZeroWithTheCommandsOnStdout) {
  for (const char* form : {"help", "--help", "-h"}) {
    const Result help = Stdout(form);
    EXPECT_EQ(help.exit_code, 0) << form << "\n" << help.out;
    EXPECT_THAT(help.out, HasSubstr("usage: splinegrid COMMAND")) << form;
    for (const char* command : {"serve", "fit", "fair", "eval", "deform", "offset", "watch",
                                "export", "import", "airfoil", "health"}) {
      EXPECT_THAT(help.out, HasSubstr(absl::StrCat("\n  ", command, " "))) << form;
    }
  }
}

TEST(CliConventions, CommandHelpListsItsFlagsWithHelpAndDefaults) {
  for (const char* form : {"help fit", "fit --help", "fit -h"}) {
    const Result help = Stdout(form);
    EXPECT_EQ(help.exit_code, 0) << form << "\n" << help.out;
    EXPECT_THAT(help.out, StartsWith("usage: splinegrid fit FILE")) << form;
    EXPECT_THAT(help.out, HasSubstr("--tol VALUE  (default: 0)")) << form;
    EXPECT_THAT(help.out, HasSubstr("fit: largest allowed deviation")) << form;
    EXPECT_THAT(help.out, HasSubstr("--kinds  (default: false)")) << form;
    EXPECT_THAT(help.out, HasSubstr("--server VALUE  (default: \"\")")) << form;
    EXPECT_THAT(help.out, HasSubstr("(default: $SPLINEGRID_SERVER, else\n      localhost:50051)"))
        << form;
    EXPECT_THAT(help.out, Not(HasSubstr("--rotate"))) << form;  // deform's
  }
  const Result serve = Stdout("help serve");
  EXPECT_EQ(serve.exit_code, 0);
  EXPECT_THAT(serve.out, HasSubstr("--metrics_address VALUE"));
  EXPECT_THAT(serve.out, Not(HasSubstr("--json")));
  const Result unknown = Both("help fitt");
  EXPECT_EQ(unknown.exit_code, 2) << unknown.out;
  EXPECT_THAT(unknown.out, HasSubstr("unknown command 'fitt'; did you mean fit?"));
}

TEST(CliConventions, VersionIsTheProjectVersion) {
  const std::string cmake = ReadFile(SPLINEGRID_SOURCE_DIR "/CMakeLists.txt");
  std::smatch match;
  ASSERT_TRUE(
      std::regex_search(cmake, match, std::regex(R"(project\(splinegrid VERSION ([0-9.]+))")));
  const Result version = Stdout("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_EQ(version.out, absl::StrCat("splinegrid ", match[1].str(), "\n"));
}

TEST(CliConventions, AFlagOfAnotherCommandIsAUsageErrorNamingItsOwner) {
  const Result list = Both("list --rotate 10 --level 3");
  EXPECT_EQ(list.exit_code, 2) << list.out;
  EXPECT_THAT(list.out, HasSubstr("--rotate is not a flag of list; it belongs to deform"));
  const Result serve = Both("serve --json");
  EXPECT_EQ(serve.exit_code, 2) << serve.out;
  EXPECT_THAT(serve.out, HasSubstr("--json is not a flag of serve"));
}

TEST(CliConventions, AMistypedFlagOrCommandGetsASuggestion) {
  const Result typo = Both("eval naca --levl 2 -o x.vts");
  EXPECT_EQ(typo.exit_code, 2) << typo.out;
  EXPECT_THAT(typo.out, HasSubstr("unknown flag --levl for eval; did you mean --level?"));
  const Result command = Both("evl naca");
  EXPECT_EQ(command.exit_code, 2) << command.out;
  EXPECT_THAT(command.out, HasSubstr("did you mean eval?"));
  const Result none = Both("");
  EXPECT_EQ(none.exit_code, 2) << none.out;
}

// The complete command lines of the READMEs' code blocks, as words after `build/splinegrid`.
std::vector<std::vector<std::string>> ReadmeCommandLines() {
  std::vector<std::vector<std::string>> lines;
  for (const char* file :
       {"/README.md", "/python/README.md", "/deploy/README.md", "/docker/README.md",
        "/docs/formats.md", "/docs/c-api.md", "/docs/operations.md"}) {
    for (absl::string_view line :
         absl::StrSplit(ReadFile(SPLINEGRID_SOURCE_DIR + std::string(file)), '\n')) {
      line = absl::StripAsciiWhitespace(line);
      if (!absl::ConsumePrefix(&line, "build/splinegrid ")) continue;
      line = line.substr(0, line.find('#'));  // a comment
      std::vector<std::string> words;
      for (absl::string_view word : absl::StrSplit(line, ' ', absl::SkipEmpty())) {
        if (word == "&") break;
        words.emplace_back(word);
      }
      lines.push_back(words);
    }
  }
  return lines;
}

// Each line runs against a closed port (client commands; airfoil works locally) in a scratch
// directory beside a link to ../shared, so nothing is written into the tree: the line must get past
// the command-line check and Abseil's parsing. Client commands then fail to connect (exit 1); serve
// is stopped by an out-of-range --threads appended, which only its own flag check reports (exit 2
// with "splinegrid serve: ...", not the check's "splinegrid: ...").
TEST(CliConventions, EveryReadmeCommandLineParses) {
  const std::vector<std::vector<std::string>> lines = ReadmeCommandLines();
  ASSERT_GT(lines.size(), 15u);
  const std::filesystem::path scratch =
      std::filesystem::temp_directory_path() / absl::StrCat("sg-cli-readme-", getpid());
  std::filesystem::create_directories(scratch / "main");
  std::filesystem::create_directory_symlink(
      std::filesystem::path(SPLINEGRID_SOURCE_DIR).parent_path() / "shared", scratch / "shared");
  const int closed = FreePort();
  for (const std::vector<std::string>& words : lines) {
    std::string args;
    for (const std::string& word : words) absl::StrAppend(&args, "'", word, "' ");
    const bool serve = !words.empty() && words[0] == "serve";
    const bool local = !words.empty() && words[0] == "airfoil";  // no server, no --server
    if (serve) {
      absl::StrAppend(&args, "--threads=-1");
    } else if (!local) {
      absl::StrAppend(&args, "--server=127.0.0.1:", closed, " --timeout=3s");
    }
    const Result result = Both(args, (scratch / "main").string());
    EXPECT_THAT(result.out, Not(HasSubstr("splinegrid: "))) << args << "\n" << result.out;
    EXPECT_THAT(result.out, Not(HasSubstr("ERROR:"))) << args << "\n" << result.out;
    if (serve) {
      EXPECT_EQ(result.exit_code, 2) << args << "\n" << result.out;
      EXPECT_THAT(result.out, HasSubstr("--threads = -1 is outside")) << args;
    } else {
      EXPECT_NE(result.exit_code, 2) << args << "\n" << result.out;
    }
  }
  std::filesystem::remove_all(scratch);
}

// The local airfoil talks to no server: a connection flag would be ignored, so it is refused.
TEST(CliConventions, TheLocalAirfoilRefusesConnectionFlags) {
  const std::string profile =
      absl::StrCat(SPLINEGRID_SOURCE_DIR, "/../shared/data/airfoils/rae2822.dat");
  for (const char* flag : {"--server=127.0.0.1:1", "--json", "--timeout=3s", "--token=t"}) {
    const Result airfoil = Both(absl::StrCat("airfoil ", profile, " ", flag, " 2>&1"));
    EXPECT_EQ(airfoil.exit_code, 2) << flag << "\n" << airfoil.out;
    EXPECT_THAT(airfoil.out, HasSubstr("is not a flag of airfoil; it belongs to the commands "
                                       "that talk to a server"))
        << flag;
  }
  const Result local = Both(absl::StrCat("airfoil ", profile, " 2>&1"));
  EXPECT_EQ(local.exit_code, 0) << local.out;
  EXPECT_THAT(Stdout("help airfoil").out, Not(HasSubstr("--server VALUE")));
}

// The server of client commands: --server, else $SPLINEGRID_SERVER (what
// deploy/local/start.sh prints), else localhost:50051. Port 1 on loopback has no listener: the
// failed call names the address it tried.
TEST(CliConventions, ClientCommandsTalkToSplinegridServerUnlessGivenServer) {
  const auto list = [](const std::string& environment, const std::string& flags) {
    Result result;
    result.exit_code = RunShell(
        absl::StrCat(environment, " timeout 60 ", kBinary, " list --timeout=2s ", flags, " 2>&1"),
        &result.out);
    return result;
  };
  const Result from_env = list("SPLINEGRID_SERVER=127.0.0.1:1", "");
  EXPECT_EQ(from_env.exit_code, 1) << from_env.out;
  EXPECT_THAT(from_env.out, HasSubstr("127.0.0.1:1")) << from_env.out;
  const Result from_flag = list("SPLINEGRID_SERVER=127.0.0.1:1", "--server=127.0.0.1:2");
  EXPECT_EQ(from_flag.exit_code, 1) << from_flag.out;
  EXPECT_THAT(from_flag.out, HasSubstr("127.0.0.1:2")) << from_flag.out;
  EXPECT_THAT(from_flag.out, Not(HasSubstr("127.0.0.1:1"))) << from_flag.out;
}

}  // namespace
}  // namespace splinegrid::testing
