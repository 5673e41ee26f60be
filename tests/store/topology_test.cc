// The shared-store topology with real processes on loopback ports:
//
//     redis-server (AOF, appendfsync always)  <-  3 x splinegrid serve --store=redis://...  <-
//     nginx
//
// nginx runs the configuration that deploy/nginx/render.sh renders from the shipped template
// (hash on x-splinegrid-grid), as an unprivileged foreground process. The pitching coupling
// client runs 200 steps through nginx while the replica serving its grid is killed with SIGKILL
// at step 100: the run completes, every acknowledged revision is readable on a survivor, and a
// WatchGrid opened directly on another replica saw them all, in order, as did one opened
// through nginx (on the killed replica: the client resumes it). Also: a replica without
// Redis refuses to start, a Redis outage turns replicas NOT_SERVING and back, two servers cannot
// share a port. Skipped when redis-server or nginx is not installed (.ci/setup installs them).
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/time/clock.h"
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
const std::string kPitching = SPLINEGRID_BINARY_DIR "/splinegrid_pitching";
const std::string kRender = SPLINEGRID_SOURCE_DIR "/deploy/nginx/render.sh";

constexpr int kReplicas = 3;
constexpr int kSteps = 200;
constexpr int kKillAtStep = 100;

std::string Address(int port) { return absl::StrCat("127.0.0.1:", port); }

