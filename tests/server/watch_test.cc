// WatchGrid: the store's subscriptions (order, lag, deletion, closing), then the stream through
// the service: stored revisions then new ones in order, and how it ends (grid deleted, client
// cancelled, deadline, slow client, server shutdown, bad requests).
#include <atomic>
#include <chrono>
#include <thread>

#include "gmock/gmock.h"
#include "server/store/memory_store.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::testing {
namespace {

using server::GridStore;
using server::GridSubscription;
using server::MemoryStore;
using End = GridSubscription::End;

// ---- GridStore subscriptions ----

struct CountingWatcher : server::GridWatcher {
  void Wake() override { ++wakes; }
  std::atomic<int> wakes{0};
};

class StoreWatchTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto grid = std::make_shared<server::StoredGrid>();
    grid->id = "g";
    grid->source = std::make_shared<server::SourcePoints>();
    ASSERT_TRUE(store_.Create(grid).ok());
  }
  int64_t Publish(server::RevisionOrigin origin = server::RevisionOrigin::kDeform) {
    server::GridRevision revision;
    revision.origin = origin;
    return store_.AddRevision("g", std::move(revision)).value()->revisions.back()->number;
  }
  // Every queued revision number, then how the subscription stands.
  std::vector<int64_t> Drain(GridSubscription& subscription, End* end) {
    std::vector<int64_t> numbers;
    server::RevisionSummary revision;
    while (subscription.Next(&revision, end)) numbers.push_back(revision.number);
    return numbers;
  }

  MemoryStore store_{/*max_deform_revisions=*/2};
  std::shared_ptr<CountingWatcher> watcher_ = std::make_shared<CountingWatcher>();
};

TEST_F(StoreWatchTest, RevisionsInPublicationOrderThenTheDeletion) {
  Publish(server::RevisionOrigin::kFit);
  GridStore::Watch watch = store_.Subscribe("g", watcher_, 8).value();
  ASSERT_EQ(watch.snapshot->revisions.size(), 1u);  // what was stored before
  End end;
  for (int r = 0; r < 3; ++r) Publish();
  EXPECT_EQ(watcher_->wakes.load(), 3);
  // Retention dropped revision 2 from the grid, not from the watch.
  EXPECT_THAT(Drain(*watch.subscription, &end), ::testing::ElementsAre(2, 3, 4));
  EXPECT_EQ(end, End::kOpen);
  Publish();
  ASSERT_TRUE(store_.Delete("g").ok());
  EXPECT_EQ(watcher_->wakes.load(), 5);
  EXPECT_THAT(Drain(*watch.subscription, &end), ::testing::ElementsAre(5));
  EXPECT_EQ(end, End::kGridDeleted);
  // A grid made again under the same id is another grid: the old watch stays ended.
  auto again = std::make_shared<server::StoredGrid>();
  again->id = "g";
  ASSERT_TRUE(store_.Create(again).ok());
  Publish();
  EXPECT_TRUE(Drain(*watch.subscription, &end).empty());
  EXPECT_EQ(watcher_->wakes.load(), 5);
}

TEST_F(StoreWatchTest, AWatchThatLagsIsEndedAndForgotten) {
  GridStore::Watch watch = store_.Subscribe("g", watcher_, 4).value();
  for (int r = 0; r < 5; ++r) Publish();
  End end;
  EXPECT_TRUE(Drain(*watch.subscription, &end).empty());  // dropped, not delivered late
  EXPECT_EQ(end, End::kLagged);
  Publish();
  EXPECT_EQ(watcher_->wakes.load(), 5);  // no longer subscribed
}

TEST_F(StoreWatchTest, ClosingEndsEveryWatchAndRefusesNewOnes) {
  EXPECT_EQ(store_.Subscribe("nothing", watcher_, 4).status().code(), absl::StatusCode::kNotFound);
  GridStore::Watch watch = store_.Subscribe("g", watcher_, 4).value();
  GridStore::Watch other = store_.Subscribe("g", std::make_shared<CountingWatcher>(), 4).value();
  store_.Unsubscribe("g", other.subscription.get());
  Publish();
  store_.CloseSubscriptions();
  End end;
  EXPECT_TRUE(Drain(*watch.subscription, &end).empty());  // closing does not wait for the queue
  EXPECT_EQ(end, End::kClosed);
  EXPECT_TRUE(Drain(*other.subscription, &end).empty());
  EXPECT_EQ(end, End::kOpen);  // unsubscribed before: neither fed nor closed
  EXPECT_EQ(store_.Subscribe("g", watcher_, 4).status().code(), absl::StatusCode::kUnavailable);
}

