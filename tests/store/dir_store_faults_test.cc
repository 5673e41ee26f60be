// The `dir:` store when its file system fails under a running server: the store directory is
// a small tmpfs mounted in the server's own mount namespace (`unshare -m`), whose grids/ is made
// read-only and which is filled up, from outside (`nsenter`). A write that fails answers
// UNAVAILABLE (read-only) or RESOURCE_EXHAUSTED (full), naming the grid and the file system's cause
// but no server path, stores nothing and leaves what was stored readable; health turns NOT_SERVING
// and back to SERVING once writes get through again, without a restart. Skipped where mount
// namespaces are not allowed (the test says so).
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

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
using ::testing::HasSubstr;
using ::testing::Not;

const std::string kBinary = SPLINEGRID_BINARY_DIR "/splinegrid";

class DirStoreFaultsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / absl::StrCat("splinegrid-dir-faults-", getpid());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "mnt");
  }
  void TearDown() override {
    server_.reset();  // its mount namespace, and the tmpfs, go with it
    fs::remove_all(dir_);
  }

  // Whether this machine lets the test mount a tmpfs in a mount namespace of its own.
  std::string CannotMount() {
    const std::string unshare = FindProgram("unshare"), nsenter = FindProgram("nsenter");
    if (unshare.empty() || nsenter.empty()) return "unshare or nsenter is not installed";
    std::string out;
    const std::string mnt = (dir_ / "mnt").string();
    if (RunShell(absl::StrCat(unshare, " -m sh -c 'mount -t tmpfs -o size=1m tmpfs ", mnt,
                              " && umount ", mnt, "' 2>&1"),
                 &out) != 0) {
      return absl::StrCat("cannot mount a tmpfs in a mount namespace here: ", out);
    }
    return "";
  }

  // Starts the server on a 2 MiB tmpfs of its own holding the store; its client, without
  // retries (each failure must show).
  std::unique_ptr<client::Client> Start() {
    port_ = FreePort();
    mnt_ = (dir_ / "mnt").string();
    server_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{
            FindProgram("unshare"), "-m", "sh", "-c",
            absl::StrCat("mount -t tmpfs -o size=2m tmpfs ", mnt_, " && exec ", kBinary,
                         " serve --address=127.0.0.1:", port_, " --store=dir:", mnt_,
                         "/store --drain_notice=0s --shutdown_grace=1s")},
        (dir_ / "server.log").string());
    EXPECT_TRUE(WaitForPort(port_, absl::Seconds(20))) << server_->ReadLog();
    client::ClientOptions options;
    options.retry.max_attempts = 1;
    return client::Client::Connect(absl::StrCat("127.0.0.1:", port_), options);
  }

  // Runs `command` in the server's mount namespace; its exit code.
  int InServerNamespace(const std::string& command) {
    std::string out;
    const int code = RunShell(absl::StrCat(FindProgram("nsenter"), " -t ", server_->pid(),
                                           " -m sh -c '", command, "' 2>&1"),
                              &out);
    EXPECT_EQ(code, 0) << command << ": " << out;
    return code;
  }

  // Polls the health status until it is `wanted` (up to 5 s): whether it became so.
  static bool HealthBecomes(client::Client& client, const std::string& wanted) {
    const absl::Time end = absl::Now() + absl::Seconds(5);
    for (;;) {
      const absl::StatusOr<std::string> health = client.Health();
      if (health.ok() && *health == wanted) return true;
      if (absl::Now() > end) return false;
      absl::SleepFor(absl::Milliseconds(100));
    }
  }

  static absl::StatusOr<v1::DeformGridResponse> Turn(client::Client& client, double degrees) {
    v1::DeformGridRequest request;
    request.set_name("grids/wing");
    request.mutable_rigid()->set_angle_degrees(degrees);
    request.mutable_rigid()->add_center(0.25);
    request.mutable_rigid()->add_center(0.0);
    return client.Deform(request);
  }

  fs::path dir_;
  std::string mnt_;
  int port_ = 0;
  std::unique_ptr<ChildProcess> server_;
};

