// Eight client threads mixing import, fit, fair, deform, watch, evaluate, wall curvature, list
// and delete on shared and on each other's grids. Every answer must be OK or an expected race
// outcome (NOT_FOUND when another thread deleted the grid, FAILED_PRECONDITION when it is not
// fitted yet or a deformation folds, ABORTED when another writer stored a revision first,
// CANCELLED for the watch the thread cancels itself); the shared grid must end exactly as it
// began. Runs clean under ThreadSanitizer (.ci/tsan).
#include <chrono>
#include <random>
#include <thread>

#include "absl/strings/str_cat.h"
#include "core/io/plot3d.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::testing {
namespace {

constexpr int kThreads = 8;
constexpr int kRounds = 25;

bool Expected(const absl::Status& status) {
  return status.ok() || status.code() == absl::StatusCode::kNotFound ||
         status.code() == absl::StatusCode::kFailedPrecondition ||
         status.code() == absl::StatusCode::kAborted;
}

// Watches `name` from its first revision, reads one message (there is one, or the grid is
// gone and the stream ends) and cancels.
absl::Status WatchBriefly(client::Client& client, const std::string& name) {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
  v1::WatchGridRequest request;
  request.set_name("grids/" + name);
  auto reader = client.stub().WatchGrid(&context, request);
  v1::WatchGridResponse message;
  reader->Read(&message);
  context.TryCancel();
  while (reader->Read(&message)) {
  }
  const absl::Status status = client::FromGrpc(reader->Finish());
  return status.code() == absl::StatusCode::kCancelled ? absl::OkStatus() : status;
}

TEST_F(ServiceTest, ConcurrentClientsMixingEveryMethod) {
  ImportShared("surfaces/m6_small.fmt", "shared");
  FitCounts("shared", 10, 10);
  const std::string before =
      client_->Get("shared", 0, v1::GRID_VIEW_FULL).value().SerializeAsString();
  const MultiBlockGrid sphere = ReadPlot3dFile(SharedDataPath("surfaces/even_sphere.fmt")).value();

  std::atomic<int> unexpected{0}, evaluated{0};
  auto worker = [&](int t) {
    std::mt19937 rng(t);
    for (int round = 0; round < kRounds; ++round) {
      const std::string mine = absl::StrCat("t", t, "-r", round);
      const std::string theirs = absl::StrCat("t", (t + 1) % kThreads, "-r", round);
      auto check = [&](const absl::Status& status, const char* what) {
        if (!Expected(status)) {
          ++unexpected;
          ADD_FAILURE() << what << ": " << status;
        }
      };
      check(client_->ImportPoints(sphere, mine, "").status(), "import");
      v1::FitSpec spec;
      if (rng() % 2) {
        spec.set_tolerance(1e-2);
      } else {
        spec.mutable_control_counts()->set_i(4 + rng() % 2);
        spec.mutable_control_counts()->set_j(4);
      }
      const absl::Status fitted = client_->Fit(mine, spec).status();
      check(fitted, "fit");
      v1::DeformGridRequest deform;
      deform.set_name(mine);
      deform.set_base_revision(1);
      deform.set_step(round);
      v1::FaceRange* surface = deform.mutable_boundary()->add_ranges();
      const int moved = static_cast<int>(rng() % sphere.blocks.size());
      surface->set_block(moved);
      surface->set_face(v1::BLOCK_FACE_K_MIN);  // the whole surface block
      surface->mutable_end()->set_i(sphere.blocks[moved].extent(0) - 1);
      surface->mutable_end()->set_j(sphere.blocks[moved].extent(1) - 1);
      deform.set_decay_radius(0.5);
      for (double d : {1e-3, 0.0, 0.0}) deform.mutable_rigid()->add_translation(d);
      check(client_->Deform(deform).status(), "deform");
      if (fitted.ok()) check(WatchBriefly(*client_, mine), "watch");
      v1::EvaluateGridRequest eval;
      eval.set_name(rng() % 2 ? "shared" : theirs);
      eval.set_refinement_level(1);
      absl::StatusOr<client::EvaluatedGrid> result = client_->Evaluate(eval);
      check(result.status(), "evaluate");
      if (result.ok()) ++evaluated;
      v1::EvaluatePointsRequest points;
      points.set_name("shared");
      points.add_blocks(rng() % 9);
      for (int x = 0; x < 3; ++x)
        points.add_parameters(std::uniform_real_distribution<>(0, 1)(rng));
      check(client_->EvaluatePoints(points).status(), "evaluate points");
      v1::Fairing fairing;
      fairing.set_mode(v1::FAIRING_MODE_WEIGHT);
      fairing.set_weight(1e-4);
      check(client_->Fair(theirs, 0, &fairing).status(), "fair");
      check(client_->WallCurvature("shared", 0, 0, {static_cast<int>(rng() % 9)}).status(),
            "wall curvature");
      check(client_->List().status(), "list");
      check(client_->Get(theirs, 0, v1::GRID_VIEW_FULL).status(), "get");
      if (round % 3 == 2) check(client_->Delete(theirs), "delete theirs");
      if (round % 2 == 1) check(client_->Delete(mine), "delete mine");
    }
  };
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) threads.emplace_back(worker, t);
  for (std::thread& thread : threads) thread.join();

  EXPECT_EQ(unexpected.load(), 0);
  EXPECT_GT(evaluated.load(), kThreads * kRounds / 2);
  EXPECT_EQ(client_->Get("shared", 0, v1::GRID_VIEW_FULL).value().SerializeAsString(), before);
  // Every grid left is listed once and readable.
  const std::vector<v1::Grid> left = client_->List().value();
  for (const v1::Grid& grid : left) {
    EXPECT_TRUE(client_->Get(grid.name()).ok()) << grid.name();
  }
}

}  // namespace
}  // namespace splinegrid::testing