TEST_F(StoreWatchTest, AWatcherThatIsGoneIsNotWoken) {
  GridStore::Watch watch = store_.Subscribe("g", watcher_, 4).value();
  const std::weak_ptr<CountingWatcher> gone = watcher_;
  watcher_.reset();  // the store holds it weakly: it goes now
  EXPECT_TRUE(gone.expired());
  Publish();
  End end;
  EXPECT_THAT(Drain(*watch.subscription, &end), ::testing::ElementsAre(1));
}

// ---- WatchGrid through the service ----

class WatchTest : public ServiceTest {
 protected:
  void SetUp() override {
    ServiceTest::SetUp();
    ImportAndFit();
  }
  // The 113 x 33 C-grid fitted to the default tolerances by kind: revision 1.
  void ImportAndFit() {
    ImportShared("grids/n0012_113-33.p2dfmt", "naca");
    v1::FitSpec spec;
    spec.mutable_boundary_tolerances();
    ASSERT_TRUE(client_->Fit("naca", spec).ok());
  }
  // Stores a deformed revision of `step` (a small pitch of the wall).
  int64_t DeformStep(int step) {
    v1::DeformGridRequest request;
    request.set_name("naca");
    request.set_reference_revision(1);
    request.set_step(step);
    request.set_time(0.5 * step);
    request.mutable_rigid()->add_center(0.25);
    request.mutable_rigid()->add_center(0.0);
    request.mutable_rigid()->set_angle_degrees(0.5 * step);
    absl::StatusOr<v1::DeformGridResponse> response = client_->Deform(request);
    EXPECT_TRUE(response.ok()) << response.status();
    return response.ok() ? response->revision() : 0;
  }
  struct Watch {
    grpc::ClientContext context;
    std::unique_ptr<grpc::ClientReader<v1::WatchGridResponse>> reader;
  };
  // Opens a watch of `name`; with `wait`, returns once the server's subscription is in place.
  std::unique_ptr<Watch> Open(const std::string& name, int64_t after, bool wait = true) {
    auto watch = std::make_unique<Watch>();
    watch->context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    v1::WatchGridRequest request;
    request.set_name(name);
    request.set_after_revision(after);
    watch->reader = client_->stub().WatchGrid(&watch->context, request);
    if (wait) watch->reader->WaitForInitialMetadata();
    return watch;
  }
  // The revision numbers of the next `count` messages (fewer if the stream ends).
  std::vector<int64_t> Read(Watch& watch, int count) {
    std::vector<int64_t> numbers;
    v1::WatchGridResponse message;
    while (static_cast<int>(numbers.size()) < count && watch.reader->Read(&message)) {
      EXPECT_EQ(message.name(), "grids/naca");
      numbers.push_back(message.revision().revision());
      last_ = message.revision();
    }
    return numbers;
  }
  // Reads to the end and returns the status.
  absl::Status End(Watch& watch) {
    v1::WatchGridResponse message;
    while (watch.reader->Read(&message)) {
    }
    return client::FromGrpc(watch.reader->Finish());
  }
  v1::RevisionInfo last_;
};

TEST_F(WatchTest, StoredRevisionsThenNewOnesInOrderUntilDeleted) {
  EXPECT_EQ(DeformStep(1), 2);
  std::unique_ptr<Watch> all = Open("grids/naca", 0);
  std::unique_ptr<Watch> after = Open("grids/naca", 1);
  std::unique_ptr<Watch> fresh = Open("grids/naca", -1);
  EXPECT_THAT(Read(*all, 2), ::testing::ElementsAre(1, 2));
  EXPECT_EQ(last_.origin(), v1::REVISION_ORIGIN_DEFORM);
  EXPECT_EQ(last_.parent_revision(), 1);
  EXPECT_EQ(last_.step(), 1);
  EXPECT_DOUBLE_EQ(last_.time(), 0.5);
  EXPECT_GT(last_.create_time().seconds(), 0);
  EXPECT_THAT(Read(*after, 1), ::testing::ElementsAre(2));
  std::thread writer([&] {
    for (int step = 2; step <= 6; ++step) DeformStep(step);
  });
  for (Watch* watch : {all.get(), after.get(), fresh.get()}) {
    EXPECT_THAT(Read(*watch, 5), ::testing::ElementsAre(3, 4, 5, 6, 7));
    EXPECT_EQ(last_.step(), 6);
  }
  writer.join();
  ASSERT_TRUE(client_->Delete("naca").ok());
  for (Watch* watch : {all.get(), after.get(), fresh.get()}) EXPECT_TRUE(End(*watch).ok());
}

TEST_F(WatchTest, RevisionsStoredBeforeTheDeletionAreSentFirst) {
  std::unique_ptr<Watch> watch = Open("grids/naca", -1);
  DeformStep(1);
  DeformStep(2);
  ASSERT_TRUE(client_->Delete("naca").ok());
  EXPECT_THAT(Read(*watch, 10), ::testing::ElementsAre(2, 3));
  EXPECT_TRUE(End(*watch).ok());
}

