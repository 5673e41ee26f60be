// The Redis store through the GridStore interface, against a real redis-server on a loopback
// port: two store instances on one Redis play two replicas. Create/Get/List/Delete across
// them, atomic creation and revision numbering (concurrent writers: exactly one wins), retention,
// watches across replicas (in order, no gap, then the deletion), chunked sources bitwise, the
// size limit, the per-process cache and its budget, outages (UNAVAILABLE, recovery, watches
// resumed or ended) and bad specs. Skipped when redis-server is not on PATH.
#include "server/store/redis_store.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/time/clock.h"
#include "core/fit/grid_fit.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/grid_store.h"
#include "server/memory_budget.h"
#include "server/store/redis_connection.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::testing {
namespace {

using server::GridRevision;
using server::GridStore;
using server::GridSubscription;
using server::RevisionOrigin;
using server::StoredGrid;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;
using End = GridSubscription::End;

// ---- A redis-server child process ----

std::string FindOnPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  for (const std::string& dir : std::vector<std::string>(absl::StrSplit(path ? path : "", ':'))) {
    const std::string candidate = dir + "/" + name;
    if (!dir.empty() && access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

// A loopback port that was free a moment ago.
int FreePort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;
  socklen_t length = sizeof(address);
  bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address));
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  close(fd);
  return ntohs(address.sin_port);
}

// Redis on 127.0.0.1:port, logging in with `password` (the default user's) when given.
server::RedisAddress Loopback(int port, const std::string& password = "") {
  server::RedisAddress address;
  address.host = "127.0.0.1";
  address.port = port;
  address.password = password;
  return address;
}

bool WaitFor(absl::Duration timeout, const std::function<bool()>& done) {
  const absl::Time deadline = absl::Now() + timeout;
  while (absl::Now() < deadline) {
    if (done()) return true;
    absl::SleepFor(absl::Milliseconds(10));
  }
  return done();
}

class RedisProcess {
 public:
  // `password`: the default user's (requirepass); empty: none.
  RedisProcess(std::string binary, std::string dir, int port, bool durable,
               std::string password = "")
      : binary_(std::move(binary)),
        dir_(std::move(dir)),
        port_(port),
        durable_(durable),
        password_(std::move(password)) {}
  ~RedisProcess() { Kill(); }

  // Starts redis-server and waits (up to 5 s) until it answers PING.
  bool Start() {
    running_ = false;
    const std::string log = dir_ + "/redis.log";
    std::vector<std::string> args = {binary_,
                                     "--port",
                                     absl::StrCat(port_),
                                     "--bind",
                                     "127.0.0.1",
                                     "--save",
                                     "",
                                     "--appendonly",
                                     durable_ ? "yes" : "no",
                                     "--appendfsync",
                                     "always",
                                     "--dir",
                                     dir_,
                                     "--logfile",
                                     log};
    if (!password_.empty()) {
      args.push_back("--requirepass");
      args.push_back(password_);
    }
    pid_ = fork();
    if (pid_ == 0) {
      prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlive the test
      const int null = open("/dev/null", O_RDWR);
      for (int fd = 0; fd < 3; ++fd) dup2(null, fd);
      std::vector<char*> argv;
      for (std::string& arg : args) argv.push_back(arg.data());
      argv.push_back(nullptr);
      execv(binary_.c_str(), argv.data());
      _exit(127);
    }
    const server::RedisAddress address = Loopback(port_, password_);
    running_ = WaitFor(absl::Seconds(5), [&] {
      return server::RedisConnection::Open(address, server::RedisConnectionOptions()).ok();
    });
    if (!running_) Kill();
    return running_;
  }
  bool running() const { return running_; }
  // SIGKILL (a crash) and wait for the exit.
  void Kill() {
    if (pid_ <= 0) return;
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
    pid_ = -1;
    running_ = false;
  }
  int port() const { return port_; }

 private:
  const std::string binary_;
  const std::string dir_;
  const int port_;
  const bool durable_;
  const std::string password_;
  pid_t pid_ = -1;
  bool running_ = false;
};

// ---- Grids and revisions ----

// A smooth 2D single-block grid of ni x nj points.
MultiBlockGrid SmallGrid(int ni, int nj) {
  MultiBlockGrid grid;
  StructuredBlock block({ni, nj, 1}, 2);
  for (int j = 0; j < nj; ++j) {
    for (int i = 0; i < ni; ++i) {
      const double u = i / double(ni - 1);
      const double v = j / double(nj - 1);
      double* p = block.Point(i, j, 0);
      p[0] = u + 0.05 * std::sin(3.0 * v);
      p[1] = v * (1.0 + 0.2 * u);
    }
  }
  grid.blocks.push_back(std::move(block));
  return grid;
}

// The fit of SmallGrid(9, 7), once.
const GridFit& SmallFit() {
  static const GridFit* fit = new GridFit(FitGrid(SmallGrid(9, 7), GridFitOptions()).value());
  return *fit;
}

GridRevision MakeRevision(RevisionOrigin origin, int64_t parent = 0, int64_t step = 0) {
  GridRevision revision;
  revision.create_time = absl::FromUnixMicros(1700000000123456);
  revision.origin = origin;
  revision.parent = parent;
  revision.step = step;
  revision.time = 0.25 * step;
  revision.fit_options = GridFitOptions();
  revision.blocks = SmallFit().blocks;
  revision.kinds = SmallFit().kinds;
  revision.report = SmallFit().report;
  return revision;
}

std::shared_ptr<StoredGrid> MakeGrid(const std::string& id,
                                     MultiBlockGrid points = SmallGrid(9, 7)) {
  auto grid = std::make_shared<StoredGrid>();
  grid->id = id;
  grid->display_name = "grid " + id;
  grid->create_time = absl::FromUnixNanos(1700000000123456789);
  auto source = std::make_shared<server::SourcePoints>();
  source->checked = FittableGrid::Check(std::move(points)).value();
  source->format = "test points";
  grid->source = std::move(source);
  return grid;
}

std::vector<int64_t> Numbers(const StoredGrid& grid) {
  std::vector<int64_t> numbers;
  for (const auto& r : grid.revisions) numbers.push_back(r->number);
  return numbers;
}

