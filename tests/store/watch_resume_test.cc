// A WatchGrid call that breaks off is resumed by the client (client::RevisionStream) where it
// stopped, on a real `splinegrid serve --store=dir:` killed with SIGKILL and started again on
// the same port and directory while the watch waits to retry:
//  - a watch of new revisions only (after_revision = -1) that had received nothing yet resumes
//    after the revision that was latest when it began (the server's initial metadata says
//    which), so the revision stored while the server was away is not missed;
//  - a watch whose grid was deleted and created again under the same id meanwhile ends as a
//    deletion ends it (OK), instead of going on with the other grid's revisions;
//  - a watch whose grid was deleted meanwhile ends OK too.
// The watch's client waits kRetryWait before its retry, so the restart and the changes made
// on the restarted server all happen before the watch comes back.
#include <signal.h>
#include <unistd.h>

#include <condition_variable>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
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
constexpr absl::Duration kRetryWait = absl::Seconds(4);

// A watch in a thread of its own, recording the revision numbers it receives.
class Watch {
 public:
  Watch(const std::string& address, int64_t after_revision) {
    client::ClientOptions options;
    // One retry, kRetryWait after the break, on a channel that reconnects at once.
    options.retry.max_attempts = 2;
    options.retry.initial_backoff = kRetryWait;
    options.retry.max_backoff = kRetryWait;
    options.retry.jitter = 0;
    grpc::ChannelArguments args;
    args.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, 100);
    args.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, 100);
    args.SetInt(GRPC_ARG_MIN_RECONNECT_BACKOFF_MS, 100);
    client_ = std::make_unique<client::Client>(
        grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), args), options);
    stream_ = client_->Watch("grids/wing", after_revision);
    thread_ = std::thread([this] {
      v1::WatchGridResponse message;
      while (stream_->Next(&message)) {
        std::lock_guard<std::mutex> lock(mu_);
        revisions_.push_back(message.revision().revision());
        cv_.notify_all();
      }
      const absl::Status status = stream_->Finish();
      std::lock_guard<std::mutex> lock(mu_);
      status_ = status;
      cv_.notify_all();
    });
  }
  ~Watch() {
    stream_->Cancel();
    thread_.join();
  }

  // Waits until `count` revisions arrived or the watch ended; the revisions.
  std::vector<int64_t> WaitForCount(size_t count, absl::Duration timeout) {
    std::unique_lock<std::mutex> lock(mu_);
    cv_.wait_for(lock, absl::ToChronoNanoseconds(timeout),
                 [&] { return status_.has_value() || revisions_.size() >= count; });
    return revisions_;
  }
  // Waits until the watch ended, up to `timeout`: its status, or nullopt.
  std::optional<absl::Status> WaitForEnd(absl::Duration timeout) {
    std::unique_lock<std::mutex> lock(mu_);
    cv_.wait_for(lock, absl::ToChronoNanoseconds(timeout), [&] { return status_.has_value(); });
    return status_;
  }
  std::vector<int64_t> revisions() {
    std::lock_guard<std::mutex> lock(mu_);
    return revisions_;
  }

 private:
  std::unique_ptr<client::Client> client_;
  std::unique_ptr<client::RevisionStream> stream_;
  std::thread thread_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::vector<int64_t> revisions_;
  std::optional<absl::Status> status_;
};

class WatchResumeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / absl::StrCat("splinegrid-watch-resume-", getpid());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    port_ = FreePort();
    address_ = absl::StrCat("127.0.0.1:", port_);
  }
  void TearDown() override {
    server_.reset();
    fs::remove_all(dir_);
  }

  // Starts the server on port_ and the store directory; a client of it.
  std::unique_ptr<client::Client> Start() {
    server_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{kBinary, "serve", absl::StrCat("--address=", address_),
                                 absl::StrCat("--store=dir:", (dir_ / "store").string()),
                                 "--threads=2", "--drain_notice=0s"},
        (dir_ / "server.log").string());
    EXPECT_TRUE(WaitForPort(port_, absl::Seconds(20))) << server_->ReadLog();
    return client::Client::Connect(address_);
  }
  // Kills the server (SIGKILL) and starts it again on the same port and directory.
  std::unique_ptr<client::Client> Restart() {
    EXPECT_EQ(server_->Stop(SIGKILL), 128 + SIGKILL);
    return Start();
  }

  // Imports the small NACA 0012 C-grid as grids/wing and fits it (revision 1).
  static void CreateWing(client::Client& client) {
    absl::StatusOr<std::string> bytes =
        ReadFileToString(SharedDataPath("grids/n0012_113-33.p2dfmt"));
    ASSERT_TRUE(bytes.ok()) << bytes.status();
    absl::StatusOr<v1::Grid> imported = client.ImportPlot3d(*bytes, "wing", "", false);
    ASSERT_TRUE(imported.ok()) << imported.status();
    v1::FitSpec spec;
    spec.mutable_boundary_tolerances();
    absl::StatusOr<v1::FitGridResponse> fit = client.Fit("wing", spec);
    ASSERT_TRUE(fit.ok()) << fit.status();
    ASSERT_EQ(fit->revision(), 1);
  }
  // A new revision: the wall turned by `degrees` about the quarter chord.
  static int64_t Turn(client::Client& client, double degrees) {
    v1::DeformGridRequest request;
    request.set_name("grids/wing");
    request.mutable_rigid()->set_angle_degrees(degrees);
    request.mutable_rigid()->add_center(0.25);
    request.mutable_rigid()->add_center(0.0);
    absl::StatusOr<v1::DeformGridResponse> moved = client.Deform(request);
    EXPECT_TRUE(moved.ok()) << moved.status();
    return moved.ok() ? moved->revision() : 0;
  }

  fs::path dir_;
  int port_ = 0;
  std::string address_;
  std::unique_ptr<ChildProcess> server_;
};

