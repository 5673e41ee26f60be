// The `dir:` store survives a crash: 100 DeformGrid calls while the server is killed with
// SIGKILL at a random point; after a restart every acknowledged revision is there and evaluates
// bitwise as before, and nothing half-written is visible.
#include <signal.h>

#include <atomic>
#include <cstring>
#include <filesystem>
#include <map>
#include <random>
#include <thread>

#include "absl/strings/str_cat.h"
#include "client/client.h"
#include "core/io/file_util.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"
#include "tests/store/server_process.h"

namespace splinegrid::testing {
namespace {

namespace fs = std::filesystem;

const std::string kBinary = SPLINEGRID_BINARY_DIR "/splinegrid";

class DirStoreCrashTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / absl::StrCat("splinegrid-dir-crash-", getpid());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    server_.reset();
    fs::remove_all(dir_);
  }

  // Starts a server on the store directory; its client, without retries (a crash must show).
  std::unique_ptr<client::Client> Start() {
    port_ = FreePort();
    server_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{kBinary, "serve", absl::StrCat("--address=127.0.0.1:", port_),
                                 absl::StrCat("--store=dir:", (dir_ / "store").string()),
                                 "--threads=2", "--keep_revisions=1000", "--shutdown_grace=2s",
                                 "--drain_notice=0s"},
        (dir_ / "server.log").string());
    EXPECT_TRUE(WaitForPort(port_, absl::Seconds(20))) << server_->ReadLog();
    client::ClientOptions options;
    options.timeout = absl::Seconds(60);
    options.retry.max_attempts = 1;
    return client::Client::Connect(absl::StrCat("127.0.0.1:", port_), options);
  }

  // `revision` evaluated at level 0.
  static absl::StatusOr<client::EvaluatedGrid> EvaluateAt(client::Client& client,
                                                          int64_t revision) {
    v1::EvaluateGridRequest request;
    request.set_name("grids/pitch");
    request.set_revision(revision);
    return client.Evaluate(request);
  }
  // Every point of an evaluation, as raw doubles.
  static std::vector<double> Values(const client::EvaluatedGrid& grid) {
    std::vector<double> values;
    for (const auto& block : grid.blocks) {
      values.insert(values.end(), block.points.coords().begin(), block.points.coords().end());
    }
    return values;
  }
  // Every point of `revision` at level 0 (a failed test and nothing if it does not evaluate).
  static std::vector<double> Evaluation(client::Client& client, int64_t revision) {
    absl::StatusOr<client::EvaluatedGrid> grid = EvaluateAt(client, revision);
    EXPECT_TRUE(grid.ok()) << "revision " << revision << ": " << grid.status();
    return grid.ok() ? Values(*grid) : std::vector<double>();
  }

  fs::path dir_;
  int port_ = 0;
  std::unique_ptr<ChildProcess> server_;
};