bool SameBits(std::span<const double> a, std::span<const double> b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

struct Watcher : server::GridWatcher {
  void Wake() override { ++wakes; }
  std::atomic<int> wakes{0};
};

// Takes the subscription's events until `count` revisions arrived or it ended (up to 5 s).
std::vector<int64_t> Collect(GridSubscription& subscription, size_t count, End* end) {
  std::vector<int64_t> numbers;
  *end = End::kOpen;
  WaitFor(absl::Seconds(5), [&] {
    server::RevisionSummary revision;
    while (subscription.Next(&revision, end)) numbers.push_back(revision.number);
    return numbers.size() >= count || *end != End::kOpen;
  });
  return numbers;
}

// ---- The fixture: one Redis, two replicas ----

class RedisStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    binary_ = FindOnPath("redis-server");
    if (binary_.empty()) {
      GTEST_SKIP() << "redis-server is not on PATH (Debian: apt-get install redis-server)";
    }
    char dir[] = "/tmp/redis_store_test.XXXXXX";
    ASSERT_NE(mkdtemp(dir), nullptr);
    dir_ = dir;
    // A free port may be taken by a parallel test before Redis binds it: try another.
    for (int attempt = 0; attempt < 3 && !(redis_ && redis_->running()); ++attempt) {
      redis_ = std::make_unique<RedisProcess>(binary_, dir_, FreePort(), durable_);
      redis_->Start();
    }
    ASSERT_TRUE(redis_->running()) << "redis-server did not start; see " << dir_ << "/redis.log";
    a_ = Open();
    b_ = Open();
  }
  void TearDown() override {
    a_.reset();
    b_.reset();
    redis_.reset();
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
  }

  void StartRedis(int port) {
    redis_ = std::make_unique<RedisProcess>(binary_, dir_, port, durable_);
    ASSERT_TRUE(redis_->Start()) << "redis-server did not answer on port " << port;
  }
  std::string Spec() const { return absl::StrCat("redis://127.0.0.1:", redis_->port()); }

  // A replica: a store of its own on the same Redis, with its own budget.
  std::unique_ptr<GridStore> Open(server::RedisStoreOptions options = {},
                                  server::MemoryBudget* budget = nullptr) {
    if (options.max_deform_revisions == 0) options.max_deform_revisions = 2;
    budgets_.push_back(std::make_unique<server::MemoryBudget>(int64_t{1} << 30));
    absl::StatusOr<std::unique_ptr<GridStore>> store =
        server::OpenRedisStore(Spec(), options, budget ? budget : budgets_.back().get());
    EXPECT_TRUE(store.ok()) << store.status();
    return store.ok() ? *std::move(store) : nullptr;
  }

  // Creates `id` on a_ with a fitted revision 1.
  void CreateFitted(const std::string& id) {
    ASSERT_TRUE(a_->Create(MakeGrid(id)).ok());
    ASSERT_TRUE(a_->AddRevision(id, MakeRevision(RevisionOrigin::kFit)).ok());
  }
  int64_t Deform(GridStore& store, const std::string& id, int64_t expected = 0) {
    absl::StatusOr<std::shared_ptr<const StoredGrid>> grid =
        store.AddRevision(id, MakeRevision(RevisionOrigin::kDeform, 1, 7), expected);
    EXPECT_TRUE(grid.ok()) << grid.status();
    return grid.ok() ? (*grid)->revisions.back()->number : -1;
  }

  std::string binary_;
  std::string dir_;
  bool durable_ = false;
  std::unique_ptr<RedisProcess> redis_;
  std::vector<std::unique_ptr<server::MemoryBudget>> budgets_;
  std::unique_ptr<GridStore> a_;
  std::unique_ptr<GridStore> b_;
  std::shared_ptr<Watcher> watcher_ = std::make_shared<Watcher>();
};

TEST_F(RedisStoreTest, CreateGetListDeleteAcrossReplicas) {
  ASSERT_TRUE(a_->Create(MakeGrid("g1")).ok());
  ASSERT_TRUE(b_->Create(MakeGrid("g2")).ok());
  const std::shared_ptr<const StoredGrid> g1 = b_->Get("g1").value();
  EXPECT_EQ(g1->display_name, "grid g1");
  EXPECT_EQ(g1->create_time, absl::FromUnixNanos(1700000000123456789));
  EXPECT_EQ(g1->source->format, "test points");
  EXPECT_TRUE(SameBits(g1->source->grid().blocks[0].coords(), SmallGrid(9, 7).blocks[0].coords()));
  EXPECT_TRUE(g1->revisions.empty());

  EXPECT_THAT(a_->Create(MakeGrid("g2")), StatusIs(absl::StatusCode::kAlreadyExists, "g2"));
  bool more = true;
  std::vector<std::string> ids;
  const auto all = a_->List("", 10, &more).value();
  for (const auto& grid : all) ids.push_back(grid->id);
  EXPECT_THAT(ids, ElementsAre("g1", "g2"));
  EXPECT_FALSE(more);
  const auto first = b_->List("", 1, &more).value();
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0]->id, "g1");
  EXPECT_TRUE(more);
  const auto second = b_->List("g1", 1, &more).value();
  ASSERT_EQ(second.size(), 1u);
  EXPECT_EQ(second[0]->id, "g2");
  EXPECT_FALSE(more);

  ASSERT_TRUE(b_->Delete("g1").ok());
  EXPECT_THAT(a_->Get("g1").status(), StatusIs(absl::StatusCode::kNotFound, "grids/g1"));
  EXPECT_THAT(a_->Delete("g1"), StatusIs(absl::StatusCode::kNotFound, "grids/g1"));
  EXPECT_EQ(a_->List("", 10, &more).value().size(), 1u);
  // Created again under the same id: a new grid, nothing of the old one.
  ASSERT_TRUE(a_->Create(MakeGrid("g1")).ok());
  EXPECT_TRUE(b_->Get("g1").value()->revisions.empty());
}

// A delete with an owner check removes the grid only if the check passes for the owner the grid
// has at the moment of removal: a grid deleted and created again by another principal between
// the check and the removal is not removed.
TEST_F(RedisStoreTest, DeleteWithAnOwnerCheckIsCompareAndDelete) {
  auto owned_by = [](const std::string& id, const std::string& owner) {
    std::shared_ptr<StoredGrid> grid = MakeGrid(id);
    grid->owner = owner;
    return grid;
  };
  auto only = [](const std::string& allowed) {
    return [allowed](const std::string& owner) {
      return owner == allowed ? absl::OkStatus()
                              : absl::PermissionDeniedError(absl::StrCat("owned by ", owner));
    };
  };
  ASSERT_TRUE(a_->Create(owned_by("g", "alice")).ok());
  EXPECT_THAT(b_->Delete("g", only("bob")),
              StatusIs(absl::StatusCode::kPermissionDenied, "owned by alice"));
  EXPECT_TRUE(a_->Get("g").ok());
  EXPECT_THAT(b_->Delete("absent", only("bob")), StatusIs(absl::StatusCode::kNotFound, "absent"));

  // Alice's delete passes its check, but before the removal the grid is deleted and created
  // again by bob (from inside the check: between reading the owner and the script).
  bool raced = false;
  const absl::Status status = a_->Delete("g", [&](const std::string& owner) -> absl::Status {
    if (!raced) {
      raced = true;
      EXPECT_TRUE(b_->Delete("g").ok());
      EXPECT_TRUE(b_->Create(owned_by("g", "bob")).ok());
    }
    return only("alice")(owner);
  });
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kPermissionDenied, "owned by bob"));
  ASSERT_TRUE(a_->Get("g").ok()) << "bob's grid was removed";
  EXPECT_EQ(a_->Get("g").value()->owner, "bob");
  EXPECT_TRUE(b_->Delete("g", only("bob")).ok());
  EXPECT_THAT(a_->Get("g").status(), StatusIs(absl::StatusCode::kNotFound, "g"));
}