TEST_F(WatchResumeTest, AWatchOfNewRevisionsMissesNoneStoredWhileItsServerWasAway) {
  std::unique_ptr<client::Client> client = Start();
  ASSERT_NO_FATAL_FAILURE(CreateWing(*client));
  Watch watch(address_, /*after_revision=*/-1);  // only new ones: none has arrived yet
  absl::SleepFor(absl::Milliseconds(300));       // the call is up (its metadata arrived)

  const absl::Time killed = absl::Now();
  client = Restart();
  EXPECT_EQ(Turn(*client, 0.5), 2);  // while the watch waits to retry
  const absl::Duration changed = absl::Now() - killed;
  ASSERT_LT(changed, kRetryWait) << "the restart took too long for this test's timing";
  EXPECT_EQ(Turn(*client, 1.0), 3);

  EXPECT_THAT(watch.WaitForCount(2, absl::Seconds(20)), ::testing::ElementsAre(2, 3))
      << "the watch resumed after revision 1 (latest when it began): " << server_->ReadLog();
  EXPECT_EQ(Turn(*client, 1.5), 4);
  EXPECT_THAT(watch.WaitForCount(3, absl::Seconds(20)), ::testing::ElementsAre(2, 3, 4));
  EXPECT_FALSE(watch.WaitForEnd(absl::ZeroDuration()).has_value());
}

TEST_F(WatchResumeTest, AWatchEndsWhenItsGridWasCreatedAgainWhileItWasAway) {
  std::unique_ptr<client::Client> client = Start();
  ASSERT_NO_FATAL_FAILURE(CreateWing(*client));
  Watch watch(address_, /*after_revision=*/0);
  ASSERT_THAT(watch.WaitForCount(1, absl::Seconds(20)), ::testing::ElementsAre(1));

  const absl::Time killed = absl::Now();
  client = Restart();
  // Another grid under the same id, with revisions 1 and 2: revision 2 is not the watched
  // grid's, and must not be sent as if it were.
  ASSERT_TRUE(client->Delete("wing").ok());
  ASSERT_NO_FATAL_FAILURE(CreateWing(*client));
  EXPECT_EQ(Turn(*client, 0.5), 2);
  ASSERT_LT(absl::Now() - killed, kRetryWait) << "the restart took too long for this test's timing";

  const std::optional<absl::Status> ended = watch.WaitForEnd(absl::Seconds(20));
  ASSERT_TRUE(ended.has_value()) << "the watch went on with the new grid's revisions: "
                                 << absl::StrJoin(watch.revisions(), " ");
  EXPECT_TRUE(ended->ok()) << *ended;
  EXPECT_THAT(watch.revisions(), ::testing::ElementsAre(1));
}

TEST_F(WatchResumeTest, AWatchEndsWhenItsGridWasDeletedWhileItWasAway) {
  std::unique_ptr<client::Client> client = Start();
  ASSERT_NO_FATAL_FAILURE(CreateWing(*client));
  Watch watch(address_, /*after_revision=*/0);
  ASSERT_THAT(watch.WaitForCount(1, absl::Seconds(20)), ::testing::ElementsAre(1));

  client = Restart();
  ASSERT_TRUE(client->Delete("wing").ok());

  const std::optional<absl::Status> ended = watch.WaitForEnd(absl::Seconds(20));
  ASSERT_TRUE(ended.has_value());
  EXPECT_TRUE(ended->ok()) << *ended;
}

}  // namespace
}  // namespace splinegrid::testing
