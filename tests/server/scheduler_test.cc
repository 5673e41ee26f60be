// The scheduler (server/scheduler.h): cheap work first, long work round-robin across principals
// and never on every worker, the queue limits named in their refusals, and Stop draining; the
// per-principal stream limit (server/stream_limits.h), alone and through WatchGrid.
#include "server/scheduler.h"

#include <atomic>
#include <chrono>
#include <future>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/stream_limits.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::testing {
namespace {

using server::Admission;
using server::Scheduler;
using server::SchedulerOptions;
using server::StreamLimits;
using server::StreamSlot;
using server::WorkKind;
using ::testing::ElementsAre;

// Holds a worker busy until Open(); Wait() returns once the worker has taken it.
class Gate {
 public:
  std::function<void()> Task() {
    return [this] {
      // The future first: once started_ is set the test may open the gate and destroy it.
      std::future<void> opened = opened_.get_future();
      started_.set_value();
      opened.wait();
    };
  }
  void WaitStarted() { started_.get_future().wait(); }
  void Open() { opened_.set_value(); }

 private:
  std::promise<void> started_;
  std::promise<void> opened_;
};

// Records the order in which tasks ran.
class Journal {
 public:
  std::function<void()> Entry(std::string name) {
    return [this, name = std::move(name)] {
      std::lock_guard<std::mutex> lock(mu_);
      order_.push_back(name);
    };
  }
  std::vector<std::string> order() {
    std::lock_guard<std::mutex> lock(mu_);
    return order_;
  }