// Everything a grid has lives under its keys; a deletion leaves only the event stream (which
// expires) behind.
TEST_F(RedisStoreTest, DeleteRemovesEveryKeyOfTheGrid) {
  CreateFitted("g");
  Deform(*b_, "g");
  const server::RedisAddress address = Loopback(redis_->port());
  auto redis = server::RedisConnection::Open(address, {}).value();
  auto keys = [&] {
    std::vector<std::string> names;
    const server::RedisReply reply = redis->Command({"KEYS", "*"}).value();
    for (size_t i = 0; i < reply.value().size(); ++i) {
      names.emplace_back(reply.value()[i].str());
    }
    std::sort(names.begin(), names.end());
    return names;
  };
  EXPECT_EQ(keys().size(), 8u) << "grids, grid:g, header, source, revs, nums, deforms, events";
  ASSERT_TRUE(a_->Delete("g").ok());
  const std::vector<std::string> left = keys();
  ASSERT_EQ(left.size(), 1u);
  EXPECT_THAT(left[0], ::testing::EndsWith(":events"));
  EXPECT_GT(redis->Command({"TTL", left[0]}).value().value().AsInt().value_or(-1), 0);
}

TEST_F(RedisStoreTest, CreateIsAtomicAcrossReplicas) {
  for (int round = 0; round < 8; ++round) {
    const std::string id = absl::StrCat("race", round);
    absl::Status from_a, from_b;
    std::thread ta([&] { from_a = a_->Create(MakeGrid(id)); });
    std::thread tb([&] { from_b = b_->Create(MakeGrid(id)); });
    ta.join();
    tb.join();
    EXPECT_NE(from_a.ok(), from_b.ok()) << from_a << " / " << from_b;
    const absl::Status& lost = from_a.ok() ? from_b : from_a;
    EXPECT_EQ(lost.code(), absl::StatusCode::kAlreadyExists) << lost;
  }
  // The losers' uploads were removed: 8 grids of 3 keys (grid, header, source) and the index.
  const server::RedisAddress address = Loopback(redis_->port());
  auto redis = server::RedisConnection::Open(address, {}).value();
  EXPECT_EQ(redis->Command({"DBSIZE"}).value().value().AsInt(), 8 * 3 + 1);
}

// A crashed creation leaves keys under its own generation: they do not block the id, they are
// not seen, and they expire.
TEST_F(RedisStoreTest, LeftoversOfACrashedCreateDoNotBlockTheId) {
  const server::RedisAddress address = Loopback(redis_->port());
  auto redis = server::RedisConnection::Open(address, {}).value();
  for (const char* part : {"header", "source", "revs"}) {
    ASSERT_TRUE(redis
                    ->Command({"SET", absl::StrCat("splinegrid:grid:g:00000000deadbeef:", part),
                               "half written", "EX", "600"})
                    .ok());
  }
  bool more = false;
  EXPECT_TRUE(a_->List("", 10, &more).value().empty());
  EXPECT_EQ(a_->Get("g").status().code(), absl::StatusCode::kNotFound);
  ASSERT_TRUE(a_->Create(MakeGrid("g")).ok());
  ASSERT_TRUE(a_->AddRevision("g", MakeRevision(RevisionOrigin::kFit)).ok());
  EXPECT_THAT(Numbers(*b_->Get("g").value()), ElementsAre(1));
}

TEST_F(RedisStoreTest, RevisionPublishedThroughOneReplicaIsSeenByTheOther) {
  ASSERT_TRUE(a_->Create(MakeGrid("g")).ok());
  const auto on_b = b_->Get("g").value();  // b caches the grid without revisions
  const auto fitted = a_->AddRevision("g", MakeRevision(RevisionOrigin::kFit)).value();
  EXPECT_THAT(Numbers(*fitted), ElementsAre(1));
  const auto seen = b_->Get("g").value();
  ASSERT_THAT(Numbers(*seen), ElementsAre(1));
  EXPECT_EQ(seen->source.get(), on_b->source.get()) << "source decoded once per process";
  const GridRevision& revision = *seen->revisions[0];
  EXPECT_EQ(revision.origin, RevisionOrigin::kFit);
  EXPECT_EQ(revision.create_time, absl::FromUnixMicros(1700000000123456));
  ASSERT_EQ(revision.blocks.size(), SmallFit().blocks.size());
  EXPECT_TRUE(SameBits(revision.blocks[0].fitted.spline.control(),
                       SmallFit().blocks[0].fitted.spline.control()));

  EXPECT_EQ(Deform(*b_, "g"), 2);
  const auto on_a = a_->Get("g").value();
  EXPECT_THAT(Numbers(*on_a), ElementsAre(1, 2));
  EXPECT_EQ(on_a->revisions[0].get(), fitted->revisions[0].get()) << "revision decoded once";
  EXPECT_EQ(on_a->revisions[1]->parent, 1);
  EXPECT_EQ(on_a->revisions[1]->step, 7);
  EXPECT_EQ(a_->Get("g").value().get(), on_a.get()) << "nothing new: the same snapshot";
}

TEST_F(RedisStoreTest, ConcurrentWritersFromTheSameBaseExactlyOneWins) {
  CreateFitted("g");
  int64_t latest = 1;
  for (int round = 0; round < 10; ++round) {
    absl::StatusOr<std::shared_ptr<const StoredGrid>> from_a, from_b;
    std::thread ta(
        [&] { from_a = a_->AddRevision("g", MakeRevision(RevisionOrigin::kDeform, 1), latest); });
    std::thread tb(
        [&] { from_b = b_->AddRevision("g", MakeRevision(RevisionOrigin::kDeform, 1), latest); });
    ta.join();
    tb.join();
    ASSERT_NE(from_a.ok(), from_b.ok()) << from_a.status() << " / " << from_b.status();
    const auto& won = from_a.ok() ? from_a : from_b;
    const auto& lost = from_a.ok() ? from_b : from_a;
    EXPECT_EQ((*won)->revisions.back()->number, latest + 1);
    EXPECT_THAT(lost.status(), StatusIs(absl::StatusCode::kAborted,
                                        absl::StrCat("base_revision ", latest, " is stale")));
    ++latest;
  }
  // Unconditional writers never conflict: both get a number, different ones.
  absl::StatusOr<std::shared_ptr<const StoredGrid>> from_a, from_b;
  std::thread ta([&] { from_a = a_->AddRevision("g", MakeRevision(RevisionOrigin::kFit)); });
  std::thread tb([&] { from_b = b_->AddRevision("g", MakeRevision(RevisionOrigin::kFit)); });
  ta.join();
  tb.join();
  ASSERT_TRUE(from_a.ok() && from_b.ok());
  EXPECT_NE((*from_a)->revisions.back()->number, (*from_b)->revisions.back()->number);
  EXPECT_EQ(b_->Get("g").value()->revisions.back()->number, latest + 2);
}