// How often `needle` occurs in `text`.
int Count(const std::string& text, const std::string& needle) {
  int n = 0;
  for (size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

// A client without retries (every UNAVAILABLE shows) and a short deadline.
std::unique_ptr<client::Client> DirectClient(int port, absl::Duration timeout = absl::Seconds(30)) {
  client::ClientOptions options;
  options.timeout = timeout;
  options.retry.max_attempts = 1;
  return client::Client::Connect(Address(port), options);
}

// `splinegrid health` against 127.0.0.1:port: its exit code, and its output in `*out`.
int HealthCli(int port, std::string* out) {
  return RunShell(absl::StrCat(kBinary, " health --server=", Address(port), " --timeout=2s"), out);
}

// Polls `done` every `interval` until it holds or `timeout` passes; whether it held.
template <typename Predicate>
bool PollUntil(absl::Duration timeout, Predicate done,
               absl::Duration interval = absl::Milliseconds(20)) {
  const absl::Time end = absl::Now() + timeout;
  for (;;) {
    if (done()) return true;
    if (absl::Now() >= end) return false;
    absl::SleepFor(interval);
  }
}

// A WatchGrid call (from revision 0) in a thread of its own, recording every revision number.
class Watcher {
 public:
  Watcher(int port, std::string grid)
      : client_(client::Client::Connect(Address(port))), grid_(std::move(grid)) {
    thread_ = std::thread([this] {
      std::unique_ptr<client::RevisionStream> stream = client_->Watch(grid_, 0, cancel_);
      v1::WatchGridResponse message;
      while (stream->Next(&message)) {
        std::lock_guard<std::mutex> lock(mu_);
        revisions_.push_back(message.revision().revision());
        cv_.notify_all();
      }
      const absl::Status status = stream->Finish();
      std::lock_guard<std::mutex> lock(mu_);
      status_ = status;
      cv_.notify_all();
    });
  }
  ~Watcher() { (void)Stop(); }

  // Waits until `revision` (or a later one) arrived or the watch ended; whether it arrived.
  bool WaitFor(int64_t revision, absl::Duration timeout) {
    std::unique_lock<std::mutex> lock(mu_);
    cv_.wait_for(lock, absl::ToChronoNanoseconds(timeout), [&] {
      return status_.has_value() || (!revisions_.empty() && revisions_.back() >= revision);
    });
    return !revisions_.empty() && revisions_.back() >= revision;
  }
  // Cancels the call and joins the thread; the watch's status (CANCELLED when it was still
  // open).
  absl::Status Stop() {
    cancel_->Cancel();
    if (thread_.joinable()) thread_.join();
    std::lock_guard<std::mutex> lock(mu_);
    return status_.value_or(absl::CancelledError());
  }
  std::vector<int64_t> revisions() {
    std::lock_guard<std::mutex> lock(mu_);
    return revisions_;
  }
  std::optional<absl::Status> ended() {
    std::lock_guard<std::mutex> lock(mu_);
    return status_;
  }

 private:
  std::unique_ptr<client::Client> client_;
  std::string grid_;
  std::shared_ptr<client::WatchCancel> cancel_ = std::make_shared<client::WatchCancel>();
  std::mutex mu_;
  std::condition_variable cv_;
  std::vector<int64_t> revisions_;
  std::optional<absl::Status> status_;
  std::thread thread_;
};

class TopologyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           absl::StrCat("splinegrid-topology-", getpid(), "-",
                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }

  void TearDown() override {
    // nginx first (on SIGTERM its master stops the workers, then exits; the process group is
    // killed if it does not), then the replicas, then Redis (SIGTERM: it flushes the AOF).
    if (nginx_ && nginx_->Stop(SIGTERM, absl::Seconds(5)) < 0) {
      kill(-nginx_->pid(), SIGKILL);  // its own process group (ChildProcess): master and workers
      nginx_->Wait(absl::Seconds(5));
    }
    if (HasFailure()) DumpLogs();
    for (auto& replica : replicas_) replica.reset();
    if (redis_) redis_->Stop(SIGTERM, absl::Seconds(10));
    redis_.reset();
    nginx_.reset();
    if (!HasFailure()) fs::remove_all(dir_);
  }

  // The last lines of every log, for a failed test.
  void DumpLogs() {
    std::string dump;
    for (const auto& entry : fs::recursive_directory_iterator(dir_)) {
      const std::string path = entry.path().string();
      if (!entry.is_regular_file() || !(path.ends_with(".log") || path.ends_with(".acked")))
        continue;
      const std::string text = ReadFileToString(path).value_or("");
      std::vector<std::string> lines = absl::StrSplit(text, '\n');
      const size_t from = lines.size() > 25 ? lines.size() - 25 : 0;
      absl::StrAppend(&dump, "--- ", path, " (last lines)\n",
                      absl::StrJoin(lines.begin() + from, lines.end(), "\n"), "\n");
    }
    std::fprintf(stderr, "%s(kept in %s)\n", dump.c_str(), dir_.c_str());
  }

  // Skips the test (true) when redis-server or nginx is missing.
  bool MissingPrograms(bool need_nginx) {
    redis_server_ = FindProgram("redis-server");
    nginx_binary_ = FindProgram("nginx");
    return redis_server_.empty() || (need_nginx && nginx_binary_.empty());
  }

  // redis-server on `redis_port_` (picked on the first start, kept for restarts) with its data
  // in dir_/redis: AOF on, fsync before every reply, bound to 127.0.0.1.
  void StartRedis() {
    if (redis_port_ == 0) redis_port_ = FreePort();
    fs::create_directories(dir_ / "redis");
    const fs::path conf = dir_ / "redis.conf";
    std::ofstream(conf) << "bind 127.0.0.1\n"
                        << "port " << redis_port_ << "\n"
                        << "protected-mode yes\n"
                        << "daemonize no\n"
                        << "dir " << (dir_ / "redis").string() << "\n"
                        << "logfile \"\"\n"
                        << "appendonly yes\n"
                        << "appendfsync always\n"
                        << "save \"\"\n";
    if (!redis_password_.empty())
      std::ofstream(conf, std::ios::app) << "requirepass " << redis_password_ << "\n";
    redis_ = std::make_unique<ChildProcess>(std::vector<std::string>{redis_server_, conf.string()},
                                            (dir_ / "redis.log").string());
    ASSERT_TRUE(WaitForPort(redis_port_, absl::Seconds(10))) << redis_->ReadLog();
  }

  std::string RedisStore() const { return absl::StrCat("--store=redis://127.0.0.1:", redis_port_); }

  // A `splinegrid serve` on a free port, logging to dir_/NAME.log; not waited for.
  std::unique_ptr<ChildProcess> Serve(const std::string& name, int port, const std::string& store,
                                      const std::string& extra_flag = "") {
    std::vector<std::string> argv = {kBinary,
                                     "serve",
                                     absl::StrCat("--address=", Address(port)),
                                     store,
                                     "--threads=1",
                                     "--keep_revisions=1000",
                                     "--shutdown_grace=2s",
                                     "--drain_notice=0s"};
    if (!extra_flag.empty()) argv.push_back(extra_flag);
    return std::make_unique<ChildProcess>(std::move(argv), (dir_ / (name + ".log")).string());
  }

  // Waits until the server on `port` answers its health check with SERVING.
  static bool WaitServing(int port, absl::Duration timeout) {
    if (!WaitForPort(port, timeout)) return false;
    auto client = DirectClient(port, absl::Seconds(2));
    return PollUntil(timeout, [&] {
      const absl::StatusOr<std::string> health = client->Health();
      return health.ok() && *health == "SERVING";
    });
  }

  // kReplicas replicas on the Redis store; fails the test unless every one is SERVING.
  void StartReplicas() {
    for (int i = 0; i < kReplicas; ++i) {
      replica_ports_.push_back(FreePort());
      replicas_.push_back(Serve(absl::StrCat("replica-", i), replica_ports_[i], RedisStore()));
    }
    for (int i = 0; i < kReplicas; ++i) {
      ASSERT_TRUE(WaitServing(replica_ports_[i], absl::Seconds(20)))
          << "replica " << i << " not SERVING:\n"
          << replicas_[i]->ReadLog();
    }
  }

  // nginx with the configuration deploy/nginx/render.sh renders for the replicas, run as the
  // template says: nginx -p RUNDIR -c RUNDIR/nginx.conf -g 'daemon off;'. Waits until a health
  // check through it answers SERVING, unless `wait_serving` is false.
  void StartNginx(bool wait_serving = true) {
    nginx_port_ = FreePort();
    const fs::path run = dir_ / "nginx";
    fs::create_directories(run);
    std::string command =
        absl::StrCat(kRender, " --run-dir ", run.string(), " --listen ", Address(nginx_port_));
    for (int port : replica_ports_) absl::StrAppend(&command, " --upstream ", Address(port));
    std::string rendered;
    // Its stderr apart: only the configuration goes into the file.
    ASSERT_EQ(
        RunShell(absl::StrCat("(", command, " 2>", (dir_ / "render.log").string(), ")"), &rendered),
        0)
        << rendered << ReadFileToString((dir_ / "render.log").string()).value_or("");
    const fs::path conf = run / "nginx.conf";
    std::ofstream(conf) << rendered;
    std::string checked;
    ASSERT_EQ(
        RunShell(absl::StrCat(nginx_binary_, " -p ", run.string(), " -c ", conf.string(), " -t"),
                 &checked),
        0)
        << "nginx -t rejects the rendered configuration:\n"
        << checked;
    nginx_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{nginx_binary_, "-p", run.string(), "-c", conf.string(), "-g",
                                 "daemon off;"},
        (dir_ / "nginx.log").string());
    if (!wait_serving) {
      ASSERT_TRUE(WaitForPort(nginx_port_, absl::Seconds(10))) << nginx_->ReadLog();
      return;
    }
    ASSERT_TRUE(WaitServing(nginx_port_, absl::Seconds(10)))
        << nginx_->ReadLog() << ReadFileToString((run / "error.log").string()).value_or("");
  }

  std::string ReplicaLog(int i) const { return replicas_[i]->ReadLog(); }

  fs::path dir_;
  std::string redis_server_, nginx_binary_;
  int redis_port_ = 0, nginx_port_ = 0;
  std::string redis_password_;  // StartRedis: requirepass, when not empty
  std::unique_ptr<ChildProcess> redis_, nginx_;
  std::vector<int> replica_ports_;
  std::vector<std::unique_ptr<ChildProcess>> replicas_;
};