TEST_F(WatchTest, ClientCancelAndDeadlineEndTheWatch) {
  std::unique_ptr<Watch> watch = Open("grids/naca", 0);
  EXPECT_THAT(Read(*watch, 1), ::testing::ElementsAre(1));
  watch->context.TryCancel();
  EXPECT_EQ(End(*watch).code(), absl::StatusCode::kCancelled);
  auto expiring = std::make_unique<Watch>();
  expiring->context.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(200));
  v1::WatchGridRequest request;
  request.set_name("grids/naca");
  expiring->reader = client_->stub().WatchGrid(&expiring->context, request);
  EXPECT_THAT(Read(*expiring, 5), ::testing::ElementsAre(1));
  EXPECT_EQ(End(*expiring).code(), absl::StatusCode::kDeadlineExceeded);
  // The server goes on publishing to the watches left.
  std::unique_ptr<Watch> next = Open("grids/naca", 1);
  DeformStep(1);
  EXPECT_THAT(Read(*next, 1), ::testing::ElementsAre(2));
}

TEST_F(WatchTest, ASlowClientIsEndedWithResourceExhausted) {
  options_.max_watch_lag = 2;
  StartServer();
  ImportAndFit();
  std::unique_ptr<Watch> watch = Open("grids/naca", 1);
  // Not reading: one revision is in flight to the client, two wait, the next is one too many.
  for (int step = 1; step <= 5; ++step) DeformStep(step);
  const absl::Status status = End(*watch);
  EXPECT_EQ(status.code(), absl::StatusCode::kResourceExhausted) << status;
  EXPECT_THAT(status.message(), ::testing::HasSubstr("more than 2 revisions behind"));
}

TEST_F(WatchTest, AWatchThatWouldMissRevisionsRetentionDroppedIsRefused) {
  options_.max_deform_revisions = 3;
  StartServer();
  ImportAndFit();
  for (int step = 1; step <= 6; ++step) DeformStep(step);  // keeps 1, 5, 6, 7
  const absl::Status gap = End(*Open("grids/naca", 1, false));
  EXPECT_EQ(gap.code(), absl::StatusCode::kOutOfRange) << gap;
  EXPECT_THAT(gap.message(), ::testing::HasSubstr("after_revision = 1: grids/naca no longer "
                                                  "keeps 3 of the revisions after it"));
  EXPECT_THAT(gap.message(), ::testing::HasSubstr("watch with after_revision = 4"));
  // What the message proposes, and every kept revision, are served.
  std::unique_ptr<Watch> rest = Open("grids/naca", 4);
  EXPECT_THAT(Read(*rest, 3), ::testing::ElementsAre(5, 6, 7));
  std::unique_ptr<Watch> all = Open("grids/naca", 0);
  EXPECT_THAT(Read(*all, 4), ::testing::ElementsAre(1, 5, 6, 7));
  // A gap between kept revisions counts too: 5 is dropped, 6 and 7 are still kept.
  DeformStep(7);
  const absl::Status middle = End(*Open("grids/naca", 4, false));
  EXPECT_EQ(middle.code(), absl::StatusCode::kOutOfRange) << middle;
  EXPECT_THAT(middle.message(), ::testing::HasSubstr("no longer keeps 1 of"));
  EXPECT_THAT(middle.message(), ::testing::HasSubstr("after_revision = 5 for"));
  std::unique_ptr<Watch> latest = Open("grids/naca", 7);
  EXPECT_THAT(Read(*latest, 1), ::testing::ElementsAre(8));
}

TEST_F(WatchTest, ServerShutdownEndsWatchesAtOnce) {
  options_.shutdown_grace = absl::Seconds(30);
  StartServer();
  ImportShared("grids/n0012_113-33.p2dfmt", "naca");
  std::unique_ptr<Watch> watch = Open("grids/naca", 0);
  const auto start = std::chrono::steady_clock::now();
  server_->Shutdown();
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
  EXPECT_EQ(End(*watch).code(), absl::StatusCode::kUnavailable);
}

TEST_F(WatchTest, BadRequestsAreRefused) {
  EXPECT_EQ(End(*Open("grids/nothing", 0, false)).code(), absl::StatusCode::kNotFound);
  const absl::Status below = End(*Open("grids/naca", -2, false));
  EXPECT_EQ(below.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(below.message(), ::testing::HasSubstr("after_revision = -2"));
  for (const char* name : {"naca", "grids/Naca", "grids/"}) {
    const absl::Status status = End(*Open(name, 0, false));
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << name;
    EXPECT_THAT(status.message(), ::testing::HasSubstr("name = ")) << name;
  }
}

}  // namespace
}  // namespace splinegrid::testing