// GetHolding answers given revisions from the replica's own snapshot while Redis confirmed it
// within cached_read_window (no round trip), and asks Redis after that, for the latest (0), and
// for revisions the snapshot does not hold.
TEST_F(RedisStoreTest, GetHoldingReadsRecentSnapshotsWithoutARoundTrip) {
  server::RedisStoreOptions options;
  options.cached_read_window = absl::Milliseconds(300);
  std::unique_ptr<GridStore> reader = Open(options);
  CreateFitted("g");
  ASSERT_EQ(reader->Get("g").value()->revisions.size(), 1u);  // cached, confirmed now
  const int64_t added = Deform(*b_, "g");
  ASSERT_EQ(added, 2);
  // Revision 1 from the snapshot (it does not know revision 2 yet); revision 2 and the latest
  // from Redis.
  EXPECT_EQ(reader->GetHolding("g", {1}).value()->revisions.back()->number, 1);
  EXPECT_EQ(reader->GetHolding("g", {1, 2}).value()->revisions.back()->number, 2);
  EXPECT_EQ(reader->GetHolding("g", {0}).value()->revisions.back()->number, 2);

  // Deleted through another replica: readable here for at most the window, then NOT_FOUND.
  ASSERT_TRUE(b_->Delete("g").ok());
  EXPECT_THAT(reader->GetHolding("g", {0}).status(), StatusIs(absl::StatusCode::kNotFound, "g"));
  ASSERT_TRUE(reader->Create(MakeGrid("h")).ok());
  const absl::Time before_confirmed = absl::Now();
  ASSERT_TRUE(reader->AddRevision("h", MakeRevision(RevisionOrigin::kFit)).ok());
  const absl::Time after_confirmed = absl::Now();
  ASSERT_TRUE(b_->Delete("h").ok());
  absl::StatusOr<std::shared_ptr<const StoredGrid>> stale = reader->GetHolding("h", {1});
  EXPECT_TRUE(stale.ok() || absl::Now() - after_confirmed > absl::Milliseconds(300))
      << "read from the snapshot within the window: " << stale.status();
  while (stale.ok()) {
    ASSERT_LT(absl::Now() - after_confirmed, absl::Seconds(5)) << "the snapshot never expired";
    absl::SleepFor(absl::Milliseconds(20));
    stale = reader->GetHolding("h", {1});
  }
  EXPECT_THAT(stale.status(), StatusIs(absl::StatusCode::kNotFound, "h"));
  EXPECT_GE(absl::Now() - before_confirmed, absl::Milliseconds(300));

  // A window of zero: every call asks Redis.
  options.cached_read_window = absl::ZeroDuration();
  std::unique_ptr<GridStore> strict = Open(options);
  ASSERT_TRUE(strict->Create(MakeGrid("k")).ok());
  ASSERT_TRUE(strict->AddRevision("k", MakeRevision(RevisionOrigin::kFit)).ok());
  ASSERT_TRUE(b_->Delete("k").ok());
  EXPECT_THAT(strict->GetHolding("k", {1}).status(), StatusIs(absl::StatusCode::kNotFound, "k"));
}

TEST_F(RedisStoreTest, RetentionDropsOldDeformedRevisionsAndNumbersAreNeverReused) {
  CreateFitted("g");                                           // 1
  for (int r = 0; r < 3; ++r) Deform(r % 2 ? *a_ : *b_, "g");  // 2, 3, 4
  EXPECT_THAT(Numbers(*a_->Get("g").value()), ElementsAre(1, 3, 4));
  const auto on_b = b_->Get("g").value();
  EXPECT_THAT(Numbers(*on_b), ElementsAre(1, 3, 4));
  EXPECT_THAT(on_b->ResolveRevision(2).status(),
              StatusIs(absl::StatusCode::kNotFound, "dropped by retention"));
  ASSERT_TRUE(b_->AddRevision("g", MakeRevision(RevisionOrigin::kFair, 1)).ok());  // 5
  EXPECT_EQ(Deform(*a_, "g"), 6);
  std::unique_ptr<GridStore> cold = Open();  // reads it all from Redis
  EXPECT_THAT(Numbers(*cold->Get("g").value()), ElementsAre(1, 4, 5, 6));
  EXPECT_THAT(Numbers(*a_->Get("g").value()), ElementsAre(1, 4, 5, 6));
}

// A grid created with more deformed revisions than retention keeps (an imported archive) keeps
// the newest ones, as if they had been deformed here; a trial's import kept all 64 under
// --keep_revisions=5 until the next deform.
TEST_F(RedisStoreTest, ACreatedGridKeepsOnlyTheDeformedRevisionsRetentionKeeps) {
  auto grid = MakeGrid("imported");
  for (int64_t n = 1; n <= 6; ++n) {
    auto revision = std::make_shared<GridRevision>(
        n == 1 ? MakeRevision(RevisionOrigin::kFit) : MakeRevision(RevisionOrigin::kDeform, 1, n));
    revision->number = n;
    grid->revisions.push_back(std::move(revision));
  }
  ASSERT_TRUE(a_->Create(grid).ok());
  EXPECT_THAT(Numbers(*b_->Get("imported").value()), ElementsAre(1, 5, 6));  // keeps 2
  EXPECT_EQ(Deform(*b_, "imported"), 7);
  EXPECT_THAT(Numbers(*a_->Get("imported").value()), ElementsAre(1, 6, 7));
}

// Revision numbers of any size survive the script's number encoding (varints of 1-3 bytes).
TEST_F(RedisStoreTest, ImportedNumbersAreKeptAndContinued) {
  for (int64_t number : {127, 300, 20000}) {
    const std::string id = absl::StrCat("n", number);
    auto grid = MakeGrid(id);
    GridRevision imported = MakeRevision(RevisionOrigin::kFit);
    imported.number = number;
    grid->revisions.push_back(std::make_shared<const GridRevision>(std::move(imported)));
    ASSERT_TRUE(a_->Create(grid).ok());
    EXPECT_EQ(Deform(*a_, id), number + 1);
    std::unique_ptr<GridStore> cold = Open();
    EXPECT_THAT(Numbers(*cold->Get(id).value()), ElementsAre(number, number + 1));
  }
}