TEST_F(DirStoreCrashTest, EveryAcknowledgedRevisionSurvivesSigkill) {
  std::unique_ptr<client::Client> client = Start();
  const std::string bytes = ReadFileToString(SharedDataPath("grids/n0012_225-65.p2dfmt")).value();
  const absl::StatusOr<v1::Grid> imported =
      client->ImportPlot3d(bytes, "pitch", "NACA 0012", false);
  ASSERT_TRUE(imported.ok()) << imported.status() << "\n" << server_->ReadLog();
  v1::FitSpec spec;
  spec.set_tolerance(1e-3);
  spec.set_allow_folds(true);  // this C-grid folds sub-cells at 1e-3; durability is the point here
  ASSERT_TRUE(client->Fit("pitch", spec).ok());

  // Kill the server at a random moment after a random number of acknowledged steps, inside or
  // between calls.
  std::mt19937 random(std::random_device{}());
  // At most 0.5 degrees in all (relative to revision 1): this C-grid fit folds a cell near 1.2.
  const int kill_after = std::uniform_int_distribution<int>(20, 80)(random);
  const int delay_us = std::uniform_int_distribution<int>(0, 3000)(random);
  std::atomic<int> acknowledged{0};
  std::thread killer([&] {
    while (acknowledged.load() < kill_after)
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    std::this_thread::sleep_for(std::chrono::microseconds(delay_us));
    kill(server_->pid(), SIGKILL);
  });
  std::map<int64_t, std::vector<double>> acked;  // revision -> its evaluation
  int64_t latest = 1;
  absl::Status failure;
  for (int step = 1; step <= 100; ++step) {
    v1::DeformGridRequest request;
    request.set_name("grids/pitch");
    request.set_reference_revision(1);
    request.set_base_revision(latest);
    request.set_time(0.01 * step);
    request.set_step(step);
    request.mutable_rigid()->set_angle_degrees(0.005 * step);
    request.mutable_rigid()->add_center(0.25);
    request.mutable_rigid()->add_center(0.0);
    absl::StatusOr<v1::DeformGridResponse> deformed = client->Deform(request);
    if (!deformed.ok()) {
      failure = deformed.status();
      break;
    }
    latest = deformed->revision();
    // The kill may fall between the deform's reply and this read: the revision is acknowledged
    // all the same (kept without its evaluation, checked to evaluate after the restart).
    absl::StatusOr<client::EvaluatedGrid> evaluated = EvaluateAt(*client, latest);
    acked[latest] = evaluated.ok() ? Values(*evaluated) : std::vector<double>();
    if (!evaluated.ok()) {
      failure = evaluated.status();
      break;
    }
    acknowledged.fetch_add(1);
  }
  // Release the killer whatever ended the loop (a failure before kill_after must show, not hang).
  acknowledged.store(1000);
  killer.join();
  ASSERT_FALSE(failure.ok()) << "the server was not killed during the 100 steps";
  ASSERT_EQ(failure.code(), absl::StatusCode::kUnavailable)
      << "step " << acked.size() + 1 << " failed before the kill: " << failure << "\n"
      << server_->ReadLog();
  EXPECT_EQ(server_->Wait(absl::Seconds(10)), 128 + SIGKILL);
  ASSERT_GE(static_cast<int>(acked.size()), kill_after);

  client = Start();
  absl::StatusOr<v1::Grid> grid = client->Get("pitch");
  ASSERT_TRUE(grid.ok()) << grid.status() << "\n" << server_->ReadLog();
  // Revision 1 (the fit), every acknowledged one, and at most the one in flight at the kill.
  std::vector<int64_t> numbers;
  for (const auto& r : grid->revisions()) numbers.push_back(r.revision());
  ASSERT_GE(numbers.size(), acked.size() + 1);
  ASSERT_LE(numbers.size(), acked.size() + 2);
  for (const auto& [revision, evaluation] : acked) {
    const std::vector<double> now = Evaluation(*client, revision);
    if (evaluation.empty()) {  // acknowledged just before the kill, not read back then
      EXPECT_FALSE(now.empty()) << "revision " << revision;
      continue;
    }
    ASSERT_EQ(now.size(), evaluation.size()) << "revision " << revision;
    EXPECT_EQ(std::memcmp(now.data(), evaluation.data(), now.size() * sizeof(double)), 0)
        << "revision " << revision << " differs after the restart";
  }
  // The one in flight, if it reached the disk, is whole: it evaluates.
  if (numbers.back() > acked.rbegin()->first) {
    EXPECT_FALSE(Evaluation(*client, numbers.back()).empty());
  }
  // Nothing damaged was found, nothing temporary was left.
  EXPECT_THAT(server_->ReadLog(), ::testing::Not(::testing::HasSubstr("damaged")));
  for (const auto& entry : fs::recursive_directory_iterator(dir_ / "store" / "grids")) {
    EXPECT_FALSE(entry.path().string().ends_with(".tmp")) << entry.path();
  }
  EXPECT_EQ(server_->Stop(SIGTERM), 0);
}

