// End to end: the real `splinegrid serve` on a free loopback port, driven by the CLI, the C++
// coupling example and the Python examples, then stopped with SIGTERM (exit code 0, one log line
// per call). Archives go out and back in through both clients; the coupling clients run through
// a proxy that loses answers (fault_proxy.py) and across a SIGKILL and restart of a server with
// a durable store.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/io/file_util.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/hexahedron_checks.h"
#include "tests/core/test_data.h"
#include "tests/store/server_process.h"

namespace splinegrid::testing {
namespace {

using ::testing::HasSubstr;

const std::string kBinary = SPLINEGRID_BINARY_DIR "/splinegrid";
const std::string kSource = SPLINEGRID_SOURCE_DIR;

struct Result {
  int exit_code;
  std::string out;  // stdout and stderr
};

// Runs a shell command and collects its output and exit code.
Result RunCommand(const std::string& command) {
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  std::string out;
  std::array<char, 4096> buffer;
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) out.append(buffer.data(), n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

class EndToEndTest : public ::testing::Test {
 protected:
  void SetUp() override {
    port_ = FreePort();
    dir_ = std::filesystem::temp_directory_path() / absl::StrCat("splinegrid-e2e-", getpid());
    std::filesystem::create_directories(dir_);
    log_ = (dir_ / "server.log").string();
    ASSERT_NO_FATAL_FAILURE(StartServer());
  }

  // Starts `splinegrid serve` on port_ with `flags` (the server's log appended to log_) and
  // waits until it is healthy.
  void StartServer(const std::vector<std::string>& flags = {}) {
    stopped_ = false;
    server_ = fork();
    if (server_ == 0) {
      freopen(log_.c_str(), "a", stderr);
      std::vector<std::string> args = {kBinary, "serve",
                                       absl::StrCat("--address=127.0.0.1:", port_), "--threads=2",
                                       "--drain_notice=0s"};
      args.insert(args.end(), flags.begin(), flags.end());
      std::vector<char*> argv;
      for (std::string& arg : args) argv.push_back(arg.data());
      argv.push_back(nullptr);
      execv(kBinary.c_str(), argv.data());
      _exit(127);
    }
    for (int i = 0; i < 100; ++i) {
      if (Cli("health --timeout=1s").exit_code == 0) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    FAIL() << "the server did not become healthy:\n" << ReadLog();
  }

  void TearDown() override {
    if (server_ > 0 && !stopped_) {
      EXPECT_EQ(Stop(), 0) << ReadLog();
    }
    std::filesystem::remove_all(dir_);
  }

  // `signal` (SIGTERM: a clean stop) and the server's exit code (-1 when killed).
  int Stop(int signal = SIGTERM) {
    stopped_ = true;
    kill(server_, signal);
    int status = 0;
    waitpid(server_, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  // The command line `args` against this test's server (the local airfoil takes no --server).
  Result Cli(const std::string& args) {
    const bool local = absl::StartsWith(args, "airfoil ");
    return RunCommand(
        absl::StrCat(kBinary, " ", args, local ? "" : absl::StrCat(" --server=127.0.0.1:", port_)));
  }

  std::string ReadLog() const {
    std::ifstream in(log_);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }

  // A grid `name` with a fitted, a faired and a deformed revision (step 4) of the coarse
  // NACA 0012 C-grid.
  void MakeGridWithRevisions(const std::string& name) {
    const Result fit = Cli(absl::StrCat("fit ", SharedDataPath("grids/n0012_113-33.p2dfmt"),
                                        " --name=", name, " --kinds"));
    ASSERT_EQ(fit.exit_code, 0) << fit.out;
    const Result fair = Cli(absl::StrCat("fair ", name));
    ASSERT_EQ(fair.exit_code, 0) << fair.out;
    const Result deform = Cli(absl::StrCat(
        "deform ", name, " --rotate=4 --about=0.25,0 --reference=1 --base=2 --time=0.4 --step=4"));
    ASSERT_EQ(deform.exit_code, 0) << deform.out;
  }

  // The `step revision` lines of a pitching client's --acked file.
  static std::vector<std::pair<int, int64_t>> ReadAcked(const std::string& path) {
    std::vector<std::pair<int, int64_t>> acked;
    std::istringstream lines(ReadFileToString(path).value_or(""));
    int step = 0;
    int64_t revision = 0;
    while (lines >> step >> revision) acked.emplace_back(step, revision);
    return acked;
  }

  // Every acknowledged step's revision is stored with its step.
  void ExpectAckedRevisionsStored(const std::string& name, const std::string& acked_path,
                                  int steps) {
    const std::vector<std::pair<int, int64_t>> acked = ReadAcked(acked_path);
    ASSERT_EQ(static_cast<int>(acked.size()), steps) << ReadFileToString(acked_path).value_or("");
    for (int n = 1; n <= steps; ++n) {
      EXPECT_EQ(acked[n - 1].first, n);
      const Result get = Cli(absl::StrCat("get ", name, " --step=", n));
      ASSERT_EQ(get.exit_code, 0) << get.out;
      EXPECT_THAT(get.out, HasSubstr(absl::StrCat("  revision ", acked[n - 1].second, " of ")));
      EXPECT_THAT(get.out, HasSubstr(absl::StrCat(", step ", n, "\n")));
    }
  }

  int port_ = 0;
  pid_t server_ = -1;
  bool stopped_ = false;
  std::filesystem::path dir_;
  std::string log_;
};

TEST_F(EndToEndTest, CliFitsListsGetsEvaluatesAndRemoves) {
  const Result fit = Cli(absl::StrCat("fit ", SharedDataPath("grids/n0012_113-33.p2dfmt"),
                                      " --name=naca --ctl=40,16 --allow_folds"));
  // These counts fold sub-cells (issue 13.3): stored with --allow_folds, exit 3 says so.
  ASSERT_EQ(fit.exit_code, 3) << fit.out;
  EXPECT_THAT(fit.out, HasSubstr("grids/naca revision 1: 3729 points -> 640 control points"));
  EXPECT_THAT(fit.out, HasSubstr("tolerances: none given (a fit to control counts)"));
  // Neither counts nor tolerances: an interpolating fit, and the report says so.
  const Result box =
      Cli(absl::StrCat("fit ", SharedDataPath("surfaces/ffd_box_6x2x6.fmt"), " --name=box"));
  ASSERT_EQ(box.exit_code, 0) << box.out;
  EXPECT_THAT(box.out, HasSubstr("tolerances: none given (interpolating: a control per point)"));
  // Nothing is a fraction of the reference length when no tolerance applies.
  EXPECT_THAT(box.out, ::testing::Not(HasSubstr("fractions of it")));
  // A curve has no cells: no cell figures (they read 0, as if every cell were degenerate).
  const std::string curve = (dir_ / "curve.p2d").string();
  ASSERT_TRUE(
      WriteFileAtomically(curve, "1\n5 1\n0 0.25 0.5 0.75 1\n0 0.0625 0.25 0.5625 1\n").ok());
  const Result line = Cli(absl::StrCat("fit ", curve, " --name=curve"));
  ASSERT_EQ(line.exit_code, 0) << line.out;
  EXPECT_THAT(line.out, HasSubstr("cells: none (a curve or a point)"));
  EXPECT_THAT(line.out, ::testing::Not(HasSubstr("worst Jacobian ratio")));

  const Result tol = Cli(absl::StrCat("fit ", SharedDataPath("grids/rae2822_257x97.fmt"),
                                      " --name=rae --tol=1e-3 --json"));
  // 1e-3 used to fold 620 sub-cells near the far field; the repairs of what knot removal leaves
  // (averaged knots, a weak fairing) remove them, and the fit says which weight it took.
  ASSERT_EQ(tol.exit_code, 0) << tol.out;
  EXPECT_THAT(tol.out, HasSubstr("\"tolerance_met\": true"));
  EXPECT_THAT(tol.out, ::testing::Not(HasSubstr("\"folded\"")));  // 0: omitted in JSON
  EXPECT_THAT(tol.out, HasSubstr("\"fairing_weight\": 1e-08"));

  const Result list = Cli("list");
  ASSERT_EQ(list.exit_code, 0) << list.out;
  EXPECT_THAT(list.out, HasSubstr("grids/naca"));
  EXPECT_THAT(list.out, HasSubstr("grids/rae"));

  const Result get = Cli("get naca --json");
  ASSERT_EQ(get.exit_code, 0) << get.out;
  EXPECT_THAT(get.out, HasSubstr("\"latest_revision\": \"1\""));

  const std::string vts = (dir_ / "naca.vts").string();
  const Result eval = Cli(absl::StrCat("eval naca --level=2 -o ", vts));
  ASSERT_EQ(eval.exit_code, 0) << eval.out;
  std::ifstream in(vts);
  std::string head(400, '\0');
  in.read(head.data(), head.size());
  EXPECT_THAT(head, HasSubstr("WholeExtent=\"0 448 0 128 0 0\""));

  const std::string xyz = (dir_ / "rae.xyz").string();
  ASSERT_EQ(Cli(absl::StrCat("eval rae --res=300,50 -o ", xyz)).exit_code, 0);
  const MultiBlockGrid back = ReadPlot3dFile(xyz).value();
  // rae2822_257x97.fmt holds two planes (CFL3D): written back as two planes, not as 2D.
  EXPECT_EQ(back.blocks[0].extents(), (Extents{2, 300, 50}));

  const std::string vtm = (dir_ / "both.vtm").string();
  ASSERT_EQ(Cli(absl::StrCat("eval rae --level=0 --derivs -o ", vtm)).exit_code, 0);
  EXPECT_TRUE(std::filesystem::exists(dir_ / "both" / "both_0.vts"));

  EXPECT_EQ(Cli("rm naca").exit_code, 0);
  const Result gone = Cli("get naca");
  EXPECT_EQ(gone.exit_code, 1);
  EXPECT_THAT(gone.out, HasSubstr("NOT_FOUND"));
}

// `fit NAME` fits a stored grid's points again (a grid left unfitted by an interrupted `fit`,
// or other tolerances); importing a name that exists says how to do either.
TEST_F(EndToEndTest, CliFitsAStoredGridAgainByName) {
  const std::string file = SharedDataPath("grids/n0012_113-33.p2dfmt");
  ASSERT_EQ(Cli(absl::StrCat("fit ", file, " --name=naca --kinds")).exit_code, 0);
  const Result again = Cli(absl::StrCat("fit ", file, " --name=naca --kinds"));
  EXPECT_EQ(again.exit_code, 1) << again.out;
  EXPECT_THAT(again.out, HasSubstr("ALREADY_EXISTS: grids/naca already exists: to fit its "
                                   "stored points again, `splinegrid fit naca`"));
  const Result refit = Cli("fit naca --tol=1e-3");
  ASSERT_EQ(refit.exit_code, 0) << refit.out;
  EXPECT_THAT(refit.out, HasSubstr("grids/naca revision 2: 3729 points"));
  EXPECT_THAT(Cli("fit grids/naca --kinds").out, HasSubstr("grids/naca revision 3: "));
  const Result renamed = Cli("fit naca --name=other");
  EXPECT_EQ(renamed.exit_code, 2) << renamed.out;
  EXPECT_THAT(renamed.out, HasSubstr("--name is about importing a file; grids/naca is a stored "
                                     "grid"));
  const Result neither = Cli("fit nothere --kinds");
  EXPECT_EQ(neither.exit_code, 1) << neither.out;
  EXPECT_THAT(neither.out, HasSubstr("nothere is neither a file nor a stored grid"));
}

// eval refuses, when its header arrives, an evaluation whose values times the copies its output
// format holds while writing would not fit in what the CLI may use (--max_memory_mb; by default
// three quarters of MemAvailable or the cgroup limit): a trial's eval to .xyz peaked at 8.8 and
// to .vts at 4.6 times the values it had been allowed, and was killed by the OOM killer.
TEST_F(EndToEndTest, CliEvalRefusesWhatItsOutputCouldNotHoldWhileWriting) {
  ASSERT_EQ(
      Cli(absl::StrCat("fit ", SharedDataPath("grids/n0012_113-33.p2dfmt"), " --name=naca --kinds"))
          .exit_code,
      0);
  // 1000 x 1000 points of 2 doubles: 15.3 MiB of values.
  const std::string eval = "eval naca --res=1000,1000 --max_memory_mb=100 -o ";
  const Result xyz = Cli(eval + (dir_ / "big.xyz").string());
  EXPECT_EQ(xyz.exit_code, 1) << xyz.out;
  EXPECT_THAT(xyz.out, HasSubstr("RESOURCE_EXHAUSTED: the evaluation holds 1000000 points"));
  EXPECT_THAT(xyz.out, HasSubstr("holds about 9.5 copies of the values"));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "big.xyz"));
  const Result vts = Cli(eval + (dir_ / "big.vts").string());  // 5 copies: 76 MiB
  EXPECT_EQ(vts.exit_code, 0) << vts.out;
  EXPECT_THAT(vts.out, HasSubstr("1000000 points"));
  EXPECT_EQ(Cli("eval naca --level=0 --max_memory_mb=-1 -o x.vts").exit_code, 2);
}

TEST_F(EndToEndTest, CliReportsErrorsWithNonZeroExit) {
  const Result missing = Cli("fit /nonexistent/grid.x");
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_THAT(missing.out, HasSubstr("/nonexistent/grid.x"));
  const Result unknown = Cli(absl::StrCat("eval nope --level=0 -o ", (dir_ / "x.vts").string()));
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_THAT(unknown.out, HasSubstr("NOT_FOUND"));
  const Result usage = Cli("eval nope");
  EXPECT_EQ(usage.exit_code, 2);
  EXPECT_THAT(usage.out, HasSubstr("usage"));
  // A NaN edge accuracy reaches the server and is refused by name; it used to read as unset, and
  // the grid was stored with the default 0.5.
  const Result nan_edge = Cli(absl::StrCat("fit ", SharedDataPath("grids/n0012_113-33.p2dfmt"),
                                           " --name=nan-edge --kinds --edge=nan"));
  EXPECT_EQ(nan_edge.exit_code, 2) << nan_edge.out;
  EXPECT_THAT(nan_edge.out, HasSubstr("edge = nan"));
  EXPECT_THAT(Cli("list").out, ::testing::Not(HasSubstr("grids/nan-edge")));
  // A server that accepts the connection and never answers: the CLI's own deadline fires, and
  // the error names the timeout (gRPC's words were only "Deadline Exceeded").
  const int silent = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof address;
  ASSERT_EQ(bind(silent, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  ASSERT_EQ(listen(silent, 1), 0);
  ASSERT_EQ(getsockname(silent, reinterpret_cast<sockaddr*>(&address), &length), 0);
  const Result late = RunCommand(
      absl::StrCat(kBinary, " list --timeout=1s --server=127.0.0.1:", ntohs(address.sin_port)));
  close(silent);
  EXPECT_EQ(late.exit_code, 1) << late.out;
  EXPECT_THAT(late.out, HasSubstr("DEADLINE_EXCEEDED: the call's deadline passed before its "
                                  "answer came (the client's timeout, 1s: ClientOptions.timeout, "
                                  "CLI --timeout"));
  // A bad --name is named as the flag (it was the request's header.grid_id), before the upload.
  const Result bad_name =
      Cli(absl::StrCat("fit ", SharedDataPath("grids/n0012_113-33.p2dfmt"), " --name=Bad_Name"));
  EXPECT_EQ(bad_name.exit_code, 2) << bad_name.out;
  EXPECT_THAT(bad_name.out, HasSubstr("--name = 'Bad_Name' is not valid"));
  // Files named by their path: an empty grid file, and a profile with a bad number (the server
  // knows only its request fields, total_bytes and airfoil_file).
  const std::string empty = (dir_ / "empty.fmt").string();
  ASSERT_TRUE(WriteFileAtomically(empty, "").ok());
  const Result nothing = Cli(absl::StrCat("fit ", empty, " --kinds"));
  EXPECT_EQ(nothing.exit_code, 2) << nothing.out;
  EXPECT_THAT(nothing.out, HasSubstr(absl::StrCat(empty, " is empty: no grid to fit")));
  const std::string nanfoil = (dir_ / "nanfoil.dat").string();
  ASSERT_TRUE(WriteFileAtomically(nanfoil, "nanfoil\n1 0\nnan 0.1\n0 0\n1 0\n").ok());
  const Result bad_profile = Cli(absl::StrCat("offset ", nanfoil));
  EXPECT_EQ(bad_profile.exit_code, 2) << bad_profile.out;
  EXPECT_THAT(bad_profile.out, HasSubstr(absl::StrCat("airfoil '", nanfoil, "': line 3")));
}

// Flag values the request cannot carry as given are refused by name (exit 2), not read as
// "unset": 0 is the wire's default for an order or a count, and a negative level or deadline has
// no meaning. A first spacing that double precision cannot resolve is refused by the server.
TEST_F(EndToEndTest, CliRefusesValuesThatWouldReadAsUnset) {
  const std::string grid = SharedDataPath("grids/n0012_113-33.p2dfmt");
  const std::string out = (dir_ / "x.vts").string();
  const auto refused = [&](const std::string& args, const std::string& why) {
    const Result result = Cli(args);
    EXPECT_EQ(result.exit_code, 2) << args << "\n" << result.out;
    EXPECT_THAT(result.out, HasSubstr(why)) << args;
  };
  refused(absl::StrCat("fit ", grid, " --name=order0 --kinds --order=0"), "--order = 0");
  ASSERT_EQ(Cli(absl::StrCat("fit ", grid, " --name=flags --kinds")).exit_code, 0);
  refused(absl::StrCat("eval flags --res=0,0 -o ", out), "0 points in direction i");
  refused(absl::StrCat("eval flags --res=40,0 -o ", out), "0 points in direction j");
  // A direction left out of --res or --box read as one point or the range 0:0.
  refused(absl::StrCat("eval flags --res=10 -o ", out),
          "--res = '10' gives 1 of the 2 directions of flags: give 2 counts (i,j)");
  refused(absl::StrCat("eval flags --level=0 --box=0:5 -o ", out),
          "--box = '0:5' gives 1 of the 2 directions of flags: give 2 ranges (i,j)");
  refused(absl::StrCat("eval flags --level=-3 -o ", out), "--level = -3 is negative");
  refused("curvature flags --level=-3", "--level = -3 is negative");
  refused("list --timeout=-5s", "--timeout = -5s is not a positive duration");
  refused(absl::StrCat("eval flags --level=1 --dist j=geometric:1e-300 -o ", out),
          "closer than double precision separates");
  EXPECT_EQ(Cli(absl::StrCat("eval flags --res=40,20 -o ", out)).exit_code, 0);
  EXPECT_THAT(Cli("list").out, ::testing::Not(HasSubstr("order0")));
  // A tolerance double precision cannot resolve is refused; one a control cap holds the fit
  // back from is stored, but not as asked: exit 3, as for stored folds (it exited 0).
  refused(absl::StrCat("fit ", grid, " --name=tiny --tol=1e-300"),
          "tolerance = 1e-300 is below what double precision resolves");
  const Result capped = Cli(absl::StrCat("fit ", SharedDataPath("surfaces/m6_small.fmt"),
                                         " --name=capped --tol=1e-6 --max_ctl=12"));
  EXPECT_EQ(capped.exit_code, 3) << capped.out;
  EXPECT_THAT(capped.out, HasSubstr("grids/capped revision 1 was stored, but its tolerances are "
                                    "NOT met"));
}

TEST_F(EndToEndTest, PythonExampleFitsAndRefines) {
  const Result python = RunCommand(
      absl::StrCat("PYTHONPATH=", SPLINEGRID_BINARY_DIR, "/python /usr/bin/python3 ", kSource,
                   "/python/examples/fit_and_refine.py --server=127.0.0.1:", port_,
                   " --grid=", SharedDataPath("grids/n0012_225-65.p2dfmt")));  // by kinds: no fold
  ASSERT_EQ(python.exit_code, 0) << python.out;
  EXPECT_THAT(python.out, HasSubstr("(1, 257, 897, 2)"));  // level 2 of the 225 x 65 grid
}

TEST_F(EndToEndTest, CliFitsByKindFairsAndWritesWallCurvature) {
  const Result fit = Cli(
      absl::StrCat("fit ", SharedDataPath("grids/n0012_113-33.p2dfmt"), " --name=coarse --kinds"));
  ASSERT_EQ(fit.exit_code, 0) << fit.out;
  EXPECT_THAT(fit.out, HasSubstr("tolerances: met"));
  // The deviation of each kind against the tolerance it was held to, relative to the chord
  // found (issue 13); the interior has none.
  EXPECT_THAT(fit.out, HasSubstr("reference length 1 (the largest extent of 1 wall"));
  EXPECT_THAT(fit.out,
              ::testing::MatchesRegex("(.|\n)*deviation: wall [0-9.e-]+ <= 0.00015 met, "
                                      "interface [0-9.e-]+ <= 0.002 met, outer [0-9.e-]+ "
                                      "<= 0.008 met, interior [0-9.e-]+ \\(no tolerance\\); "
                                      "first-layer heights at walls changed by up to "
                                      "[0-9.e-]+%\n(.|\n)*"));
  EXPECT_THAT(fit.out, HasSubstr("connectivity: 1 matches"));
  // Block by block in the table too (a percentage).
  EXPECT_THAT(fit.out, HasSubstr("interior 1st layer  min jac"));
  EXPECT_THAT(fit.out, ::testing::ContainsRegex("\n     0 [^\n]* [0-9.e-]+% "));
  // Held (--first_layer): against its tolerance, and within it.
  const Result held = Cli(absl::StrCat("fit ", SharedDataPath("grids/n0012_113-33.p2dfmt"),
                                       " --name=held --first_layer=0.1"));
  ASSERT_EQ(held.exit_code, 0) << held.out;
  EXPECT_THAT(held.out, HasSubstr("tolerances: met"));
  EXPECT_THAT(held.out, ::testing::MatchesRegex("(.|\n)*first-layer heights at walls changed by "
                                                "up to [0-9.e-]+% <= 10% met\n(.|\n)*"));
  const Result bad = Cli("fit held --first_layer=2");
  EXPECT_EQ(bad.exit_code, 2);  // INVALID_ARGUMENT, named by the server
  EXPECT_THAT(bad.out, HasSubstr("tolerances.first_layer = 2 is outside [0, 1]"));
  // The block table's "max size" is the summary's largest size ratio (either way, shrunk cells
  // too), not growth alone: one block, so the same figure.
  const std::string summary = "largest size ratio ";
  const size_t at = fit.out.find(summary);
  ASSERT_NE(at, std::string::npos) << fit.out;
  const std::string ratio =
      fit.out.substr(at + summary.size(), fit.out.find('\n', at) - at - summary.size());
  EXPECT_THAT(fit.out.substr(fit.out.find("\n     0 ")), HasSubstr(absl::StrCat(" ", ratio, " ")));
  const Result fair = Cli("fair coarse");
  ASSERT_EQ(fair.exit_code, 0) << fair.out;
  EXPECT_THAT(fair.out, HasSubstr("revision 2"));
  EXPECT_THAT(fair.out, HasSubstr("walls, same knots unfaired"));
  const std::string csv = (dir_ / "wall.csv").string();
  const Result curvature = Cli(absl::StrCat("curvature coarse --revision=1 -o ", csv));
  ASSERT_EQ(curvature.exit_code, 0) << curvature.out;
  const std::string text = ReadFileToString(csv).value();
  EXPECT_EQ(text.rfind("block,direction,start_i,start_j,start_k,line,sample,arc_length", 0), 0u);
  // One wall line of the 113 x 33 C-grid: its airfoil points at refinement level 2, a header.
  const int64_t rows = std::count(text.begin(), text.end(), '\n');
  EXPECT_GT(rows, 4 * 60);
  EXPECT_NE(Cli("curvature coarse --level=9").exit_code, 0);
}

TEST_F(EndToEndTest, CliFitsAnAirfoilLocally) {
  const std::string csv = (dir_ / "rae.csv").string();
  const Result fit =
      Cli(absl::StrCat("airfoil ", SharedDataPath("airfoils/rae2822.dat"), " -o ", csv));
  ASSERT_EQ(fit.exit_code, 0) << fit.out;
  EXPECT_THAT(fit.out, HasSubstr("sharp trailing edge"));
  EXPECT_THAT(fit.out, HasSubstr("(within 0.0001)"));
  EXPECT_THAT(fit.out, HasSubstr("0 spurious"));
  const std::string text = ReadFileToString(csv).value();
  EXPECT_EQ(text.rfind("u,x,y,curvature\n", 0), 0u);
  EXPECT_NE(Cli(absl::StrCat("airfoil ", SharedDataPath("grids/n0012_113-33.p2dfmt"))).exit_code,
            0);
}

// --face sets explicit kinds (issue 13, point 5): the C-grid's far field (j max) as a wall is
// held to the wall tolerance; a bad token is named with exit status 2.
TEST_F(EndToEndTest, CliFitSetsFaceKinds) {
  const Result fit = Cli(absl::StrCat("fit ", SharedDataPath("grids/n0012_113-33.p2dfmt"),
                                      " --name=faces --face 0:jmax=wall --ref_length 1"));
  // The far field held to the wall's tolerance used to fold 2 sub-cells at level 2 near
  // (13, 21); the fold repairs after knot removal leave none.
  ASSERT_EQ(fit.exit_code, 0) << fit.out;
  EXPECT_THAT(fit.out, HasSubstr("0 folded sub-cells"));
  // Measured: the far field adds 3 wall lines to the airfoil's one (without --face: "walls: 1
  // lines"), all within the wall tolerance.
  EXPECT_THAT(fit.out, HasSubstr("walls: 4 lines"));
  EXPECT_THAT(fit.out,
              ::testing::MatchesRegex("(.|\n)*deviation: wall [0-9.e-]+ <= 0.00015 met(.|\n)*"));
  for (const char* token : {"0:lmin=wall", "0:imin=symmetry", "x:imin=wall", "0:imin"}) {
    const Result bad = Cli(absl::StrCat("fit ", SharedDataPath("grids/n0012_113-33.p2dfmt"),
                                        " --name=bad --face 1:jmin=outer,", token));
    EXPECT_EQ(bad.exit_code, 2) << bad.out;
    EXPECT_THAT(bad.out, HasSubstr(absl::StrCat("--face: '", token, "'")));
  }
}

// A fit that fails writes no curvature file (issue 13, point 4): RAE 2822 with a zigzag of
// +-1e-3 chord on its middle points at 1e-6 chord has a cusp (measured: curvature 10393 against
// the reference's 892).
TEST_F(EndToEndTest, CliAirfoilFailureWritesNoCurvature) {
  std::istringstream lines(ReadFileToString(SharedDataPath("airfoils/rae2822.dat")).value());
  std::vector<std::string> rows;
  for (std::string line; std::getline(lines, line);) rows.push_back(line);
  const int m = static_cast<int>(rows.size()) - 1;  // after the name line
  std::ofstream zigzag(dir_ / "zigzag.dat");
  zigzag << rows[0] << "\n";
  for (int i = 0; i < m; ++i) {
    double x = 0.0, y = 0.0;
    std::istringstream(rows[i + 1]) >> x >> y;
    if (i >= 10 && i < m - 10) y += 1e-3 * (i % 3 - 1);
    zigzag << absl::StrCat(x, " ", y) << "\n";
  }
  zigzag.close();
  const std::string csv = (dir_ / "failed.csv").string();
  const Result fit =
      Cli(absl::StrCat("airfoil ", (dir_ / "zigzag.dat").string(), " --tol 1e-6 -o ", csv));
  EXPECT_EQ(fit.exit_code, 1) << fit.out;
  EXPECT_THAT(fit.out, HasSubstr("cusp"));
  EXPECT_THAT(fit.out, HasSubstr("curvature not written"));
  EXPECT_FALSE(std::filesystem::exists(csv));
}

TEST_F(EndToEndTest, CliGeneratesAnOGridAroundAnAirfoilAndWritesIt) {
  const std::string vts = (dir_ / "grid.vts").string();
  const Result offset =
      Cli(absl::StrCat("offset ", SharedDataPath("airfoils/naca0012.dat"),
                       " --name=naca-og --layers=32 --first=1e-4 --far=20 --points=129 -o ", vts));
  // No --allow_folds: the interpolation is C0 on the corner lines of the blunt base, and the
  // grid is stored only because nothing folds at levels 0-2.
  ASSERT_EQ(offset.exit_code, 0) << offset.out;
  EXPECT_THAT(offset.out, HasSubstr("levels 0-2: 0 folded sub-cells"));
  EXPECT_THAT(offset.out, HasSubstr("grids/naca-og: offsets O-grid 129x33x1 around 'Naca 0012"));
  EXPECT_THAT(offset.out, HasSubstr("quality: 0 negative cells"));
  EXPECT_THAT(offset.out, HasSubstr("grids/naca-og revision 1: 4257 points"));
  EXPECT_THAT(offset.out, HasSubstr(absl::StrCat("wrote ", vts, ": 4257 points (revision 1)")));
  EXPECT_THAT(ReadFileToString(vts).value(), HasSubstr("WholeExtent=\"0 128 0 32 0 0\""));

  // Transfinite, as binary Plot3D: every cell of the written grid has a positive area.
  const std::string x = (dir_ / "grid.x").string();
  const Result transfinite = Cli(absl::StrCat(
      "offset ", SharedDataPath("airfoils/rae2822.dat"),
      " --name=rae-og --method=transfinite --layers=24 --first=1e-3 --far=10 --points=97 --json "
      "--allow_folds -o ",
      x));
  // The transfinite grid's first column at a sharp trailing edge is a wedge up to 15x wider than
  // the next one: its interpolating spline folds sub-cells there. Stored, exit 3.
  ASSERT_EQ(transfinite.exit_code, 3) << transfinite.out;
  EXPECT_THAT(transfinite.out, HasSubstr("\"method\": \"LAYER_METHOD_TRANSFINITE\""));
  EXPECT_THAT(transfinite.out, HasSubstr("\"growth_ratio\""));
  const MultiBlockGrid grid = ReadPlot3dFile(x).value();
  ASSERT_EQ(grid.blocks.size(), 1u);
  const StructuredBlock& g = grid.blocks[0];
  ASSERT_EQ(g.extent(0), 97);
  ASSERT_EQ(g.extent(1), 25);
  int non_positive = 0;
  for (int j = 0; j + 1 < g.extent(1); ++j) {
    for (int i = 0; i + 1 < g.extent(0); ++i) {
      const double* a = g.Point(i, j, 0);
      const double* b = g.Point(i + 1, j, 0);
      const double* c = g.Point(i + 1, j + 1, 0);
      const double* d = g.Point(i, j + 1, 0);
      non_positive += !((c[0] - a[0]) * (d[1] - b[1]) - (c[1] - a[1]) * (d[0] - b[0]) > 0);
    }
  }
  EXPECT_EQ(non_positive, 0);

  // Taken names and bad layers are refused, naming the field (usage errors exit 2).
  const Result taken = Cli(absl::StrCat("offset ", SharedDataPath("airfoils/naca0012.dat"),
                                        " --name=naca-og --layers=8 --points=65"));
  EXPECT_EQ(taken.exit_code, 1);
  EXPECT_THAT(taken.out, HasSubstr("ALREADY_EXISTS"));
  const Result bad = Cli(absl::StrCat("offset ", SharedDataPath("airfoils/naca0012.dat"),
                                      " --name=bad --first=-1e-5"));
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.out, HasSubstr("first_height = -1e-05"));
  EXPECT_THAT(Cli("list").out, ::testing::Not(HasSubstr("grids/bad")));
}

// The issue's command: a volume grid off the stored M6 wing surface, written as multi-block

// A profile in its source's units (the 30P30N slat, chord 153) with no length given: the
// defaults are fractions of the chord (first layer 1e-5, far field 50 chords, fit tolerance
// 1e-4), so it gets the grid a file in chords gets. With the first two absolute (1e-5 and 50
// in the file's unit) the interpolated grid folded 175 sub-cells and was refused; with the
// airfoil command's absolute 1e-4 the fit failed (178 control points for 211 points).
TEST_F(EndToEndTest, CliDefaultLengthsScaleWithTheProfile) {
  const std::string slat = SharedDataPath("airfoils/30p30n/30p30n_slat.dat");
  const Result offset = Cli(absl::StrCat("offset ", slat, " --name=slat --layers=64"));
  ASSERT_EQ(offset.exit_code, 0) << offset.out;
  EXPECT_THAT(offset.out, HasSubstr("first height 0.00153, distance 7634"));
  EXPECT_THAT(offset.out, HasSubstr("levels 0-2: 0 folded sub-cells"));
  const Result fit = Cli(absl::StrCat("airfoil ", slat));
  ASSERT_EQ(fit.exit_code, 0) << fit.out;
  EXPECT_THAT(fit.out, HasSubstr("(within 0.0153)"));
}
// Plot3D; its hexahedra are checked here.
TEST_F(EndToEndTest, CliMarchesAVolumeGridOffAStoredSurface) {
  const Result fit =
      Cli(absl::StrCat("fit ", SharedDataPath("surfaces/m6_small.fmt"), " --name=m6"));
  ASSERT_EQ(fit.exit_code, 0) << fit.out;
  const std::string x = (dir_ / "m6.x").string();
  const Result offset = Cli(absl::StrCat("offset m6 --layers 32 --first 1e-4 --far 5 -o ", x));
  ASSERT_EQ(offset.exit_code, 0) << offset.out;
  EXPECT_THAT(offset.out, HasSubstr("grids/m6-volume: volume grid of 9 blocks, 528033 points, "
                                    "marched outward"));
  EXPECT_THAT(offset.out, HasSubstr("symmetry planes: z = 0"));
  EXPECT_THAT(offset.out, HasSubstr("levels 0-2: 0 folded sub-cells"));
  const MultiBlockGrid grid = ReadPlot3dFile(x).value();
  ASSERT_EQ(grid.blocks.size(), 9u);
  for (size_t b = 0; b < grid.blocks.size(); ++b) {
    ASSERT_EQ(grid.blocks[b].extent(2), 33);
    EXPECT_GT(MinCornerJacobian(grid.blocks[b]), 0.0) << "block " << b;  // right-handed
  }
  // As CGNS, with its block interfaces: the grid's FULL view (12 MiB of nets) is over the
  // message limit, and the writer asked for it only for the connectivity.
  const std::string cgns = (dir_ / "m6.cgns").string();
  const Result as_cgns = Cli(absl::StrCat("eval m6-volume --level 0 -o ", cgns));
  ASSERT_EQ(as_cgns.exit_code, 0) << as_cgns.out;
  EXPECT_THAT(as_cgns.out, HasSubstr("9 block(s), 528033 points"));
  EXPECT_THAT(as_cgns.out, ::testing::Not(HasSubstr("note:")));  // a gap of rounding only
  const Result planar = Cli("offset grids/nothing --layers 8");
  EXPECT_EQ(planar.exit_code, 1);
  EXPECT_THAT(planar.out, HasSubstr("NOT_FOUND"));
}

TEST_F(EndToEndTest, PythonGeneratesOGrids) {
  const std::string script = (dir_ / "generate.py").string();
  ASSERT_TRUE(WriteFileAtomically(script, R"(
import sys
import numpy as np
from splinegrid import Client, SplinegridError

with Client(sys.argv[1]) as client:
    r = client.generate("py-sc2", airfoil=sys.argv[2], wall_points=129, layers=32,
                        first_height=1e-4, distance=20, allow_folds=True)
    g = client.evaluate(r.grid.name, level=0)[0].points[0]  # (nj, ni, 2)
    a, b, c, d = g[:-1, :-1], g[:-1, 1:], g[1:, 1:], g[1:, :-1]
    area = ((c[..., 0] - a[..., 0]) * (d[..., 1] - b[..., 1])
            - (c[..., 1] - a[..., 1]) * (d[..., 0] - b[..., 0]))
    print("generated", r.grid.name, g.shape, "negative", r.report.quality.negative_cells,
          "positive", bool(area.min() > 0), "revision", r.fit.revision)
    points = np.loadtxt(sys.argv[2], skiprows=1)
    t = client.generate("py-points", points=points, method="offsets", wall_points=65,
                        layers=16, first_height=1e-3, distance=10, allow_folds=True)
    print("points", t.report.extents.i, t.report.extents.j, t.report.profile.num_points)
    try:
        client.generate("py-bad", points=points, first_height=-1.0)
    except SplinegridError as error:
        print("refused", error.code, "first_height" in error.message)
    print("grids", " ".join(sorted(grid.name for grid in client.list())))
)")
                  .ok());
  const Result python = RunCommand(
      absl::StrCat("PYTHONPATH=", SPLINEGRID_BINARY_DIR, "/python /usr/bin/python3 ", script,
                   " 127.0.0.1:", port_, " ", SharedDataPath("airfoils/sc20714.dat")));
  ASSERT_EQ(python.exit_code, 0) << python.out;
  EXPECT_THAT(python.out,
              HasSubstr("generated grids/py-sc2 (33, 129, 2) negative 0 positive True revision 1"));
  EXPECT_THAT(python.out, HasSubstr("points 65 17 "));
  EXPECT_THAT(python.out, HasSubstr("refused INVALID_ARGUMENT True"));
  EXPECT_THAT(python.out, HasSubstr("grids grids/py-points grids/py-sc2\n"));
}

TEST_F(EndToEndTest, PythonFairsAndPlotsWallCurvature) {
  const std::string png = (dir_ / "curvature.png").string();
  const Result python = RunCommand(
      absl::StrCat("PYTHONPATH=", SPLINEGRID_BINARY_DIR, "/python /usr/bin/python3 ", kSource,
                   "/python/examples/fair_and_plot.py --server=127.0.0.1:", port_,
                   " --grid=", SharedDataPath("grids/n0012_113-33.p2dfmt"), " --png=", png));
  ASSERT_EQ(python.exit_code, 0) << python.out;
  EXPECT_THAT(python.out, HasSubstr("fairing weight"));
  const std::string image = ReadFileToString(png).value();
  ASSERT_GT(image.size(), 1000u);
  EXPECT_EQ(image.substr(1, 3), "PNG");
}

TEST_F(EndToEndTest, CliDeformsRefusesAFoldAndGetsTheDeformedRevision) {
  ASSERT_EQ(
      Cli(absl::StrCat("fit ", SharedDataPath("grids/n0012_113-33.p2dfmt"), " --name=naca --kinds"))
          .exit_code,
      0);
  const Result deform =
      Cli("deform naca --rotate=5 --about=0.25,0 --reference=1 --base=1 --time=0.5 --step=3 "
          "--check_level=1");
  ASSERT_EQ(deform.exit_code, 0) << deform.out;
  EXPECT_THAT(deform.out,
              HasSubstr("grids/naca revision 2: deformed revision 1, time 0.5, step 3"));
  EXPECT_THAT(deform.out, HasSubstr("fold check at level 1"));
  EXPECT_THAT(deform.out, HasSubstr("Jacobian ratio min 0.9"));
  EXPECT_THAT(deform.out, HasSubstr("moved controls"));
  EXPECT_THAT(deform.out, HasSubstr("wall orthogonality change"));

  // Everything a third of a chord away stays: turning the wall by 60 degrees tears the nose.
  const Result fold =
      Cli("deform naca --rotate=60 --about=0.25,0 --decay_radius=0.3 --reference=1 --step=4");
  EXPECT_EQ(fold.exit_code, 1) << fold.out;
  EXPECT_THAT(fold.out, HasSubstr("FAILED_PRECONDITION"));
  EXPECT_THAT(fold.out, HasSubstr("folds"));
  // A stale base revision is ABORTED.
  const Result stale = Cli("deform naca --rotate=1 --base=1");
  EXPECT_EQ(stale.exit_code, 1) << stale.out;
  EXPECT_THAT(stale.out, HasSubstr("ABORTED"));

  // Only the good deformation was stored.
  const Result get = Cli("get naca");
  ASSERT_EQ(get.exit_code, 0) << get.out;
  EXPECT_THAT(get.out, HasSubstr("revision 2 of 2"));
  EXPECT_THAT(get.out, HasSubstr("origin DEFORM of revision 1, time 0.5, step 3"));
  const Result by_step = Cli("get naca --step=3 --json");
  ASSERT_EQ(by_step.exit_code, 0) << by_step.out;
  EXPECT_THAT(by_step.out, HasSubstr("\"origin\": \"REVISION_ORIGIN_DEFORM\""));
  EXPECT_THAT(by_step.out, HasSubstr("\"min_jacobian_ratio\""));

  // A face range instead of the wall (the airfoil part of the C-grid's j = 0 line), as JSON.
  const Result range =
      Cli("deform naca --rotate=-3 --about=0.25,0 --boundary=0:jmin:20:92 --reference=1 --json");
  ASSERT_EQ(range.exit_code, 0) << range.out;
  EXPECT_THAT(range.out, HasSubstr("\"revision\": \"3\""));
  EXPECT_THAT(range.out, HasSubstr("\"moved_controls\""));
  const Result eval =
      Cli(absl::StrCat("eval naca --step=3 --level=1 -o ", (dir_ / "s.vts").string()));
  ASSERT_EQ(eval.exit_code, 0) << eval.out;
  EXPECT_THAT(eval.out, HasSubstr("(revision 2)"));

  const Result usage = Cli("deform naca --rotate=5 --about=1");
  EXPECT_EQ(usage.exit_code, 2);
  EXPECT_THAT(usage.out, HasSubstr("--about"));
  EXPECT_EQ(Cli("deform naca --rotate=5 --boundary=0:lmin").exit_code, 2);
  EXPECT_EQ(Cli("deform naca").exit_code, 2);
  // A step at rest is a motion too (a scripted series passes through angle 0), as in the C and
  // Python clients: stored, not a usage error.
  const Result rest = Cli("deform naca --rotate=0 --about=0.25,0 --reference=1 --step=5");
  EXPECT_EQ(rest.exit_code, 0) << rest.out;
  EXPECT_THAT(rest.out, HasSubstr("grids/naca revision 4: deformed revision 1"));
}

TEST_F(EndToEndTest, CliWatchPrintsRevisionsUntilTheGridIsDeletedOrInterrupted) {
  ASSERT_EQ(Cli(absl::StrCat("fit ", SharedDataPath("grids/n0012_113-33.p2dfmt"),
                             " --name=watched --kinds"))
                .exit_code,
            0);
  // In the background; --after=1: revisions after the fit, the stored ones first, so the
  // deformations below are seen however late the watch starts.
  const std::string out = (dir_ / "watch.out").string();
  const std::string watch =
      absl::StrCat(kBinary, " watch watched --after=1 --server=127.0.0.1:", port_);
  RunCommand(absl::StrCat("(timeout 60 ", watch, " > ", out, " 2>&1; echo exit=$? >> ", out,
                          ") > /dev/null 2>&1 < /dev/null &"));
  const std::string deform = "deform watched --about=0.25,0 --reference=1 ";
  ASSERT_EQ(Cli(deform + "--rotate=2 --time=0.1 --step=1").exit_code, 0);
  ASSERT_EQ(Cli(deform + "--rotate=4 --time=0.2 --step=2").exit_code, 0);
  // Deleting the grid ends the stream, and the watch with it.
  std::string text;
  for (int i = 0; i < 100 && text.find("revision 3") == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    text = ReadFileToString(out).value_or("");
  }
  ASSERT_EQ(Cli("rm watched").exit_code, 0);
  for (int i = 0; i < 200 && text.find("exit=") == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    text = ReadFileToString(out).value_or("");
  }
  EXPECT_THAT(text, HasSubstr("revision 2 origin DEFORM parent 1 time 0.1 step 1"));
  EXPECT_THAT(text, HasSubstr("revision 3 origin DEFORM parent 1 time 0.2 step 2"));
  EXPECT_EQ(text.find("revision 1 "), std::string::npos) << text;  // --after=1
  EXPECT_THAT(text, HasSubstr("the stream ended"));
  EXPECT_THAT(text, HasSubstr("exit=0"));

  // ^C ends a watch cleanly (exit 0); --json prints one object per line.
  ASSERT_EQ(Cli(absl::StrCat("fit ", SharedDataPath("grids/n0012_113-33.p2dfmt"),
                             " --name=again --ctl=40,16 --allow_folds"))
                .exit_code,
            3);  // stored with folds (issue 13.3)
  const Result interrupted =
      RunCommand(absl::StrCat("timeout --preserve-status -s INT 2 ", kBinary,
                              " watch again --json --server=127.0.0.1:", port_));
  EXPECT_EQ(interrupted.exit_code, 0) << interrupted.out;
  EXPECT_THAT(interrupted.out, HasSubstr("\"origin\":\"REVISION_ORIGIN_FIT\""));
  EXPECT_THAT(interrupted.out, HasSubstr("interrupted"));
  const Result unknown = Cli("watch nope");
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_THAT(unknown.out, HasSubstr("NOT_FOUND"));
}

// A watch is a monitor: it rides out a restart of its server (here 3 s down, longer than a
// one-off command retries) and goes on after the last revision it printed.
TEST_F(EndToEndTest, CliWatchRidesOutAServerRestart) {
  const std::vector<std::string> durable = {
      absl::StrCat("--store=dir:", (dir_ / "store").string())};
  ASSERT_EQ(Stop(), 0);
  ASSERT_NO_FATAL_FAILURE(StartServer(durable));
  ASSERT_EQ(Cli(absl::StrCat("fit ", SharedDataPath("grids/n0012_113-33.p2dfmt"),
                             " --name=watched --kinds"))
                .exit_code,
            0);
  const std::string out = (dir_ / "watch.out").string();
  RunCommand(absl::StrCat("(timeout 60 ", kBinary,
                          " watch watched --after=1 --server=127.0.0.1:", port_, " > ", out,
                          " 2>&1; echo exit=$? >> ", out, ") > /dev/null 2>&1 < /dev/null &"));
  const std::string deform = "deform watched --about=0.25,0 --reference=1 ";
  ASSERT_EQ(Cli(deform + "--rotate=2 --time=0.1 --step=1").exit_code, 0);
  auto wait_for = [&](const std::string& what) {
    std::string text;
    for (int i = 0; i < 300 && text.find(what) == std::string::npos; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      text = ReadFileToString(out).value_or("");
    }
    return text;
  };
  ASSERT_THAT(wait_for("revision 2 "), HasSubstr("revision 2 ")) << ReadLog();
  ASSERT_EQ(Stop(SIGKILL), -1);
  std::this_thread::sleep_for(std::chrono::seconds(3));
  EXPECT_THAT(ReadFileToString(out).value_or(""), Not(HasSubstr("exit=")));
  ASSERT_NO_FATAL_FAILURE(StartServer(durable));
  ASSERT_EQ(Cli(deform + "--rotate=4 --time=0.2 --step=2").exit_code, 0);
  const std::string text = wait_for("revision 3 ");
  EXPECT_THAT(text, HasSubstr("revision 3 origin DEFORM parent 1 time 0.2 step 2")) << ReadLog();
  EXPECT_EQ(text.find("revision 2 "), text.rfind("revision 2 ")) << text;  // not repeated
  ASSERT_EQ(Cli("rm watched").exit_code, 0);
  EXPECT_THAT(wait_for("exit="), HasSubstr("exit=0"));
}

TEST_F(EndToEndTest, CliExportRemoveImportGivesByteIdenticalEvaluations) {
  ASSERT_NO_FATAL_FAILURE(MakeGridWithRevisions("naca"));
  // The evaluations to compare: the latest (deformed) revision, the fit, the step.
  const std::vector<std::string> evals = {"--level=1", "--revision=1 --level=0",
                                          "--step=4 --res=57,17"};
  const auto evaluate = [&](const std::string& name, const std::string& tag) {
    std::vector<std::string> files;
    for (size_t e = 0; e < evals.size(); ++e) {
      const std::string out = (dir_ / absl::StrCat(name, "-", tag, "-", e, ".xyz")).string();
      const Result eval = Cli(absl::StrCat("eval ", name, " ", evals[e], " -o ", out));
      EXPECT_EQ(eval.exit_code, 0) << eval.out;
      files.push_back(ReadFileToString(out).value_or(""));
    }
    return files;
  };
  const std::vector<std::string> before = evaluate("naca", "before");
  const std::string get_before = Cli("get naca").out;

  const std::string archive = (dir_ / "naca.sgrid").string();
  const Result exported = Cli(absl::StrCat("export naca -o ", archive));
  ASSERT_EQ(exported.exit_code, 0) << exported.out;
  EXPECT_THAT(exported.out,
              HasSubstr(absl::StrCat("exported grids/naca to ", archive, ": 3 ", "revision(s), ")));
  EXPECT_EQ(ReadFileToString(archive).value().rfind("splinegrid-records\n", 0), 0u);
  ASSERT_EQ(Cli("rm naca").exit_code, 0);
  EXPECT_EQ(Cli("get naca").exit_code, 1);

  const Result imported = Cli(absl::StrCat("import ", archive));
  ASSERT_EQ(imported.exit_code, 0) << imported.out;
  EXPECT_THAT(imported.out,
              HasSubstr(absl::StrCat("imported ", archive, " as grids/naca (3 revision(s))")));
  EXPECT_THAT(imported.out, HasSubstr("revision 3 of 3"));
  const std::vector<std::string> after = evaluate("naca", "after");
  for (size_t e = 0; e < evals.size(); ++e) {
    EXPECT_FALSE(before[e].empty());
    EXPECT_TRUE(after[e] == before[e]) << "eval " << evals[e] << " differs after the round trip";
  }
  EXPECT_EQ(Cli("get naca").out, get_before);

  // Under a new name, next to the original; the archive's own name is taken now.
  const Result copy = Cli(absl::StrCat("import ", archive, " --name=copy"));
  ASSERT_EQ(copy.exit_code, 0) << copy.out;
  EXPECT_THAT(copy.out, HasSubstr("as grids/copy (3 revision(s))"));
  EXPECT_TRUE(evaluate("copy", "copy") == before);
  const Result taken = Cli(absl::StrCat("import ", archive));
  EXPECT_EQ(taken.exit_code, 1) << taken.out;
  EXPECT_THAT(taken.out, HasSubstr("ALREADY_EXISTS"));

  const Result usage = Cli("export naca");
  EXPECT_EQ(usage.exit_code, 2);
  EXPECT_THAT(usage.out, HasSubstr("usage: splinegrid export NAME -o FILE.sgrid"));
  const Result unknown = Cli(absl::StrCat("export nope -o ", (dir_ / "nope.sgrid").string()));
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_THAT(unknown.out, HasSubstr("NOT_FOUND"));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "nope.sgrid"));
}

TEST_F(EndToEndTest, CliImportOfADamagedFileFailsAndStoresNothing) {
  ASSERT_NO_FATAL_FAILURE(MakeGridWithRevisions("naca"));
  const std::string archive = (dir_ / "naca.sgrid").string();
  ASSERT_EQ(Cli(absl::StrCat("export naca -o ", archive)).exit_code, 0);
  const std::string whole = ReadFileToString(archive).value();
  const std::string list_before = Cli("list").out;

  // Cut in half: the file ends inside a record.
  const std::string half = (dir_ / "half.sgrid").string();
  ASSERT_TRUE(WriteFileAtomically(half, whole.substr(0, whole.size() / 2)).ok());
  const Result cut = Cli(absl::StrCat("import ", half, " --name=half"));
  EXPECT_NE(cut.exit_code, 0) << cut.out;
  EXPECT_THAT(cut.out, HasSubstr(absl::StrCat("record file '", half, "': record ")));
  EXPECT_THAT(cut.out, HasSubstr("truncated record"));
  // A damaged byte in the last record.
  std::string flipped = whole;
  flipped[flipped.size() - 3] ^= 0x10;
  const std::string damaged = (dir_ / "damaged.sgrid").string();
  ASSERT_TRUE(WriteFileAtomically(damaged, flipped).ok());
  const Result crc = Cli(absl::StrCat("import ", damaged, " --name=damaged"));
  EXPECT_NE(crc.exit_code, 0) << crc.out;
  EXPECT_THAT(crc.out, HasSubstr("CRC mismatch"));
  // A Plot3D file is not an archive: the tool says what to do instead.
  const std::string plot3d = SharedDataPath("grids/n0012_113-33.p2dfmt");
  const Result grid = Cli(absl::StrCat("import ", plot3d));
  EXPECT_EQ(grid.exit_code, 2) << grid.out;
  EXPECT_THAT(grid.out, HasSubstr(absl::StrCat(plot3d, " is not a splinegrid archive")));
  EXPECT_THAT(grid.out, HasSubstr(absl::StrCat("use `splinegrid fit ", plot3d, "`")));

  EXPECT_EQ(Cli("list").out, list_before);  // nothing stored
}

TEST_F(EndToEndTest, ArchivesMoveBetweenTheCppAndPythonClients) {
  ASSERT_NO_FATAL_FAILURE(MakeGridWithRevisions("naca"));
  const std::string from_cpp = (dir_ / "cpp.sgrid").string();
  const std::string from_python = (dir_ / "python.sgrid").string();
  ASSERT_EQ(Cli(absl::StrCat("export naca -o ", from_cpp)).exit_code, 0);
  // Python imports the C++ client's file and exports its copy; both files hold the same
  // records (the same grid, the same revisions).
  const std::string script = (dir_ / "archives.py").string();
  ASSERT_TRUE(WriteFileAtomically(script, R"(
import sys
from splinegrid import Client, records

server, from_cpp, from_python = sys.argv[1:4]
with Client(server) as client:
    grid = client.import_archive(from_cpp, name="py-copy")
    print("imported", grid.name, len(grid.revisions))
    summary = client.export_grid("py-copy", from_python)
    print("exported", summary.revisions, "revisions", summary.source_chunks, "chunks")
    a, b = list(records.read_records(from_cpp)), list(records.read_records(from_python))
    print("records", len(a), len(b), "same after the header", a[1:] == b[1:])
)")
                  .ok());
  const Result python =
      RunCommand(absl::StrCat("PYTHONPATH=", SPLINEGRID_BINARY_DIR, "/python /usr/bin/python3 ",
                              script, " 127.0.0.1:", port_, " ", from_cpp, " ", from_python));
  ASSERT_EQ(python.exit_code, 0) << python.out;
  EXPECT_THAT(python.out, HasSubstr("imported grids/py-copy 3"));
  EXPECT_THAT(python.out, HasSubstr("exported 3 revisions"));
  EXPECT_THAT(python.out, HasSubstr("same after the header True"));
  // The C++ client imports the Python client's file.
  const Result imported = Cli(absl::StrCat("import ", from_python, " --name=cpp-copy"));
  ASSERT_EQ(imported.exit_code, 0) << imported.out;
  EXPECT_THAT(imported.out, HasSubstr("as grids/cpp-copy (3 revision(s))"));
  std::vector<std::string> evaluations;
  for (const char* name : {"naca", "py-copy", "cpp-copy"}) {
    const std::string out = (dir_ / absl::StrCat(name, ".xyz")).string();
    ASSERT_EQ(Cli(absl::StrCat("eval ", name, " --level=1 -o ", out)).exit_code, 0);
    evaluations.push_back(ReadFileToString(out).value());
  }
  EXPECT_TRUE(evaluations[1] == evaluations[0]);
  EXPECT_TRUE(evaluations[2] == evaluations[0]);
}

TEST_F(EndToEndTest, CppPitchingExampleRunsWithoutFolds) {
  const std::string acked = (dir_ / "cpp.acked").string();
  const Result run = RunCommand(absl::StrCat(
      SPLINEGRID_BINARY_DIR, "/splinegrid_pitching --server=127.0.0.1:", port_,
      " --steps=10 --amplitude=20 --grid=", SharedDataPath("grids/n0012_pitch_257x129.fmt"),
      " --acked=", acked, " --keep"));
  ASSERT_EQ(run.exit_code, 0) << run.out;
  ExpectAckedRevisionsStored("pitching-cpp", acked, 10);
  ASSERT_EQ(Cli("rm pitching-cpp").exit_code, 0);
  EXPECT_THAT(run.out, HasSubstr("p50       p90       p99       max"));
  EXPECT_THAT(run.out, HasSubstr("  deform "));
  EXPECT_THAT(run.out, HasSubstr("  evaluate "));
  EXPECT_THAT(run.out, HasSubstr("  step "));
  EXPECT_THAT(run.out, HasSubstr("step  10 "));
  EXPECT_THAT(run.out, HasSubstr("folds: 0 (folded cells over all steps), 0 steps refused"));
  EXPECT_THAT(Cli("list").out, ::testing::Not(HasSubstr("pitching")));
  // Without --keep the grid is deleted at the end.
  ASSERT_EQ(
      RunCommand(absl::StrCat(SPLINEGRID_BINARY_DIR,
                              "/splinegrid_pitching --quiet --steps=2 --server=127.0.0.1:", port_,
                              " --grid=", SharedDataPath("grids/n0012_pitch_257x129.fmt")))
          .exit_code,
      0);
  EXPECT_THAT(Cli("list").out, ::testing::Not(HasSubstr("pitching")));
}

TEST_F(EndToEndTest, PythonPitchingExampleRunsWithoutFolds) {
  const std::string acked = (dir_ / "python.acked").string();
  const Result python = RunCommand(absl::StrCat(
      "PYTHONPATH=", SPLINEGRID_BINARY_DIR, "/python /usr/bin/python3 ", kSource,
      "/python/examples/pitching.py --server=127.0.0.1:", port_,
      " --steps=10 --amplitude=20 --grid=", SharedDataPath("grids/n0012_pitch_257x129.fmt"),
      " --acked=", acked, " --keep"));
  ASSERT_EQ(python.exit_code, 0) << python.out;
  ExpectAckedRevisionsStored("pitching-py", acked, 10);
  EXPECT_THAT(python.out, HasSubstr("p50       p90       p99       max"));
  EXPECT_THAT(python.out, HasSubstr("  deform "));
  EXPECT_THAT(python.out, HasSubstr("  evaluate "));
  EXPECT_THAT(python.out, HasSubstr("step  10 "));
  EXPECT_THAT(python.out, HasSubstr("folds: 0 (folded cells over all steps), 0 steps refused"));
}

TEST_F(EndToEndTest, PitchingClientsAcknowledgeStepsWhoseAnswersWereLost) {
  // Through a proxy that loses DeformGrid answers after the server stored them, refuses calls
  // with UNAVAILABLE and breaks evaluations off: every step is still acknowledged exactly once,
  // with the revision the server stored for it.
  const std::string port_file = (dir_ / "proxy.port").string();
  const Result started =
      RunCommand(absl::StrCat("PYTHONPATH=", SPLINEGRID_BINARY_DIR, "/python /usr/bin/python3 ",
                              kSource, "/tests/e2e/fault_proxy.py 127.0.0.1:", port_, " ",
                              port_file, " > ", (dir_ / "proxy.log").string(), " 2>&1 & echo $!"));
  const pid_t proxy = std::atoi(started.out.c_str());
  ASSERT_GT(proxy, 0) << started.out;
  std::string proxy_port;
  for (int i = 0; i < 200 && proxy_port.empty(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
    proxy_port = ReadFileToString(port_file).value_or("");
  }
  ASSERT_FALSE(proxy_port.empty()) << ReadFileToString((dir_ / "proxy.log").string()).value_or("");
  const std::string through = absl::StrCat(" --server=127.0.0.1:", proxy_port,
                                           " --steps=12 --amplitude=20 --quiet --keep --grid=",
                                           SharedDataPath("grids/n0012_pitch_257x129.fmt"));
  const std::string cpp_acked = (dir_ / "cpp.acked").string();
  const Result cpp = RunCommand(
      absl::StrCat(SPLINEGRID_BINARY_DIR, "/splinegrid_pitching", through, " --acked=", cpp_acked));
  const std::string python_acked = (dir_ / "python.acked").string();
  const Result python = RunCommand(
      absl::StrCat("PYTHONPATH=", SPLINEGRID_BINARY_DIR, "/python /usr/bin/python3 ", kSource,
                   "/python/examples/pitching.py", through, " --acked=", python_acked));
  kill(proxy, SIGTERM);
  for (const auto& [run, name, acked] : {std::tuple(cpp, "pitching-cpp", cpp_acked),
                                         std::tuple(python, "pitching-py", python_acked)}) {
    ASSERT_EQ(run.exit_code, 0) << run.out;
    EXPECT_THAT(run.out, HasSubstr("had been stored: acknowledged"));
    EXPECT_THAT(run.out, HasSubstr("folds: 0 (folded cells over all steps), 0 steps refused "
                                   "by the server, 0 failed"));
    ExpectAckedRevisionsStored(name, acked, 12);
    // One deformed revision per step: nothing was stored twice.
    EXPECT_THAT(Cli(absl::StrCat("get ", name)).out, HasSubstr(" of 13: "));
  }
}

TEST_F(EndToEndTest, PitchingClientsSurviveAServerKilledAndRestartedWithADurableStore) {
  // The server keeps its grids in a directory; SIGKILLed in the middle of a coupling run and
  // started again, it is reached by the retries (the channel reconnects while they wait), and
  // every step the client acknowledged is stored with its revision.
  const std::vector<std::string> flags = {absl::StrCat("--store=dir:", (dir_ / "store").string()),
                                          "--keep_revisions=1000"};
  ASSERT_EQ(Stop(), 0);
  ASSERT_NO_FATAL_FAILURE(StartServer(flags));
  constexpr int kSteps = 60;
  const std::string common = absl::StrCat(
      " --server=127.0.0.1:", port_, " --steps=", kSteps,
      " --amplitude=10 --quiet --keep --grid=", SharedDataPath("grids/n0012_pitch_257x129.fmt"));
  const std::vector<std::pair<std::string, std::string>> runs = {
      {"pitching-cpp", absl::StrCat(SPLINEGRID_BINARY_DIR, "/splinegrid_pitching", common)},
      {"pitching-py",
       absl::StrCat("PYTHONPATH=", SPLINEGRID_BINARY_DIR, "/python /usr/bin/python3 ", kSource,
                    "/python/examples/pitching.py", common)}};
  for (const auto& [name, command] : runs) {
    const std::string acked = (dir_ / absl::StrCat(name, ".acked")).string();
    Result run;
    std::thread client([&] { run = RunCommand(absl::StrCat(command, " --acked=", acked)); });
    int lines = 0;
    for (int i = 0; i < 600 && lines < kSteps / 3; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      lines = static_cast<int>(ReadAcked(acked).size());
    }
    EXPECT_GE(lines, kSteps / 3) << "the run did not get going";
    Stop(SIGKILL);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    ASSERT_NO_FATAL_FAILURE(StartServer(flags));
    client.join();
    ASSERT_EQ(run.exit_code, 0) << name << ":\n" << run.out;
    EXPECT_THAT(run.out, HasSubstr("0 steps refused by the server, 0 failed"));
    ExpectAckedRevisionsStored(name, acked, kSteps);
    EXPECT_THAT(Cli(absl::StrCat("get ", name)).out,
                HasSubstr(absl::StrCat(" of ", kSteps + 1, ": ")));
  }
}

TEST_F(EndToEndTest, SigtermDrainsAndExitsZeroWithOneLogLinePerCall) {
  ASSERT_EQ(
      Cli(absl::StrCat("fit ", SharedDataPath("surfaces/m6_small.fmt"), " --name=m6 --ctl=8,8"))
          .exit_code,
      0);
  EXPECT_EQ(Cli("health").exit_code, 0);
  EXPECT_EQ(Stop(), 0);
  const std::string log = ReadLog();
  EXPECT_THAT(log, HasSubstr("ImportGrid grids/m6 OK"));
  EXPECT_THAT(log, HasSubstr("FitGrid grids/m6 OK"));
  EXPECT_THAT(log, HasSubstr("SIGTERM received"));
  EXPECT_THAT(log, HasSubstr("stopped"));
  // After the stop nothing answers.
  EXPECT_NE(Cli("health --timeout=2s").exit_code, 0);
}

}  // namespace
}  // namespace splinegrid::testing