TEST_F(RedisStoreTest, AddRevisionToAMissingGridIsNotFound) {
  EXPECT_THAT(a_->AddRevision("nothing", MakeRevision(RevisionOrigin::kFit)).status(),
              StatusIs(absl::StatusCode::kNotFound, "grids/nothing"));
  CreateFitted("g");
  ASSERT_TRUE(b_->Delete("g").ok());
  EXPECT_THAT(a_->AddRevision("g", MakeRevision(RevisionOrigin::kDeform, 1), 1).status(),
              StatusIs(absl::StatusCode::kNotFound, "grids/g was deleted"));
}

// A revision made from a grid read through one replica is not published on a grid created again
// under the same id through another meanwhile: the generation is checked in the script.
TEST_F(RedisStoreTest, ARevisionOfAnEarlierCreationOfTheIdIsRefused) {
  CreateFitted("g");
  const std::shared_ptr<const StoredGrid> read = a_->Get("g").value();
  EXPECT_EQ(read->incarnation.size(), 16u);
  ASSERT_TRUE(b_->Delete("g").ok());
  ASSERT_TRUE(b_->Create(MakeGrid("g")).ok());
  const std::shared_ptr<const StoredGrid> again = b_->Get("g").value();
  EXPECT_NE(again->incarnation, read->incarnation);
  EXPECT_THAT(
      a_->AddRevision("g", MakeRevision(RevisionOrigin::kFit), 0, read->incarnation).status(),
      StatusIs(absl::StatusCode::kAborted, "grids/g was deleted and created again"));
  // The refusal drops a's snapshot of the earlier creation: a read of a given revision (which
  // may answer from a recent snapshot) sees the new creation at once.
  EXPECT_EQ(a_->GetHolding("g", {1}).value()->incarnation, again->incarnation);
  EXPECT_TRUE(a_->Get("g").value()->revisions.empty());
  // The new creation takes revisions made from it, on either replica.
  EXPECT_TRUE(a_->AddRevision("g", MakeRevision(RevisionOrigin::kFit), 0, again->incarnation).ok());
  EXPECT_EQ(b_->Get("g").value()->incarnation, again->incarnation);
}

TEST_F(RedisStoreTest, WatchSeesRevisionsFromTheOtherReplicaInOrderThenTheDeletion) {
  CreateFitted("g");
  GridStore::Watch on_a = a_->Subscribe("g", watcher_, 64).value();
  GridStore::Watch on_b = b_->Subscribe("g", watcher_, 64).value();
  EXPECT_THAT(Numbers(*on_a.snapshot), ElementsAre(1));
  for (int r = 0; r < 5; ++r) Deform(*b_, "g");
  End end;
  EXPECT_THAT(Collect(*on_a.subscription, 5, &end), ElementsAre(2, 3, 4, 5, 6));
  EXPECT_EQ(end, End::kOpen);
  Deform(*a_, "g");
  ASSERT_TRUE(b_->Delete("g").ok());
  EXPECT_THAT(Collect(*on_a.subscription, 99, &end), ElementsAre(7));
  EXPECT_EQ(end, End::kGridDeleted);
  EXPECT_THAT(Collect(*on_b.subscription, 99, &end), ElementsAre(2, 3, 4, 5, 6, 7));
  EXPECT_EQ(end, End::kGridDeleted);
  EXPECT_GT(watcher_->wakes.load(), 0);
  // A grid created again under the id is another grid: the ended watch stays ended.
  CreateFitted("g");
  Deform(*b_, "g");
  absl::SleepFor(absl::Milliseconds(300));
  EXPECT_TRUE(Collect(*on_a.subscription, 0, &end).empty());
  EXPECT_EQ(end, End::kGridDeleted);
}

// Watches opened on replica a while replica b publishes: each sees exactly the revisions after
// its snapshot, in order, none missed or repeated.
TEST_F(RedisStoreTest, WatchesStartedWhilePublishingMissNothing) {
  CreateFitted("g");
  constexpr int kPublished = 40;
  std::thread publisher([&] {
    for (int r = 0; r < kPublished; ++r) Deform(*b_, "g");
  });
  std::vector<GridStore::Watch> watches;
  for (int w = 0; w < 8; ++w) {
    watches.push_back(a_->Subscribe("g", watcher_, 1000).value());
    absl::SleepFor(absl::Milliseconds(5));
  }
  publisher.join();
  const int64_t last = 1 + kPublished;
  for (GridStore::Watch& watch : watches) {
    const int64_t from = watch.snapshot->revisions.back()->number;
    End end;
    const std::vector<int64_t> seen = Collect(*watch.subscription, last - from, &end);
    std::vector<int64_t> expected;
    for (int64_t n = from + 1; n <= last; ++n) expected.push_back(n);
    EXPECT_EQ(seen, expected) << "watch from " << from;
    EXPECT_EQ(end, End::kOpen);
  }
}

TEST_F(RedisStoreTest, UnsubscribeAndCloseSubscriptions) {
  CreateFitted("g");
  GridStore::Watch kept = a_->Subscribe("g", watcher_, 64).value();
  GridStore::Watch dropped = a_->Subscribe("g", std::make_shared<Watcher>(), 64).value();
  a_->Unsubscribe("g", dropped.subscription.get());
  Deform(*b_, "g");
  End end;
  EXPECT_THAT(Collect(*kept.subscription, 1, &end), ElementsAre(2));
  absl::SleepFor(absl::Milliseconds(200));
  EXPECT_TRUE(Collect(*dropped.subscription, 0, &end).empty());
  EXPECT_EQ(end, End::kOpen);
  a_->CloseSubscriptions();
  Collect(*kept.subscription, 0, &end);
  EXPECT_EQ(end, End::kClosed);
  EXPECT_EQ(a_->Subscribe("g", watcher_, 64).status().code(), absl::StatusCode::kUnavailable);
  EXPECT_TRUE(b_->Subscribe("g", watcher_, 64).ok()) << "only a's watches closed";
}