 private:
  std::mutex mu_;
  std::vector<std::string> order_;
};

SchedulerOptions OneThread() {
  SchedulerOptions options;
  options.threads = 1;
  options.long_worker_nice = 0;
  return options;
}

TEST(SchedulerTest, CheapTasksGoBeforeLongOnesEachInSubmissionOrder) {
  Journal journal;
  Gate gate;
  {
    Scheduler scheduler(OneThread());
    ASSERT_TRUE(scheduler.TrySubmit("a", WorkKind::kLong, gate.Task()).ok());
    gate.WaitStarted();
    ASSERT_TRUE(scheduler.TrySubmit("a", WorkKind::kLong, journal.Entry("long1")).ok());
    ASSERT_TRUE(scheduler.TrySubmit("b", WorkKind::kCheap, journal.Entry("cheap1")).ok());
    ASSERT_TRUE(scheduler.TrySubmit("a", WorkKind::kLong, journal.Entry("long2")).ok());
    ASSERT_TRUE(scheduler.TrySubmit("a", WorkKind::kCheap, journal.Entry("cheap2")).ok());
    gate.Open();
  }  // Stop() drains
  EXPECT_THAT(journal.order(), ElementsAre("cheap1", "cheap2", "long1", "long2"));
}

TEST(SchedulerTest, LongTasksTakeTurnsAcrossPrincipals) {
  Journal journal;
  Gate gate;
  {
    Scheduler scheduler(OneThread());
    ASSERT_TRUE(scheduler.TrySubmit("gate", WorkKind::kLong, gate.Task()).ok());
    gate.WaitStarted();
    for (const char* name : {"a1", "a2", "a3", "a4"}) {
      ASSERT_TRUE(scheduler.TrySubmit("alice", WorkKind::kLong, journal.Entry(name)).ok());
    }
    ASSERT_TRUE(scheduler.TrySubmit("bob", WorkKind::kLong, journal.Entry("b1")).ok());
    ASSERT_TRUE(scheduler.TrySubmit("bob", WorkKind::kLong, journal.Entry("b2")).ok());
    ASSERT_TRUE(scheduler.TrySubmit("carol", WorkKind::kLong, journal.Entry("c1")).ok());
    gate.Open();
  }
  EXPECT_THAT(journal.order(), ElementsAre("a1", "b1", "c1", "a2", "b2", "a3", "a4"));
}

TEST(SchedulerTest, APrincipalThatComesBackJoinsTheEndOfTheRing) {
  Journal journal;
  Gate gate;
  {
    Scheduler scheduler(OneThread());
    ASSERT_TRUE(scheduler.TrySubmit("gate", WorkKind::kLong, gate.Task()).ok());
    gate.WaitStarted();
    ASSERT_TRUE(scheduler.TrySubmit("alice", WorkKind::kLong, journal.Entry("a1")).ok());
    ASSERT_TRUE(scheduler.TrySubmit("alice", WorkKind::kLong, journal.Entry("a2")).ok());
    // The gate's principal has nothing queued any more: a new task puts it at the end.
    ASSERT_TRUE(scheduler.TrySubmit("gate", WorkKind::kLong, journal.Entry("g1")).ok());
    ASSERT_TRUE(scheduler.TrySubmit("bob", WorkKind::kLong, journal.Entry("b1")).ok());
    gate.Open();
  }
  EXPECT_THAT(journal.order(), ElementsAre("a1", "g1", "b1", "a2"));
}

TEST(SchedulerTest, LongWorkLeavesAWorkerForCheapWork) {
  SchedulerOptions options;
  options.threads = 2;
  Scheduler scheduler(options);
  EXPECT_EQ(scheduler.max_running_long(), 1);
  Gate first, second;
  std::atomic<bool> second_started{false};
  ASSERT_TRUE(scheduler.TrySubmit("a", WorkKind::kLong, first.Task()).ok());
  first.WaitStarted();
  ASSERT_TRUE(scheduler
                  .TrySubmit("b", WorkKind::kLong,
                             [&] {
                               second_started = true;
                               second.Task()();
                             })
                  .ok());
  // Both long tasks wait for the one long worker; the other worker runs cheap tasks meanwhile.
  for (int i = 0; i < 20; ++i) {
    std::promise<void> ran;
    ASSERT_TRUE(scheduler.TrySubmit("c", WorkKind::kCheap, [&] { ran.set_value(); }).ok());
    ASSERT_EQ(ran.get_future().wait_for(std::chrono::seconds(10)), std::future_status::ready);
  }
  EXPECT_FALSE(second_started.load());
  first.Open();
  second.WaitStarted();
  EXPECT_TRUE(second_started.load());
  second.Open();
}

// Slices (the chunks of a large evaluation) run on the worker kept for cheap work while a long
// task holds the long one, after the cheap tasks waiting, taking turns across principals.
TEST(SchedulerTest, SlicesGoOnWhileLongWorkHoldsTheLongWorkers) {
  Journal journal;
  Gate fit, cheap_gate;
  {
    SchedulerOptions options;
    options.threads = 2;
    options.long_worker_nice = 0;
    Scheduler scheduler(options);
    ASSERT_TRUE(scheduler.TrySubmit("fitter", WorkKind::kLong, fit.Task()).ok());
    fit.WaitStarted();
    ASSERT_TRUE(scheduler.TrySubmit("fitter", WorkKind::kLong, journal.Entry("fit2")).ok());
    // Hold the other worker too while the queue is filled, so that the order is the policy's.
    ASSERT_TRUE(scheduler.TrySubmit("x", WorkKind::kCheap, cheap_gate.Task()).ok());
    cheap_gate.WaitStarted();
    for (const char* name : {"a1", "a2", "a3"}) {
      ASSERT_TRUE(
          scheduler
              .TrySubmit("alice", WorkKind::kSlice, journal.Entry(name), Admission::kContinuation)
              .ok());
    }
    ASSERT_TRUE(
        scheduler.TrySubmit("bob", WorkKind::kSlice, journal.Entry("b1"), Admission::kContinuation)
            .ok());
    ASSERT_TRUE(scheduler.TrySubmit("carol", WorkKind::kCheap, journal.Entry("cheap")).ok());
    cheap_gate.Open();
    // Every slice runs while the fit still holds the long worker.
    for (int i = 0; i < 1000 && journal.order().size() < 5; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    EXPECT_THAT(journal.order(), ElementsAre("cheap", "a1", "b1", "a2", "a3"));
    fit.Open();
  }
  EXPECT_THAT(journal.order(), ElementsAre("cheap", "a1", "b1", "a2", "a3", "fit2"));
}

TEST(SchedulerTest, RunningLongTasksDefaultToAllButOneWorker) {
  for (const auto& [threads, requested, expected] : std::vector<std::tuple<int, int, int>>{
           {1, 0, 1}, {2, 0, 1}, {4, 0, 3}, {4, 2, 2}, {2, 5, 2}}) {
    SchedulerOptions options;
    options.threads = threads;
    options.max_running_long = requested;
    options.long_worker_nice = 0;
    Scheduler scheduler(options);
    EXPECT_EQ(scheduler.max_running_long(), expected) << threads << " threads, " << requested;
    EXPECT_EQ(scheduler.num_threads(), threads);
  }
}

TEST(SchedulerTest, QueuedLongCallsOfAPrincipalAreLimitedByName) {
  SchedulerOptions options = OneThread();
  options.max_queued_long_calls_per_principal = 2;
  Gate gate;
  Scheduler scheduler(options);
  ASSERT_TRUE(scheduler.TrySubmit("gate", WorkKind::kLong, gate.Task()).ok());
  gate.WaitStarted();
  std::atomic<int> ran{0};
  auto count = [&] { ++ran; };
  ASSERT_TRUE(scheduler.TrySubmit("alice", WorkKind::kLong, count).ok());
  ASSERT_TRUE(scheduler.TrySubmit("alice", WorkKind::kLong, count).ok());
  EXPECT_THAT(
      scheduler.TrySubmit("alice", WorkKind::kLong, count),
      StatusIs(absl::StatusCode::kResourceExhausted, "max_queued_long_calls_per_principal = 2"));
  // Other principals, cheap work and continuations of admitted calls are not held back.
  EXPECT_TRUE(scheduler.TrySubmit("bob", WorkKind::kLong, count).ok());
  EXPECT_TRUE(scheduler.TrySubmit("alice", WorkKind::kCheap, count).ok());
  EXPECT_TRUE(scheduler.TrySubmit("alice", WorkKind::kLong, count, Admission::kContinuation).ok());
  gate.Open();
  for (int i = 0; i < 500 && ran.load() < 5; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(ran.load(), 5);
  // Once they have run, alice may queue again.
  EXPECT_TRUE(scheduler.TrySubmit("alice", WorkKind::kLong, count).ok());
}

TEST(SchedulerTest, WaitingTasksAreLimitedByName) {
  SchedulerOptions options = OneThread();
  options.max_queued_tasks = 2;
  Gate gate;
  Scheduler scheduler(options);
  ASSERT_TRUE(scheduler.TrySubmit("gate", WorkKind::kLong, gate.Task()).ok());
  gate.WaitStarted();  // running, not waiting
  EXPECT_TRUE(scheduler.TrySubmit("a", WorkKind::kCheap, [] {}).ok());
  EXPECT_TRUE(scheduler.TrySubmit("b", WorkKind::kLong, [] {}).ok());
  EXPECT_THAT(scheduler.TrySubmit("c", WorkKind::kCheap, [] {}),
              StatusIs(absl::StatusCode::kResourceExhausted, "max_queued_tasks = 2"));
  EXPECT_THAT(scheduler.TrySubmit(
                  "c", WorkKind::kLong, [] {}, Admission::kContinuation),
              StatusIs(absl::StatusCode::kResourceExhausted, "max_queued_tasks = 2"));
  gate.Open();
}

TEST(SchedulerTest, StopRunsEveryQueuedTaskThenRefuses) {
  SchedulerOptions options;
  options.threads = 2;
  Scheduler scheduler(options);
  Gate gate;
  ASSERT_TRUE(scheduler.TrySubmit("gate", WorkKind::kLong, gate.Task()).ok());
  gate.WaitStarted();
  std::atomic<int> ran{0};
  for (int i = 0; i < 6; ++i) {
    ASSERT_TRUE(scheduler
                    .TrySubmit(i % 2 ? "a" : "b", i % 3 ? WorkKind::kLong : WorkKind::kCheap,
                               [&] { ++ran; })
                    .ok());
  }
  std::thread stopper([&] { scheduler.Stop(); });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  gate.Open();
  stopper.join();
  EXPECT_EQ(ran.load(), 6);
  EXPECT_THAT(scheduler.TrySubmit("a", WorkKind::kCheap, [] {}),
              StatusIs(absl::StatusCode::kUnavailable, "shutting down"));
  scheduler.Stop();  // idempotent
}

TEST(SchedulerTest, ManyThreadsSubmittingRunEveryTaskOnce) {
  SchedulerOptions options;
  options.threads = 3;
  options.max_queued_long_calls_per_principal = 1 << 20;
  std::atomic<int> ran{0};
  {
    Scheduler scheduler(options);
    std::vector<std::thread> submitters;
    for (int t = 0; t < 4; ++t) {
      submitters.emplace_back([&, t] {
        for (int i = 0; i < 500; ++i) {
          const WorkKind kind = (i + t) % 3 ? WorkKind::kCheap : WorkKind::kLong;
          EXPECT_TRUE(scheduler.TrySubmit(absl::StrCat("p", i % 5), kind, [&] { ++ran; }).ok());
        }
      });
    }
    for (std::thread& s : submitters) s.join();
  }
  EXPECT_EQ(ran.load(), 2000);
}

// ---- StreamLimits ----

TEST(StreamLimitsTest, OpenStreamsPerPrincipalAreLimitedByName) {
  StreamLimits limits(2);
  std::vector<StreamSlot> alice;
  for (int i = 0; i < 2; ++i) alice.push_back(limits.Open("alice").value());
  EXPECT_THAT(limits.Open("alice").status(),
              StatusIs(absl::StatusCode::kResourceExhausted, "max_streams_per_principal = 2"));
  EXPECT_EQ(limits.open("alice"), 2);
  absl::StatusOr<StreamSlot> bob = limits.Open("bob");
  EXPECT_TRUE(bob.ok());
  EXPECT_EQ(limits.open("bob"), 1);
  alice.pop_back();  // destroyed: released
  EXPECT_EQ(limits.open("alice"), 1);
  StreamSlot moved = std::move(alice.back());
  alice.clear();  // the moved-from slot holds nothing
  EXPECT_EQ(limits.open("alice"), 1);
  moved.Release();
  moved.Release();
  EXPECT_EQ(limits.open("alice"), 0);
  EXPECT_TRUE(limits.Open("alice").ok());
}

// ---- Through the service ----

class StreamLimitServiceTest : public ServiceTest {
 protected:
  void SetUp() override {
    options_.max_streams_per_principal = 2;
    StartServer();
  }
};

TEST_F(StreamLimitServiceTest, WatchesBeyondTheLimitAreRefusedUntilOneEnds) {
  ImportShared("grids/n0012_113-33.p2dfmt", "naca");
  FitCounts("naca", 24, 12);
  struct Watch {
    grpc::ClientContext context;
    std::unique_ptr<grpc::ClientReader<v1::WatchGridResponse>> reader;
  };
  auto open = [&] {
    auto watch = std::make_unique<Watch>();
    watch->context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    v1::WatchGridRequest request;
    request.set_name("grids/naca");
    request.set_after_revision(-1);
    watch->reader = client_->stub().WatchGrid(&watch->context, request);
    watch->reader->WaitForInitialMetadata();
    return watch;
  };
  // Every in-process call has the same peer, hence the same principal (no tokens).
  v1::EvaluateGridRequest evaluate;
  evaluate.set_name("naca");
  evaluate.set_refinement_level(0);
  auto first = open();
  auto second = open();
  auto third = open();
  v1::WatchGridResponse message;
  EXPECT_FALSE(third->reader->Read(&message));
  EXPECT_THAT(client::FromGrpc(third->reader->Finish()),
              StatusIs(absl::StatusCode::kResourceExhausted, "max_streams_per_principal = 2"));
  // Other streaming calls count too.
  EXPECT_THAT(client_->Evaluate(evaluate).status(),
              StatusIs(absl::StatusCode::kResourceExhausted, "max_streams_per_principal = 2"));
  first->context.TryCancel();
  EXPECT_FALSE(first->reader->Read(&message));
  first->reader->Finish();
  // A client's cancellation reaches the server a moment later; then the slot is free.
  absl::Status evaluated;
  for (int i = 0; i < 100; ++i) {
    evaluated = client_->Evaluate(evaluate).status();
    if (evaluated.ok()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_TRUE(evaluated.ok()) << evaluated;
  second->context.TryCancel();
}

// Without tokens the principal is the peer: in-process calls share one, loopback connections
// each have their own, so one client at its limit leaves another's streams alone.
TEST(StreamLimitTcpTest, EachConnectionIsAPrincipalOfItsOwn) {
  server::ServerOptions options;
  options.address = "127.0.0.1:0";
  options.log_calls = false;
  options.worker_threads = 2;
  options.max_streams_per_principal = 1;
  std::unique_ptr<server::Server> server = server::Server::Start(options).value();
  auto connect = [&] {
    grpc::ChannelArguments args;
    args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);  // a connection of its own
    return std::make_unique<client::Client>(grpc::CreateCustomChannel(
        absl::StrCat("127.0.0.1:", server->port()), grpc::InsecureChannelCredentials(), args));
  };
  auto alice = connect();
  auto bob = connect();
  const std::string bytes = ReadFileToString(SharedDataPath("grids/n0012_113-33.p2dfmt")).value();
  ASSERT_TRUE(alice->ImportPlot3d(bytes, "naca", "naca", false).ok());
  auto open = [](client::Client& client, grpc::ClientContext* context) {
    context->set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    v1::WatchGridRequest request;
    request.set_name("grids/naca");
    request.set_after_revision(-1);
    auto reader = client.stub().WatchGrid(context, request);
    reader->WaitForInitialMetadata();
    return reader;
  };
  grpc::ClientContext alice_context, alice_again_context, bob_context;
  auto alice_watch = open(*alice, &alice_context);
  auto alice_again = open(*alice, &alice_again_context);
  v1::WatchGridResponse message;
  EXPECT_FALSE(alice_again->Read(&message));
  EXPECT_THAT(client::FromGrpc(alice_again->Finish()),
              StatusIs(absl::StatusCode::kResourceExhausted, "max_streams_per_principal = 1"));
  auto bob_watch = open(*bob, &bob_context);
  // Bob's watch is open: a fit of the grid reaches it.
  v1::FitSpec spec;
  spec.set_allow_folds(true);  // these counts fold the C-grid; the watch is tested
  spec.mutable_control_counts()->set_i(24);
  spec.mutable_control_counts()->set_j(12);
  ASSERT_TRUE(bob->Fit("naca", spec).ok());
  EXPECT_TRUE(bob_watch->Read(&message));
  alice_context.TryCancel();
  bob_context.TryCancel();
  while (alice_watch->Read(&message)) {
  }
  while (bob_watch->Read(&message)) {
  }
  alice_watch->Finish();
  bob_watch->Finish();
}

TEST(SchedulingOptionsTest, OutOfRangeLimitsAreRefusedAtStart) {
  for (auto change : std::vector<std::function<void(server::ServerOptions&)>>{
           [](server::ServerOptions& o) { o.max_streams_per_principal = 0; },
           [](server::ServerOptions& o) { o.max_queued_long_calls_per_principal = 0; },
           [](server::ServerOptions& o) { o.max_running_long_tasks = -1; },
           [](server::ServerOptions& o) { o.max_running_long_tasks = 3; }}) {
    server::ServerOptions options;
    options.address = "";
    options.worker_threads = 2;
    change(options);
    EXPECT_THAT(server::Server::Start(options).status(),
                StatusIs(absl::StatusCode::kInvalidArgument, "scheduling options out of range"));
  }
}

}  // namespace
}  // namespace splinegrid::testing