// A damaged revision file is reported and skipped; the rest of the grid loads.
TEST_F(DirStoreCrashTest, DamagedFilesAreSkippedWithAMessage) {
  std::unique_ptr<client::Client> client = Start();
  const std::string bytes = ReadFileToString(SharedDataPath("grids/n0012_225-65.p2dfmt")).value();
  ASSERT_TRUE(client->ImportPlot3d(bytes, "pitch", "", false).ok());
  v1::FitSpec spec;
  spec.mutable_control_counts()->set_i(40);
  spec.mutable_control_counts()->set_j(12);
  spec.set_allow_folds(true);  // 40 x 12 controls fold cells of this C-grid; stored all the same
  ASSERT_TRUE(client->Fit("pitch", spec).ok());
  ASSERT_TRUE(client->Fit("pitch", spec).ok());
  ASSERT_TRUE(client->ImportPlot3d(bytes, "other", "", false).ok());
  EXPECT_EQ(server_->Stop(SIGTERM), 0);
  // Flip a byte in the middle of revision 2, cut the other grid's points file short.
  const fs::path revision = dir_ / "store" / "grids" / "pitch" / "r000000000002.records";
  std::string text = ReadFileToString(revision.string()).value();
  text[text.size() / 2] ^= 0x20;
  ASSERT_TRUE(WriteFileAtomically(revision.string(), text).ok());
  const fs::path points = dir_ / "store" / "grids" / "other" / "grid.records";
  fs::resize_file(points, fs::file_size(points) / 2);

  client = Start();
  const absl::StatusOr<v1::Grid> grid = client->Get("pitch");
  ASSERT_TRUE(grid.ok()) << grid.status();
  ASSERT_EQ(grid->revisions_size(), 1);
  EXPECT_EQ(grid->revisions(0).revision(), 1);
  // A grid whose points file is damaged says so (not "not found"), and keeps its id taken.
  const auto damaged_grid = [&] {
    const absl::Status status = client->Get("other").status();
    EXPECT_EQ(status.code(), absl::StatusCode::kDataLoss) << status;
    EXPECT_THAT(status.message(), ::testing::HasSubstr("grids/other was damaged on disk ("));
    EXPECT_THAT(status.message(), ::testing::HasSubstr("delete grids/other to use the id again"));
  };
  damaged_grid();
  EXPECT_EQ(client->ImportPlot3d(bytes, "other", "", false).status().code(),
            absl::StatusCode::kAlreadyExists);
  const std::string log = server_->ReadLog();
  EXPECT_THAT(log, ::testing::HasSubstr("r000000000002.records is damaged"));
  EXPECT_THAT(log, ::testing::HasSubstr("other is damaged"));
  // Asking for revision 2 says what happened to it (not "dropped by retention").
  const auto damaged = [&] {
    const absl::Status status = client->Get("pitch", 2).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kDataLoss) << status;
    EXPECT_THAT(status.message(), ::testing::HasSubstr("revision 2 was damaged on disk"));
  };
  damaged();
  // The grid keeps working; a new fit does not take the damaged revision's number (a client may
  // have been given it), and both stay so across another restart.
  const absl::StatusOr<v1::FitGridResponse> refit = client->Fit("pitch", spec);
  ASSERT_TRUE(refit.ok()) << refit.status();
  EXPECT_EQ(refit->revision(), 3);
  EXPECT_EQ(server_->Stop(SIGTERM), 0);
  client = Start();
  damaged();
  damaged_grid();
  const absl::StatusOr<v1::Grid> again = client->Get("pitch");
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_EQ(again->latest_revision(), 3);
  EXPECT_EQ(again->revisions_size(), 2);
  // Deleting the damaged grid frees its id, also across a restart.
  EXPECT_TRUE(client->Delete("other").ok());
  EXPECT_EQ(client->Get("other").status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(server_->Stop(SIGTERM), 0);
  client = Start();
  EXPECT_EQ(client->Get("other").status().code(), absl::StatusCode::kNotFound);
  EXPECT_TRUE(client->ImportPlot3d(bytes, "other", "", false).ok());
  EXPECT_EQ(server_->Stop(SIGTERM), 0);
}

// Two servers cannot share one store directory.
TEST_F(DirStoreCrashTest, SecondServerOnTheSameDirectoryExitsNonZero) {
  std::unique_ptr<client::Client> client = Start();
  ChildProcess second({kBinary, "serve", absl::StrCat("--address=127.0.0.1:", FreePort()),
                       absl::StrCat("--store=dir:", (dir_ / "store").string())},
                      (dir_ / "second.log").string());
  EXPECT_EQ(second.Wait(absl::Seconds(20)), 1);
  EXPECT_THAT(second.ReadLog(), ::testing::HasSubstr("in use by another process"));
  EXPECT_EQ(server_->Stop(SIGTERM), 0);
}

}  // namespace
}  // namespace splinegrid::testing