TEST_F(RedisStoreTest, SourceOfSeveralChunksRoundTripsBitwise) {
  MultiBlockGrid points;
  // 2 x 400 x 300 = 240000 coordinates: two chunks, then iblank; a small second block.
  StructuredBlock big({400, 300, 1}, 2);
  std::span<double> coords = big.coords();
  // A wavy grid (the store keeps fittable points only) whose low bits differ everywhere, with
  // a negative zero, a denormal and a value one ulp off.
  for (int j = 0; j < 300; ++j) {
    for (int i = 0; i < 400; ++i) {
      const size_t p = 400 * j + i;
      coords[2 * p] = i + 0.25 * std::sin(0.01 * j) + 1e-9 * p;
      coords[2 * p + 1] = j + 0.25 * std::sin(0.01 * i) + 1e-9 * p;
    }
  }
  coords[0] = -0.0;
  coords[1] = std::numeric_limits<double>::denorm_min();
  coords[123457] = std::nextafter(coords[123457], 1e9);
  big.iblank().assign(120000, 1);
  big.iblank()[99999] = 0;
  points.blocks.push_back(std::move(big));
  StructuredBlock small({5, 4, 1}, 2);
  for (int p = 0; p < 20; ++p) {
    small.coords()[2 * p] = 0.1 * (p % 5);
    small.coords()[2 * p + 1] = 0.1 * (p / 5) + 0.01 * p;
  }
  small.iblank().assign(20, 1);
  small.iblank()[7] = 0;
  small.iblank()[8] = -2;
  points.blocks.push_back(std::move(small));
  const MultiBlockGrid expected = points;
  const absl::Status created = a_->Create(MakeGrid("big", std::move(points)));
  ASSERT_TRUE(created.ok()) << created;
  const auto got = b_->Get("big").value();
  ASSERT_EQ(got->source->grid().blocks.size(), 2u);
  for (int b = 0; b < 2; ++b) {
    const StructuredBlock& block = got->source->grid().blocks[b];
    EXPECT_EQ(block.extents(), expected.blocks[b].extents());
    EXPECT_TRUE(SameBits(block.coords(), expected.blocks[b].coords())) << "block " << b;
    EXPECT_EQ(block.iblank(), expected.blocks[b].iblank());
  }
}

TEST_F(RedisStoreTest, SourceBeyondTheLimitIsRefused) {
  EXPECT_EQ(server::kMaxRedisSourceBytes, int64_t{1} << 30);
  server::RedisStoreOptions options;
  options.max_source_bytes = int64_t{1} << 20;
  std::unique_ptr<GridStore> limited = Open(options);
  const absl::Status refused = limited->Create(MakeGrid("huge", SmallGrid(400, 300)));
  EXPECT_THAT(refused, StatusIs(absl::StatusCode::kResourceExhausted,
                                "the source points take 1.83 MiB (1920000 bytes)"));
  EXPECT_THAT(refused.message(), HasSubstr("at most 1.00 MiB (1048576 bytes)"));
  EXPECT_EQ(a_->Get("huge").status().code(), absl::StatusCode::kNotFound);
}

// The cache gives way when the budget is short: the least recently used grid's snapshot goes.
TEST_F(RedisStoreTest, CacheEvictsLeastRecentlyUsedGridsWhenTheBudgetIsShort) {
  ASSERT_TRUE(a_->Create(MakeGrid("g1", SmallGrid(200, 100))).ok());  // 320000 bytes each
  ASSERT_TRUE(a_->Create(MakeGrid("g2", SmallGrid(200, 100))).ok());
  server::MemoryBudget budget(500000);
  std::unique_ptr<GridStore> small = Open({}, &budget);
  EXPECT_TRUE(small->Get("g1").ok());
  EXPECT_GE(budget.used(), 320000);
  EXPECT_TRUE(small->Get("g2").ok()) << "g1's snapshot is evicted to make room";
  EXPECT_LE(budget.used(), 500000);
  {
    const auto held = small->Get("g1").value();  // a reader holds g1: eviction cannot help
    EXPECT_THAT(small->Get("g2").status(),
                StatusIs(absl::StatusCode::kResourceExhausted, "source points"));
  }
  EXPECT_TRUE(small->Get("g2").ok());
}

TEST_F(RedisStoreTest, RedisDownIsUnavailableAndTheStoreRecoversByItself) {
  CreateFitted("g");
  GridStore::Watch watch = a_->Subscribe("g", watcher_, 64).value();
  EXPECT_TRUE(a_->Available().ok());
  redis_->Kill();
  const absl::Status down = a_->Get("g").status();
  EXPECT_THAT(down, StatusIs(absl::StatusCode::kUnavailable,
                             absl::StrCat("Redis at 127.0.0.1:", redis_->port())));
  EXPECT_EQ(b_->AddRevision("g", MakeRevision(RevisionOrigin::kFit)).status().code(),
            absl::StatusCode::kUnavailable);
  EXPECT_TRUE(WaitFor(absl::Seconds(3), [&] { return !a_->Available().ok(); }));
  EXPECT_THAT(a_->Available(), StatusIs(absl::StatusCode::kUnavailable, "Redis at 127.0.0.1"));
  absl::Time t = absl::Now();
  while (absl::Now() - t < absl::Seconds(1)) {  // failing fast while it is down
    EXPECT_EQ(a_->Get("g").status().code(), absl::StatusCode::kUnavailable);
  }

  // Back on the same port, empty (no persistence): both replicas serve again by themselves.
  ASSERT_NO_FATAL_FAILURE(StartRedis(redis_->port()));
  t = absl::Now();
  EXPECT_TRUE(
      WaitFor(absl::Seconds(5), [&] { return a_->Available().ok() && b_->Available().ok(); }));
  EXPECT_TRUE(WaitFor(absl::Seconds(5), [&] { return a_->Create(MakeGrid("after")).ok(); }));
  std::printf("recovered %.2f s after Redis was back\n", absl::ToDoubleSeconds(absl::Now() - t));
  EXPECT_TRUE(b_->Get("after").ok());
  EXPECT_EQ(b_->Get("g").status().code(), absl::StatusCode::kNotFound) << "Redis lost it";
  // The watch cannot know what it missed: it ends (the service says UNAVAILABLE).
  End end;
  EXPECT_TRUE(Collect(*watch.subscription, 99, &end).empty());
  EXPECT_EQ(end, End::kClosed);
}

// With appendfsync always Redis keeps every acknowledged write: after a crash and restart the
// grid is whole and a watch carries on from where it was.
// Redis with an append-only file (appendfsync always).
class DurableRedisStoreTest : public RedisStoreTest {
 protected:
  DurableRedisStoreTest() { durable_ = true; }
};

TEST_F(DurableRedisStoreTest, WatchResumesWhenRedisComesBackWithItsData) {
  CreateFitted("g");
  Deform(*b_, "g");  // 2
  GridStore::Watch watch = a_->Subscribe("g", watcher_, 64).value();
  Deform(*b_, "g");  // 3
  End end;
  EXPECT_THAT(Collect(*watch.subscription, 1, &end), ElementsAre(3));
  const int port = redis_->port();
  redis_->Kill();
  ASSERT_NO_FATAL_FAILURE(StartRedis(port));
  ASSERT_TRUE(WaitFor(absl::Seconds(5), [&] { return b_->Available().ok(); }));
  int64_t four = -1;
  ASSERT_TRUE(WaitFor(absl::Seconds(5), [&] {
    absl::StatusOr<std::shared_ptr<const StoredGrid>> grid =
        b_->AddRevision("g", MakeRevision(RevisionOrigin::kDeform, 1));
    if (grid.ok()) four = (*grid)->revisions.back()->number;
    return grid.ok();
  }));
  EXPECT_EQ(four, 4);
  EXPECT_THAT(Collect(*watch.subscription, 1, &end), ElementsAre(4));
  EXPECT_EQ(end, End::kOpen);
  EXPECT_THAT(Numbers(*a_->Get("g").value()), ElementsAre(1, 3, 4));
}