TEST_F(DirStoreFaultsTest, AReadOnlyOrFullStoreRefusesWritesByNameAndRecoversByItself) {
  if (const std::string why = CannotMount(); !why.empty()) GTEST_SKIP() << why;
  std::unique_ptr<client::Client> client = Start();
  absl::StatusOr<std::string> small = ReadFileToString(SharedDataPath("grids/n0012_113-33.p2dfmt"));
  ASSERT_TRUE(small.ok()) << small.status();
  ASSERT_TRUE(client->ImportPlot3d(*small, "wing", "", false).ok());
  v1::FitSpec spec;
  spec.mutable_boundary_tolerances();
  ASSERT_TRUE(client->Fit("wing", spec).ok());
  ASSERT_EQ(*client->Health(), "SERVING");

  // Read-only: a deformation is refused, nothing is stored, the fit is still served.
  // (grids/ alone, bound onto itself: the store's LOCK file, open for writing, would keep a
  // read-only remount of the whole tmpfs from happening)
  const std::string grids = absl::StrCat(mnt_, "/store/grids");
  ASSERT_EQ(InServerNamespace(absl::StrCat("mount --bind ", grids, " ", grids,
                                           " && mount -o remount,bind,ro ", grids)),
            0);
  const absl::StatusOr<v1::DeformGridResponse> refused = Turn(*client, 0.5);
  EXPECT_TRUE(absl::IsUnavailable(refused.status())) << refused.status();
  EXPECT_THAT(refused.status().message(),
              HasSubstr("grids/wing revision 2: the server's store could not be written "
                        "(Read-only file system); nothing was stored"));
  EXPECT_THAT(refused.status().message(), Not(HasSubstr(mnt_)));  // no server path
  const absl::StatusOr<v1::Grid> grid = client->Get("wing");
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_EQ(grid->latest_revision(), 1);
  v1::EvaluateGridRequest evaluate;
  evaluate.set_name("wing");
  EXPECT_TRUE(client->Evaluate(evaluate).ok());
  EXPECT_TRUE(HealthBecomes(*client, "NOT_SERVING"));
  EXPECT_THAT(server_->ReadLog(), HasSubstr("the store is unavailable"));

  // Writable again: health comes back by itself, the revision number was not used up.
  ASSERT_EQ(InServerNamespace(absl::StrCat("umount ", grids)), 0);
  EXPECT_TRUE(HealthBecomes(*client, "SERVING"));
  const absl::StatusOr<v1::DeformGridResponse> turned = Turn(*client, 0.5);
  ASSERT_TRUE(turned.ok()) << turned.status();
  EXPECT_EQ(turned->revision(), 2);

  // Full: an import that does not fit is RESOURCE_EXHAUSTED and leaves no grid behind.
  absl::StatusOr<std::string> large =
      ReadFileToString(SharedDataPath("grids/n0012_pitch_257x129.fmt"));
  ASSERT_TRUE(large.ok()) << large.status();
  std::vector<std::string> imported;
  absl::Status full;
  for (int n = 0; n < 10 && full.ok(); ++n) {
    const std::string id = absl::StrCat("big-", n);
    full = client->ImportPlot3d(*large, id, "", false).status();
    if (full.ok()) imported.push_back(id);
  }
  ASSERT_TRUE(absl::IsResourceExhausted(full)) << full;
  EXPECT_THAT(full.message(), HasSubstr("(No space left on device); nothing was stored"));
  EXPECT_TRUE(absl::IsNotFound(client->Get(absl::StrCat("big-", imported.size())).status()));
  for (const std::string& id : imported) {
    const absl::Status deleted = client->Delete(id);
    ASSERT_TRUE(deleted.ok()) << id << ": " << deleted;
  }
  EXPECT_TRUE(HealthBecomes(*client, "SERVING"));
  const absl::StatusOr<v1::DeformGridResponse> after = Turn(*client, 1.0);
  ASSERT_TRUE(after.ok()) << after.status();
  EXPECT_EQ(after->revision(), 3);
}

}  // namespace
}  // namespace splinegrid::testing
