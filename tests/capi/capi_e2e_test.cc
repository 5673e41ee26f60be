// The C API and the Fortran module against the real `splinegrid serve` on a free loopback
// port: the C test program (capi_test.c) checks every call and its error paths; the Fortran
// pitching example runs the C++ example's coupling loop and must end where the C++ example
// ends (same revisions, same Jacobian ratios per step, the same evaluated points).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/client.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"
#include "tests/store/server_process.h"

namespace splinegrid {
namespace {

using testing::ChildProcess;
using ::testing::HasSubstr;

const std::string kBinary = SPLINEGRID_BINARY_DIR "/splinegrid";

class CApiTest : public ::testing::Test {
 protected:
  void SetUp() override {
    port_ = testing::FreePort();
    dir_ = std::filesystem::temp_directory_path() / absl::StrCat("splinegrid-capi-", getpid());
    std::filesystem::create_directories(dir_);
    server_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{kBinary, "serve", absl::StrCat("--address=127.0.0.1:", port_),
                                 "--threads=2", "--drain_notice=0s"},
        (dir_ / "server.log").string());
    ASSERT_TRUE(testing::WaitForPort(port_, absl::Seconds(20))) << server_->ReadLog();
  }
  void TearDown() override {
    EXPECT_EQ(server_->Stop(SIGTERM), 0) << server_->ReadLog();
    std::filesystem::remove_all(dir_);
  }
  std::string Address() const { return absl::StrCat("127.0.0.1:", port_); }