TEST_F(RedisStoreTest, OpenAgainstAClosedPortIsUnavailableAtOnce) {
  const int nothing = FreePort();
  const absl::Time start = absl::Now();
  server::MemoryBudget budget(1 << 20);
  server::RedisStoreOptions options;
  options.max_deform_revisions = 2;
  const auto store =
      server::OpenRedisStore(absl::StrCat("redis://127.0.0.1:", nothing), options, &budget);
  EXPECT_LT(absl::Now() - start, absl::Seconds(1));
  EXPECT_THAT(store.status(), StatusIs(absl::StatusCode::kUnavailable,
                                       absl::StrCat("Redis at 127.0.0.1:", nothing)));
}

TEST_F(RedisStoreTest, SpecsAreParsedStrictly) {
  const server::RedisAddress full = server::ParseRedisSpec("redis://cache.local:6380/15").value();
  EXPECT_EQ(full.host, "cache.local");
  EXPECT_EQ(full.port, 6380);
  EXPECT_EQ(full.db, 15);
  const server::RedisAddress v6 = server::ParseRedisSpec("redis://[::1]:6379").value();
  EXPECT_EQ(v6.host, "::1");
  EXPECT_EQ(v6.db, 0);
  EXPECT_EQ(v6.ToString(), "[::1]:6379");
  server::MemoryBudget budget(1 << 20);
  server::RedisStoreOptions options;
  options.max_deform_revisions = 2;
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"redis://", "no :PORT"},
      {"redis://host", "no :PORT"},
      {"redis://:6379", "the host is empty"},
      {"redis://host:0", "the port '0'"},
      {"redis://host:65536", "the port '65536'"},
      {"redis://host:63x9", "the port '63x9'"},
      {"redis://host:-1", "the port '-1'"},
      {"redis://host:6379/", "the database ''"},
      {"redis://host:6379/x", "the database 'x'"},
      {"redis://host:6379/1/2", "the database '1/2'"},
      {"redis://:@host:6379", "the password after USER: is empty"},
      {"redis://u%4@host:6379", "two hex digits"},
      {"redis://u%zz:pw@host:6379", "two hex digits"},
      {"redis://host:6379?db=1", "options"},
      {"rediss://host:6379", "redis://"},
      {"redis://[::1:6379", "closing ]"},
  };
  for (const auto& [spec, why] : bad) {
    EXPECT_THAT(server::OpenRedisStore(spec, options, &budget).status(),
                StatusIs(absl::StatusCode::kInvalidArgument, why))
        << spec;
  }
  // A database Redis does not have (16 by default).
  EXPECT_THAT(server::OpenRedisStore(Spec() + "/99", options, &budget).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "database 99"));
  // Databases keep deployments apart.
  std::unique_ptr<GridStore> other =
      server::OpenRedisStore(Spec() + "/3", options, &budget).value();
  ASSERT_TRUE(a_->Create(MakeGrid("g")).ok());
  EXPECT_EQ(other->Get("g").status().code(), absl::StatusCode::kNotFound);
  ASSERT_TRUE(other->Create(MakeGrid("g")).ok());
}

TEST_F(RedisStoreTest, CredentialsAreParsedAndNeverQuoted) {
  const server::RedisAddress acl =
      server::ParseRedisSpec("redis://solver:p%40ss%3Aw%2Frd%25@cache.local:6380/2").value();
  EXPECT_EQ(acl.user, "solver");
  EXPECT_EQ(acl.password, "p@ss:w/rd%");
  EXPECT_EQ(acl.host, "cache.local");
  EXPECT_EQ(acl.port, 6380);
  EXPECT_EQ(acl.db, 2);
  EXPECT_EQ(acl.ToString(), "cache.local:6380/2");
  // A raw '@' or '/' in the password: everything before the last '@' is the credentials.
  const server::RedisAddress raw = server::ParseRedisSpec("redis://:a@b/c@h:1").value();
  EXPECT_EQ(raw.user, "");
  EXPECT_EQ(raw.password, "a@b/c");
  EXPECT_EQ(raw.host, "h");
  EXPECT_EQ(server::ParseRedisSpec("redis://solver@h:1").value().user, "solver");

  EXPECT_EQ(server::RedactRedisSpec("redis://u:s3cret@h:1/2"), "redis://u:***@h:1/2");
  EXPECT_EQ(server::RedactRedisSpec("redis://:s3cret@h:1"), "redis://:***@h:1");
  EXPECT_EQ(server::RedactRedisSpec("redis://:a@b/c@h:1"), "redis://:***@h:1");
  EXPECT_EQ(server::RedactRedisSpec("reddis://u:s3cret@h:1"), "reddis://u:***@h:1");
  EXPECT_EQ(server::RedactRedisSpec("redis://s3cret@h:1"), "redis://***@h:1");
  EXPECT_EQ(server::RedactRedisSpec("redis://h:1/2"), "redis://h:1/2");
  EXPECT_EQ(server::RedactRedisSpec("dir:/var/lib/a:b@c"), "dir:/var/lib/a:b@c");

  // Refusals of specs with a password quote them without it.
  server::MemoryBudget budget(1 << 20);
  server::RedisStoreOptions options;
  options.max_deform_revisions = 2;
  for (const std::string spec : {"redis://u:s3cret@h:0", "redis://u:s3cret@h:1?x",
                                 "redis://u:s3cret@:1", "redis://u:s3cret@h:1/x"}) {
    const absl::Status status = server::OpenRedisStore(spec, options, &budget).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << spec;
    EXPECT_THAT(status.message(), Not(HasSubstr("s3cret"))) << status;
    EXPECT_THAT(status.message(), HasSubstr("u:***@")) << status;
  }
  // A user needs a password; a password is given once.
  EXPECT_THAT(server::OpenRedisStore("redis://solver@h:1", options, &budget).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "names a user without a password"));
  // A long password is redacted before a message cuts the spec to 200 characters.
  const std::string long_secret = std::string(300, 'q') + "s3cret";
  const absl::Status long_spec =
      server::OpenRedisStore("redis://u:" + long_secret + "@h:0", options, &budget).status();
  EXPECT_EQ(long_spec.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(long_spec.message(), Not(HasSubstr("qqqq")));
  options.password_file = dir_ + "/unused";
  EXPECT_THAT(server::OpenRedisStore("redis://:pw@h:1", options, &budget).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "give it once"));
}