// `step revision` lines of the pitching client's --acked file (a torn last line is ignored).
std::map<int, int64_t> ReadAcked(const fs::path& path) {
  std::map<int, int64_t> acked;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (in.eof()) break;  // no newline yet: still being written
    std::istringstream fields(line);
    int step = 0;
    int64_t revision = 0;
    if (fields >> step >> revision) acked[step] = revision;
  }
  return acked;
}

int AckedLines(const fs::path& path) {
  const std::string text = ReadFileToString(path.string()).value_or("");
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

// With every replica down, a call through nginx ends the way a gRPC server would end it:
// UNAVAILABLE with a message (which clients retry), not an HTML 502 page.
TEST_F(TopologyTest, NginxWithoutAReplicaAnswersUnavailable) {
  if (MissingPrograms(/*need_nginx=*/true)) {
    GTEST_SKIP() << "redis-server or nginx is not installed (.ci/setup installs them: "
                    "redis-server nginx-light)";
  }
  replica_ports_ = {FreePort()};  // nothing listens there
  ASSERT_NO_FATAL_FAILURE(StartNginx(/*wait_serving=*/false));
  auto through_nginx = DirectClient(nginx_port_, absl::Seconds(5));
  const absl::Status status = through_nginx->Get("grids/absent").status();
  EXPECT_EQ(status.code(), absl::StatusCode::kUnavailable) << status;
  EXPECT_THAT(std::string(status.message()),
              ::testing::HasSubstr("no splinegrid replica could be reached"));
}

// Without tokens a caller is its connection. Through nginx every call arrives on one of nginx's
// connections, so each was a caller of its own and the turns and per-caller limits did
// nothing (a trial). nginx names the client's connection (x-client-address) and a replica
// that trusts it (serve --trusted_proxies) takes that as the caller: one client's calls share
// a principal, another client's differ, and neither is nginx's upstream connection.
TEST_F(TopologyTest, BehindNginxTheCallerIsTheClientsConnection) {
  if (MissingPrograms(/*need_nginx=*/true)) {
    GTEST_SKIP() << "redis-server or nginx is not installed (.ci/setup installs them: "
                    "redis-server nginx-light)";
  }
  replica_ports_ = {FreePort()};
  replicas_.push_back(
      Serve("replica-0", replica_ports_[0], "--store=memory", "--trusted_proxies=127.0.0.1"));
  ASSERT_TRUE(WaitServing(replica_ports_[0], absl::Seconds(20))) << ReplicaLog(0);
  ASSERT_NO_FATAL_FAILURE(StartNginx());
  auto first = DirectClient(nginx_port_, absl::Seconds(5));
  for (const char* grid : {"grids/first-a", "grids/first-b"})
    EXPECT_EQ(first->Get(grid).status().code(), absl::StatusCode::kNotFound);
  // Another process: its own connection to nginx (clients in one process with the same channel
  // arguments share one).
  std::string out;
  EXPECT_EQ(RunShell(absl::StrCat(kBinary, " get second --server=", Address(nginx_port_),
                                  " --timeout=5s"),
                     &out),
            1)
      << out;
  // The log line of a call: "TIME METHOD GRID STATUS MS ms by PRINCIPAL[: MESSAGE]".
  auto principal_of = [&](const std::string& grid) -> std::string {
    for (absl::string_view line : absl::StrSplit(ReplicaLog(0), '\n')) {
      if (!absl::StrContains(line, absl::StrCat(" ", grid, " "))) continue;
      const size_t by = line.find(" by ");
      if (by == absl::string_view::npos) continue;
      const absl::string_view rest = line.substr(by + 4);
      return std::string(rest.substr(0, rest.find(": ")));
    }
    return "";
  };
  const std::string a = principal_of("grids/first-a"), b = principal_of("grids/first-b"),
                    c = principal_of("grids/second");
  EXPECT_THAT(a, ::testing::StartsWith("ipv4:127.0.0.1:")) << ReplicaLog(0);
  EXPECT_EQ(a, b) << ReplicaLog(0);
  EXPECT_NE(a, c) << ReplicaLog(0);
  // A client's port, not nginx's upstream connection: the first client's own connection.
  auto direct = DirectClient(replica_ports_[0], absl::Seconds(5));
  EXPECT_EQ(direct->Get("grids/direct").status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(principal_of("grids/direct"), ::testing::StartsWith("ipv4:127.0.0.1:"));
  EXPECT_NE(principal_of("grids/direct"), a);
}

TEST_F(TopologyTest, PitchingRunSurvivesKillingTheServingReplica) {
  if (MissingPrograms(/*need_nginx=*/true)) {
    GTEST_SKIP() << "redis-server or nginx is not installed (.ci/setup installs them: "
                    "redis-server nginx-light)";
  }
  {
    std::string help;
    RunShell(kPitching + " --helpfull", &help);
    ASSERT_THAT(help, ::testing::HasSubstr("--acked")) << "splinegrid_pitching has no --acked flag";
  }
  const absl::Time start = absl::Now();
  ASSERT_NO_FATAL_FAILURE(StartRedis());
  ASSERT_NO_FATAL_FAILURE(StartReplicas());
  ASSERT_NO_FATAL_FAILURE(StartNginx());
  const absl::Duration startup = absl::Now() - start;

  // Which replica nginx routes the grid to: a call about it (NOT_FOUND yet) is logged there.
  const std::string id = "topology-pitch";
  const std::string logged_get = absl::StrCat(" GetGrid grids/", id, " NOT_FOUND");
  int routed = -1;
  {
    auto through_nginx = DirectClient(nginx_port_);
    ASSERT_EQ(through_nginx->Get(id).status().code(), absl::StatusCode::kNotFound);
    PollUntil(absl::Seconds(2), [&] {
      for (int i = 0; i < kReplicas; ++i) {
        if (absl::StrContains(ReplicaLog(i), logged_get)) routed = i;
      }
      return routed >= 0;
    });
  }
  // The watcher's replica: one that nginx does not route the grid to.
  int watched = routed < 0 ? 0 : (routed + 1) % kReplicas;

  // The coupling client through nginx: import, fit by boundary kind, 200 steps of deform +
  // evaluate at level 1 + fold check.
  const fs::path acked_file = dir_ / "pitching.acked";
  const absl::Time client_start = absl::Now();
  // Every wait of the run below shares this budget (the run takes a few seconds).
  const absl::Time run_deadline = client_start + absl::Seconds(75);
  const auto remaining = [&] { return std::max(run_deadline - absl::Now(), absl::ZeroDuration()); };
  ChildProcess pitching({kPitching, absl::StrCat("--server=", Address(nginx_port_)),
                         absl::StrCat("--steps=", kSteps), absl::StrCat("--name=", id),
                         absl::StrCat("--grid=", SharedDataPath("grids/n0012_pitch_257x129.fmt")),
                         absl::StrCat("--acked=", acked_file.string()), "--keep", "--quiet"},
                        (dir_ / "pitching.log").string());

  // The watch goes on the other replica once the fitted grid is there (from revision 0: the
  // stored revisions first, then each new one as another replica publishes it).
  auto on_watched = DirectClient(replica_ports_[watched], absl::Seconds(5));
  ASSERT_TRUE(PollUntil(remaining(), [&] {
    const absl::StatusOr<v1::Grid> grid = on_watched->Get(id);
    return (grid.ok() && grid->latest_revision() >= 1) || !pitching.running();
  }));
  ASSERT_TRUE(pitching.running()) << "the pitching client ended before its grid was fitted:\n"
                                  << pitching.ReadLog();
  const absl::Duration import_and_fit = absl::Now() - client_start;
  auto watcher = std::make_unique<Watcher>(replica_ports_[watched], id);
  // And one through nginx: it lands on the replica that will be killed, and must resume.
  Watcher through_nginx(nginx_port_, id);

  // At step 100, SIGKILL the replica that serves the grid: the one logging its DeformGrid calls
  // (found a few steps ahead, so that the kill follows the 100th acknowledgement within ~1 ms:
  // it lands in that step's EvaluateGrid stream or the next step's DeformGrid).
  const std::string logged_deform = absl::StrCat(" DeformGrid grids/", id, " ");
  int killed = -1, killed_at = 0;
  std::vector<int> deforms_before_kill(kReplicas, 0);
  ASSERT_TRUE(PollUntil(
      remaining(),
      [&] { return !pitching.running() || AckedLines(acked_file) >= kKillAtStep - 10; },
      absl::Milliseconds(1)));
  for (int i = 0; i < kReplicas; ++i) deforms_before_kill[i] = Count(ReplicaLog(i), logged_deform);
  const int serving =
      static_cast<int>(std::max_element(deforms_before_kill.begin(), deforms_before_kill.end()) -
                       deforms_before_kill.begin());
  ASSERT_TRUE(PollUntil(
      remaining(),
      [&] {
        if (!pitching.running()) return true;
        if (AckedLines(acked_file) < kKillAtStep) return false;
        kill(replicas_[serving]->pid(), SIGKILL);
        killed = serving;
        killed_at = AckedLines(acked_file);
        return true;
      },
      absl::Milliseconds(1)));
  ASSERT_GE(killed, 0) << "the client ended before step " << kKillAtStep << ":\n"
                       << pitching.ReadLog();
  EXPECT_EQ(replicas_[killed]->Wait(absl::Seconds(5)), 128 + SIGKILL);
  for (int i = 0; i < kReplicas; ++i) deforms_before_kill[i] = Count(ReplicaLog(i), logged_deform);
  EXPECT_GT(deforms_before_kill[killed], kKillAtStep / 2)
      << "no replica served most DeformGrid calls: " << absl::StrJoin(deforms_before_kill, ", ");
  if (routed >= 0) {
    EXPECT_EQ(killed, routed) << "nginx moved the grid before the kill";
  }
  if (killed == watched) {
    // Routing was not what the probe said: watch again, from 0, on a survivor.
    ADD_FAILURE() << "the watched replica served the grid; watching again on a survivor";
    (void)watcher->Stop();
    watched = (killed + 1) % kReplicas;
    watcher = std::make_unique<Watcher>(replica_ports_[watched], id);
  }

  // The run completes: UNAVAILABLE is retried, nginx hashes the grid to a survivor.
  const int exit_code = pitching.Wait(remaining());
  const absl::Duration run = absl::Now() - client_start;
  ASSERT_EQ(exit_code, 0) << pitching.ReadLog();
  const std::map<int, int64_t> acked = ReadAcked(acked_file);
  ASSERT_EQ(static_cast<int>(acked.size()), kSteps) << "steps acknowledged";
  EXPECT_EQ(acked.begin()->first, 1);
  EXPECT_EQ(acked.rbegin()->first, kSteps);
  int64_t previous = 1;  // the fit
  for (const auto& [step, revision] : acked) {
    EXPECT_GT(revision, previous) << "step " << step << ": revisions must grow with the steps";
    previous = revision;
  }
  std::vector<int> survivors;
  for (int i = 0; i < kReplicas; ++i) {
    if (i != killed) survivors.push_back(i);
  }
  int deforms_after_kill = 0;
  for (int i : survivors) deforms_after_kill += Count(ReplicaLog(i), logged_deform);
  EXPECT_GE(deforms_after_kill, kSteps - killed_at) << "survivors served the rest of the run";

  // Every acknowledged revision is on a survivor (not the watcher's, when there is another one),
  // with its step, and evaluates at the original resolution.
  const int reader = survivors.back() != watched ? survivors.back() : survivors.front();
  auto survivor = DirectClient(replica_ports_[reader]);
  for (const auto& [step, revision] : acked) {
    const absl::StatusOr<v1::Grid> grid = survivor->Get(id, revision);
    ASSERT_TRUE(grid.ok()) << "step " << step << " revision " << revision << ": " << grid.status();
    EXPECT_EQ(grid->revision().revision(), revision);
    EXPECT_EQ(grid->revision().step(), step) << "revision " << revision;
    v1::EvaluateGridRequest evaluate;
    evaluate.set_name(id);
    evaluate.set_revision(revision);
    const absl::StatusOr<client::EvaluatedGrid> points = survivor->Evaluate(evaluate);
    ASSERT_TRUE(points.ok()) << "revision " << revision << ": " << points.status();
    ASSERT_EQ(points->blocks.size(), 1u);
    EXPECT_EQ(points->blocks[0].points.num_points(), 257 * 129) << "revision " << revision;
  }

  // Both watches saw all of them, in strictly increasing order: the one on a survivor directly,
  // and the one through nginx, which the kill broke off and the client resumed on a survivor.
  const int64_t last = acked.rbegin()->second;
  std::set<int64_t> acked_revisions;
  for (const auto& [step, revision] : acked) acked_revisions.insert(revision);
  const auto check_watch = [&](Watcher& watch, const std::string& where) {
    SCOPED_TRACE(where);
    EXPECT_TRUE(watch.WaitFor(last, absl::Seconds(15)))
        << "the watch did not see revision " << last << "; it ended with "
        << watch.ended().value_or(absl::OkStatus());
    EXPECT_FALSE(watch.ended().has_value()) << "the watch ended by itself: " << *watch.ended();
    EXPECT_TRUE(absl::IsCancelled(watch.Stop()));
    const std::vector<int64_t> seen = watch.revisions();
    EXPECT_FALSE(seen.empty());
    if (seen.empty()) return seen;
    EXPECT_EQ(seen.front(), 1) << "the fitted revision comes first";
    for (size_t n = 1; n < seen.size(); ++n) {
      EXPECT_GT(seen[n], seen[n - 1])
          << "watch message " << n << " out of order: " << absl::StrJoin(seen, " ");
      // Revision numbers are consecutive and none is dropped (--keep_revisions=1000): a jump is
      // a revision the watch missed.
      EXPECT_EQ(seen[n], seen[n - 1] + 1)
          << "the watch skipped from " << seen[n - 1] << " to " << seen[n];
    }
    const std::set<int64_t> seen_set(seen.begin(), seen.end());
    std::vector<int64_t> missed;
    for (int64_t revision : acked_revisions) {
      if (!seen_set.contains(revision)) missed.push_back(revision);
    }
    EXPECT_TRUE(missed.empty()) << "acknowledged revisions the watch missed: "
                                << absl::StrJoin(missed, " ");
    return seen;
  };
  const std::vector<int64_t> seen = check_watch(*watcher, "watch on a survivor");
  const std::vector<int64_t> seen_through_nginx = check_watch(through_nginx, "watch through nginx");
  std::vector<int64_t> unacknowledged;
  for (int64_t revision : seen) {
    if (revision > 1 && !acked_revisions.contains(revision)) unacknowledged.push_back(revision);
  }

  std::printf(
      "topology: startup %.2f s, import + fit through nginx %.2f s, %d steps in %.2f s; replica "
      "%d (routed %d) killed after %d acknowledged steps (%d DeformGrid calls); watched on "
      "replica %d: %zu revisions (%zu not acknowledged: %s), through nginx %zu; survivors served "
      "%d "
      "DeformGrid calls; whole test %.1f s\n",
      absl::ToDoubleSeconds(startup), absl::ToDoubleSeconds(import_and_fit), kSteps,
      absl::ToDoubleSeconds(run), killed, routed, killed_at, deforms_before_kill[killed], watched,
      seen.size(), unacknowledged.size(), absl::StrJoin(unacknowledged, " ").c_str(),
      seen_through_nginx.size(), deforms_after_kill, absl::ToDoubleSeconds(absl::Now() - start));
}

// A replica whose Redis is not there refuses to start, at once, saying so.
TEST_F(TopologyTest, ReplicaWithoutRedisExitsNonZero) {
  if (MissingPrograms(/*need_nginx=*/false)) {
    GTEST_SKIP() << "redis-server is not installed (.ci/setup installs it: redis-server)";
  }
  const int nothing = FreePort();  // nothing listens there
  const absl::Time start = absl::Now();
  std::unique_ptr<ChildProcess> replica =
      Serve("replica", FreePort(), absl::StrCat("--store=redis://127.0.0.1:", nothing));
  const int code = replica->Wait(absl::Seconds(15));
  const absl::Duration took = absl::Now() - start;
  EXPECT_GT(code, 0) << "exit code (-1: still running)";
  EXPECT_LT(took, absl::Seconds(10)) << "a replica without Redis should give up quickly";
  const std::string log = replica->ReadLog();
  EXPECT_THAT(absl::AsciiStrToLower(log), ::testing::HasSubstr("redis")) << log;
  EXPECT_THAT(log, ::testing::HasSubstr(absl::StrCat(nothing))) << "names the address: " << log;
  std::printf("without Redis: exit %d after %.2f s: %s", code, absl::ToDoubleSeconds(took),
              log.c_str());
}

// A Redis with a password: a replica logs in with --redis_password_file or with the password in
// the URL, and no log shows it (the banner shows ***); without it, or with a wrong one, a
// replica exits non-zero saying what Redis wants and how to give it.
TEST_F(TopologyTest, ReplicasLogInToRedisWithAPasswordThatNoLogShows) {
  if (MissingPrograms(/*need_nginx=*/false)) {
    GTEST_SKIP() << "redis-server is not installed (.ci/setup installs it: redis-server)";
  }
  const std::string secret = "s3cret-7Hq2";
  redis_password_ = secret;
  ASSERT_NO_FATAL_FAILURE(StartRedis());
  const fs::path good = dir_ / "redis-password";
  const fs::path wrong = dir_ / "wrong-password";
  std::ofstream(good) << secret << "\n";
  std::ofstream(wrong) << "not-" << secret << "\n";
  const std::string plain = absl::StrCat("--store=redis://127.0.0.1:", redis_port_);
  const std::string in_url = absl::StrCat("--store=redis://:", secret, "@127.0.0.1:", redis_port_);

  // Logged in from the file, and from the URL: both SERVING, the grid one replica stores is
  // read through the other.
  const int from_file_port = FreePort(), from_url_port = FreePort();
  std::unique_ptr<ChildProcess> from_file =
      Serve("from-file", from_file_port, plain, "--redis_password_file=" + good.string());
  std::unique_ptr<ChildProcess> from_url = Serve("from-url", from_url_port, in_url);
  ASSERT_TRUE(WaitServing(from_file_port, absl::Seconds(20))) << from_file->ReadLog();
  ASSERT_TRUE(WaitServing(from_url_port, absl::Seconds(20))) << from_url->ReadLog();
  const std::string bytes = ReadFileToString(SharedDataPath("grids/n0012_113-33.p2dfmt")).value();
  ASSERT_TRUE(DirectClient(from_file_port)->ImportPlot3d(bytes, "locked", "", false).ok());
  EXPECT_TRUE(DirectClient(from_url_port)->Get("locked").ok());

  // Without the password, and with a wrong one: exit non-zero, saying so.
  std::unique_ptr<ChildProcess> without = Serve("without", FreePort(), plain);
  std::unique_ptr<ChildProcess> mistaken =
      Serve("mistaken", FreePort(), plain, "--redis_password_file=" + wrong.string());
  EXPECT_GT(without->Wait(absl::Seconds(15)), 0) << "exit code (-1: still running)";
  EXPECT_GT(mistaken->Wait(absl::Seconds(15)), 0) << "exit code (-1: still running)";
  EXPECT_THAT(without->ReadLog(), ::testing::HasSubstr("requires a password"));
  EXPECT_THAT(without->ReadLog(), ::testing::HasSubstr("--redis_password_file"));
  EXPECT_THAT(mistaken->ReadLog(),
              ::testing::HasSubstr("refuses the password of the default user"));

  // The banner of the URL's replica hides the password; no log has it.
  EXPECT_THAT(from_url->ReadLog(), ::testing::HasSubstr("store redis://:***@127.0.0.1:"));
  for (ChildProcess* process : {from_file.get(), from_url.get(), without.get(), mistaken.get()}) {
    EXPECT_THAT(process->ReadLog(), ::testing::Not(::testing::HasSubstr(secret))) << process->log();
  }
  EXPECT_EQ(from_file->Stop(SIGTERM), 0) << from_file->ReadLog();
  EXPECT_EQ(from_url->Stop(SIGTERM), 0) << from_url->ReadLog();
}

// Redis goes away: the replica says NOT_SERVING and calls fail UNAVAILABLE; Redis comes back on
// the same port with the same AOF: SERVING again within seconds, and the grid is still there.
TEST_F(TopologyTest, RedisOutageTurnsReplicaNotServingAndBack) {
  if (MissingPrograms(/*need_nginx=*/false)) {
    GTEST_SKIP() << "redis-server is not installed (.ci/setup installs it: redis-server)";
  }
  ASSERT_NO_FATAL_FAILURE(StartRedis());
  const int port = FreePort();
  std::unique_ptr<ChildProcess> replica = Serve("replica", port, RedisStore());
  ASSERT_TRUE(WaitServing(port, absl::Seconds(20))) << replica->ReadLog();
  replicas_.push_back(std::move(replica));  // for the logs of a failed test
  auto client = DirectClient(port);
  const std::string bytes = ReadFileToString(SharedDataPath("grids/n0012_113-33.p2dfmt")).value();
  ASSERT_TRUE(client->ImportPlot3d(bytes, "outage", "", /*planar_view=*/false).ok());
  v1::FitSpec spec;
  spec.set_tolerance(1e-3);
  spec.set_allow_folds(true);  // this C-grid folds sub-cells at 1e-3; the outage is the point
  const absl::StatusOr<v1::FitGridResponse> fit = client->Fit("outage", spec);
  ASSERT_TRUE(fit.ok()) << fit.status();
  std::string out;
  ASSERT_EQ(HealthCli(port, &out), 0) << out;

  // Kill Redis (a crash): NOT_SERVING within a few seconds, calls UNAVAILABLE.
  ASSERT_EQ(redis_->Stop(SIGKILL, absl::Seconds(5)), 128 + SIGKILL);
  absl::Time t = absl::Now();
  int health_code = 0;
  EXPECT_TRUE(PollUntil(absl::Seconds(10),
                        [&] {
                          health_code = HealthCli(port, &out);
                          return health_code != 0 && absl::StrContains(out, "NOT_SERVING");
                        }))
      << "health after Redis died: exit " << health_code << ": " << out;
  const absl::Duration to_not_serving = absl::Now() - t;
  EXPECT_EQ(client->Get("outage").status().code(), absl::StatusCode::kUnavailable)
      << client->Get("outage").status();
  EXPECT_EQ(client->List().status().code(), absl::StatusCode::kUnavailable);
  EXPECT_EQ(client->Fit("outage", spec).status().code(), absl::StatusCode::kUnavailable);

  // Redis again, same port, same AOF directory.
  ASSERT_NO_FATAL_FAILURE(StartRedis());
  t = absl::Now();
  EXPECT_TRUE(PollUntil(absl::Seconds(10), [&] { return HealthCli(port, &out) == 0; }))
      << "health after Redis came back: " << out;
  const absl::Duration to_serving = absl::Now() - t;
  EXPECT_THAT(out, ::testing::HasSubstr("SERVING"));
  const absl::StatusOr<v1::Grid> grid = client->Get("outage");
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_EQ(grid->latest_revision(), fit->revision());
  v1::EvaluateGridRequest evaluate;
  evaluate.set_name("outage");
  const absl::StatusOr<client::EvaluatedGrid> points = client->Evaluate(evaluate);
  ASSERT_TRUE(points.ok()) << points.status();
  EXPECT_EQ(points->blocks.at(0).points.num_points(), 113 * 33);
  std::printf("Redis outage: NOT_SERVING after %.2f s, SERVING %.2f s after the restart\n",
              absl::ToDoubleSeconds(to_not_serving), absl::ToDoubleSeconds(to_serving));
}

// Two servers on one port: the second exits non-zero naming the port, in one line of its own; the
// first keeps serving.
TEST_F(TopologyTest, SecondServerOnTheSamePortExitsNonZero) {
  const int port = FreePort();
  std::unique_ptr<ChildProcess> first = Serve("first", port, "--store=memory");
  ASSERT_TRUE(WaitServing(port, absl::Seconds(20))) << first->ReadLog();
  std::unique_ptr<ChildProcess> second = Serve("second", port, "--store=memory");
  EXPECT_GT(second->Wait(absl::Seconds(15)), 0) << "exit code (-1: still running)";
  const std::string log = second->ReadLog();
  EXPECT_THAT(log, ::testing::HasSubstr(Address(port)));
  EXPECT_THAT(log, ::testing::HasSubstr("the port is in use")) << log;
  // Refused by the server's own check, in one line: not after gRPC's log of the failed bind.
  EXPECT_THAT(log, ::testing::Not(::testing::HasSubstr("chttp2"))) << log;
  std::string out;
  EXPECT_EQ(HealthCli(port, &out), 0) << out;
  EXPECT_TRUE(first->running());
  // The banner says how many deformed revisions a grid keeps (Serve gives 1000): a coupling run
  // that reads old steps needs to know.
  EXPECT_THAT(first->ReadLog(),
              ::testing::HasSubstr(
                  "keeps the newest 1000 deformed revisions of a grid (--keep_revisions)"));
  EXPECT_EQ(first->Stop(SIGTERM), 0) << first->ReadLog();
}

}  // namespace
}  // namespace splinegrid::testing