  int port_ = 0;
  std::filesystem::path dir_;
  std::unique_ptr<ChildProcess> server_;
};

TEST_F(CApiTest, CProgramPassesEveryCheck) {
  // A CGNS file as users get one: Debian's plot3d_to_cgns from a shared multi-block surface.
  const std::string cgns = (dir_ / "m6.cgns").string();
  std::string out;
  ASSERT_EQ(testing::RunShell(absl::StrCat("plot3d_to_cgns -f -d ",
                                           SharedDataPath("surfaces/m6_small.fmt"), " ", cgns),
                              &out),
            0)
      << out << "(plot3d_to_cgns is in Debian's cgns-convert, installed by .ci/setup)";
  const int code = testing::RunShell(
      absl::StrCat(SPLINEGRID_CAPI_TEST, " ", Address(), " 127.0.0.1:", testing::FreePort(), " ",
                   SharedDataPath("grids/n0012_113-33.p2dfmt"), " ", cgns, " 2>&1"),
      &out);
  EXPECT_EQ(code, 0) << out;
  EXPECT_THAT(out, ::testing::ContainsRegex("capi_test: [0-9]+ checks, 0 failed")) << out;
}

// "revision R min Jacobian ratio X" of every step line, by step.
std::map<int, std::string> StepLines(const std::string& out) {
  static const std::regex kStep(
      R"(step +([0-9]+) t [0-9.]+ alpha +[-0-9.]+ (revision +[0-9]+ min Jacobian ratio [0-9.]+))");
  std::map<int, std::string> steps;
  for (std::sregex_iterator it(out.begin(), out.end(), kStep), end; it != end; ++it) {
    steps[std::stoi((*it)[1])] = (*it)[2];
  }
  return steps;
}

TEST_F(CApiTest, FortranPitchingExampleMatchesTheCppExample) {
  if (std::string(SPLINEGRID_FORTRAN_PITCHING).empty()) {
    GTEST_SKIP() << "no Fortran compiler was found at configure time (Debian: gfortran), so "
                    "splinegrid_pitching_fortran was not built";
  }
  const std::string grid = SharedDataPath("grids/n0012_pitch_257x129.fmt");
  const std::string common =
      absl::StrCat(" --steps 8 --amplitude 12 --grid ", grid, " --keep");
  std::string cpp, fortran, help;
  ASSERT_EQ(testing::RunShell(absl::StrCat(SPLINEGRID_BINARY_DIR, "/splinegrid_pitching --server ",
                                           Address(), common, " --name pitch-cpp 2>&1"),
                              &cpp),
            0)
      << cpp;
  // The server from $SPLINEGRID_SERVER, as the C++ example takes it.
  const std::string points = (dir_ / "fortran-points.txt").string();
  ASSERT_EQ(testing::RunShell(absl::StrCat("SPLINEGRID_SERVER=", Address(), " ",
                                           SPLINEGRID_FORTRAN_PITCHING, common,
                                           " --name pitch-f --output ", points, " 2>&1"),
                              &fortran),
            0)
      << fortran;
  // --server wins over the variable.
  std::string given;
  ASSERT_EQ(testing::RunShell(absl::StrCat("SPLINEGRID_SERVER=127.0.0.1:1 ",
                                           SPLINEGRID_FORTRAN_PITCHING, " --server ", Address(),
                                           " --steps 1 --grid ", grid, " --name pitch-g 2>&1"),
                              &given),
            0)
      << given;
  ASSERT_EQ(testing::RunShell(absl::StrCat(SPLINEGRID_FORTRAN_PITCHING, " --help 2>&1"), &help), 0);
  EXPECT_EQ(help.rfind("usage: splinegrid_pitching_fortran [--server host:port (default: "
                       "$SPLINEGRID_SERVER",
                       0),
            0u)
      << help;
  EXPECT_THAT(fortran, HasSubstr("grids/pitch-f revision 1: 33153 points -> "));
  EXPECT_THAT(fortran, HasSubstr("p50       p90       p99       max"));
  EXPECT_THAT(fortran, HasSubstr("  (server) "));
  EXPECT_THAT(fortran, HasSubstr("folds: 0 (folded cells over all steps), 0 steps refused by the "
                                 "server, 0 failed"));
  EXPECT_THAT(fortran, HasSubstr("final revision 9: 513 x 257 points evaluated"));
  // Step by step the same revisions and the same fold-check figures as the C++ example.
  const std::map<int, std::string> cpp_steps = StepLines(cpp), fortran_steps = StepLines(fortran);
  EXPECT_EQ(cpp_steps.size(), 8u) << cpp;
  EXPECT_EQ(fortran_steps, cpp_steps) << fortran;

  // The Fortran client's array of the last step holds the points the C++ client evaluates
  // from the C++ example's last revision.
  auto client = client::Client::Connect(Address());
  const v1::Grid cpp_grid = client->Get("pitch-cpp").value();
  const v1::Grid fortran_grid = client->Get("pitch-f").value();
  EXPECT_EQ(cpp_grid.latest_revision(), 9);
  EXPECT_EQ(fortran_grid.latest_revision(), cpp_grid.latest_revision());
  v1::EvaluateGridRequest request;
  request.set_name("pitch-cpp");
  request.set_refinement_level(1);
  const client::EvaluatedGrid evaluated = client->Evaluate(request).value();
  ASSERT_EQ(evaluated.blocks.size(), 1u);
  const StructuredBlock& want = evaluated.blocks[0].points;
  std::ifstream file(points);
  int ni = 0, nj = 0, dim = 0;
  file >> ni >> nj >> dim;
  ASSERT_EQ(ni, want.extent(0));
  ASSERT_EQ(nj, want.extent(1));
  ASSERT_EQ(dim, want.spatial_dim());
  // Written with 17 significant digits: the same doubles up to the last bit's rounding.
  constexpr double kRelative = 1e-15;
  double worst = 0.0;
  for (int64_t v = 0; v < static_cast<int64_t>(want.coords().size()); ++v) {
    double got = 0.0;
    ASSERT_TRUE(file >> got) << "value " << v;
    worst = std::max(worst, std::abs(got - want.coords()[v]) / std::max(1.0, std::abs(got)));
  }
  EXPECT_LE(worst, kRelative);
}

}  // namespace
}  // namespace splinegrid