// A Redis with a password (requirepass) and an ACL user: logging in from the spec or from a
// file, what a missing, wrong, unreadable or empty password gets (never quoting it), and a
// rotated password taken by new connections without reopening the store.
TEST_F(RedisStoreTest, PasswordsFromTheSpecOrAFileAreSentOnEveryConnection) {
  const std::string secret = "s3cret-a9";
  const std::string auth_dir = dir_ + "/auth";
  std::filesystem::create_directories(auth_dir);
  RedisProcess locked(binary_, auth_dir, FreePort(), /*durable=*/false, secret);
  ASSERT_TRUE(locked.Start()) << "see " << auth_dir << "/redis.log";
  const std::string at = absl::StrCat("127.0.0.1:", locked.port());
  server::MemoryBudget budget(int64_t{1} << 30);
  server::RedisStoreOptions options;
  options.max_deform_revisions = 2;
  auto open = [&](const std::string& spec) {
    return server::OpenRedisStore(spec, options, &budget);
  };

  // Nothing given, or a wrong password: UNAVAILABLE saying what Redis wants.
  absl::Status status = open("redis://" + at).status();
  EXPECT_THAT(status, StatusIs(absl::StatusCode::kUnavailable, "requires a password"));
  EXPECT_THAT(status.message(), HasSubstr("--redis_password_file"));
  status = open("redis://:wrong-a9@" + at).status();
  EXPECT_THAT(status,
              StatusIs(absl::StatusCode::kUnavailable, "refuses the password of the default user"));
  EXPECT_THAT(status.message(), Not(HasSubstr("wrong-a9")));

  // The password in the spec: a working store.
  std::unique_ptr<GridStore> from_spec = open("redis://:" + secret + "@" + at).value();
  ASSERT_TRUE(from_spec->Create(MakeGrid("g")).ok());
  EXPECT_TRUE(from_spec->Get("g").ok());

  // An ACL user with what deploy/README.md says it needs, whose password needs escapes in a
  // URL, on database 2: it creates, deforms and reads.
  auto admin = server::RedisConnection::Open(Loopback(locked.port(), secret), {}).value();
  ASSERT_TRUE(admin
                  ->Command({"ACL", "SETUSER", "solver", "on", ">p@ss:w/rd%", "~splinegrid:*",
                             "+@all", "-@dangerous", "+info"})
                  .ok());
  std::unique_ptr<GridStore> as_user =
      open("redis://solver:p%40ss%3Aw%2Frd%25@" + at + "/2").value();
  EXPECT_EQ(as_user->Get("g").status().code(), absl::StatusCode::kNotFound);  // database 2
  ASSERT_TRUE(as_user->Create(MakeGrid("g2")).ok());
  ASSERT_TRUE(as_user->AddRevision("g2", MakeRevision(RevisionOrigin::kFit)).ok());
  EXPECT_EQ(Deform(*as_user, "g2"), 2);
  EXPECT_THAT(Numbers(*as_user->Get("g2").value()), ElementsAre(1, 2));
  EXPECT_THAT(open("redis://solver:p%40ss@" + at).status(),
              StatusIs(absl::StatusCode::kUnavailable, "refuses the password of user 'solver'"));

  // From a file: its first line; missing, empty or oversized files are refused by name.
  const std::string file = auth_dir + "/password";
  std::ofstream(file) << secret << "\r\nsecond line\n";
  options.password_file = file;
  std::unique_ptr<GridStore> from_file = open("redis://" + at).value();
  EXPECT_TRUE(from_file->Get("g").ok());
  options.password_file = auth_dir + "/missing";
  EXPECT_THAT(open("redis://" + at).status(),
              StatusIs(absl::StatusCode::kUnavailable, "cannot read --redis_password_file"));
  const std::string empty = auth_dir + "/empty";
  std::ofstream(empty) << "\n";
  options.password_file = empty;
  EXPECT_THAT(open("redis://" + at).status(),
              StatusIs(absl::StatusCode::kUnavailable, "holds no password"));
  const std::string large = auth_dir + "/large";
  std::ofstream(large) << std::string(5000, 'x');
  options.password_file = large;
  EXPECT_THAT(open("redis://" + at).status(),
              StatusIs(absl::StatusCode::kUnavailable, "larger than 4096 bytes"));

  // Rotation: a new password in Redis and in the file, every connection dropped; the store
  // opened from the file logs in again with the new one, the one from the spec cannot.
  std::ofstream(file) << "rotated-b7\n";
  ASSERT_TRUE(admin->Command({"CONFIG", "SET", "requirepass", "rotated-b7"}).ok());
  ASSERT_TRUE(admin->Command({"CLIENT", "KILL", "TYPE", "normal"}).ok());
  EXPECT_TRUE(WaitFor(absl::Seconds(3), [&] { return from_file->Get("g").ok(); }))
      << from_file->Get("g").status();
  EXPECT_THAT(from_spec->Get("g").status(),
              StatusIs(absl::StatusCode::kUnavailable, "refuses the password"));
}

// Not a check: what a Get costs (printed for the record).
TEST_F(RedisStoreTest, GetCost) {
  CreateFitted("g");
  Deform(*b_, "g");
  constexpr int kGets = 500;
  absl::Time start = absl::Now();
  for (int i = 0; i < kGets; ++i) ASSERT_TRUE(a_->Get("g").ok());
  const double unchanged = absl::ToDoubleMicroseconds(absl::Now() - start) / kGets;
  start = absl::Now();
  for (int i = 0; i < 50; ++i) {
    Deform(*b_, "g");
    ASSERT_TRUE(a_->Get("g").ok());
  }
  const double deform_and_get = absl::ToDoubleMicroseconds(absl::Now() - start) / 50;
  start = absl::Now();
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(Open()->Get("g").ok());
  const double cold = absl::ToDoubleMicroseconds(absl::Now() - start) / 10;
  // A source of 32 MiB (2048 x 1024 x 2 doubles, 32 chunks): written once, read cold.
  start = absl::Now();
  ASSERT_TRUE(a_->Create(MakeGrid("large", SmallGrid(2048, 1024))).ok());
  const double create_large = absl::ToDoubleMilliseconds(absl::Now() - start);
  start = absl::Now();
  ASSERT_TRUE(b_->Get("large").ok());
  const double get_large = absl::ToDoubleMilliseconds(absl::Now() - start);
  std::printf(
      "Get, nothing new: %.0f us; AddRevision on b + Get on a: %.0f us; open a store + "
      "cold Get: %.0f us; 32 MiB source: Create %.0f ms, cold Get %.0f ms\n",
      unchanged, deform_and_get, cold, create_large, get_large);
}

}  // namespace
}  // namespace splinegrid::testing
