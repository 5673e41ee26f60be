// The operations layer (server/ops) on its own: no gRPC, no protobuf; a real MemoryStore, budget
// and deformer cache. Fit, fair and deform publish revisions; a deform's deformer is kept by its
// reference and options; stale bases, folding motions and bad requests change nothing; points
// are evaluated on the revision asked for, and bad batches are refused naming the field.
#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "core/bspline/evaluation.h"
#include "core/grid/connectivity.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/ops/deform.h"
#include "server/ops/evaluate_points.h"
#include "server/ops/fit.h"
#include "server/ops/wall_curvature.h"
#include "tests/core/synthetic_grids.h"
#include "tests/server/ops_fixture.h"

namespace splinegrid::server {
namespace {

using ::testing::HasSubstr;

class OpsTest : public OpsFixture {
 protected:
  void SetUp() override { AddNaca("naca", 0); }

  int64_t Latest() { return store_.Get("naca").value()->revisions.back()->number; }

  // A rigid pitch of `degrees` about the quarter chord, relative to revision 1.
  ops::DeformRequest Pitch(double degrees, int64_t base = 0) {
    ops::DeformRequest request;
    request.grid_id = "naca";
    request.base_revision = base;
    request.reference_revision = 1;
    RigidMotion pitch;
    pitch.center = {0.25, 0.0, 0.0};
    pitch.angle = degrees * std::numbers::pi / 180.0;
    request.motion = pitch;
    request.time = 0.5;
    request.step = 7;
    return request;
  }
};

// A first layer to hold on a grid without walls is refused naming the request's field (the
// kernel names GridFitOptions'): "spec." for FitGrid, the refaired revision's spec for FairGrid,
// which cannot change that spec and says how to get past it. Such a revision can be in a store
// from before the refusal existed (here added as an archive would add it).
TEST_F(OpsTest, AFirstLayerWithoutWallsIsRefusedNamingTheRequestField) {
  ops::ImportedSource source;
  source.imported.grid.blocks.push_back(PlanarBlock(9, 9, [](int i, int j) {
    return std::array<double, 2>{0.1 * i, 0.1 * j};
  }));
  source.imported.format = "plot3d";
  ASSERT_TRUE(ops::StoreImported(ops_, {"square", "", ""}, std::move(source)).ok());
  GridFitOptions options;
  options.boundary_tolerances = BoundaryTolerances();
  options.boundary_tolerances->first_layer = 0.05;
  const auto refused = ops::Fit(ops_, "square", options, {});
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(refused.status().message(),
              HasSubstr("spec.boundary_tolerances.first_layer = 0.05 holds nothing"));
  EXPECT_TRUE(store_.Get("square").value()->revisions.empty());

  options.boundary_tolerances->first_layer = 0.0;
  const auto fit = ops::Fit(ops_, "square", options, {});
  ASSERT_TRUE(fit.ok()) << fit.status();
  GridRevision archived;
  archived.fit_options = (*fit)->fit_options;
  archived.fit_options.boundary_tolerances->first_layer = 0.05;
  archived.blocks = (*fit)->blocks;
  archived.kinds = (*fit)->kinds;
  archived.report = (*fit)->report;
  const std::string incarnation = store_.Get("square").value()->incarnation;
  ASSERT_TRUE(store_.AddRevision("square", std::move(archived), 0, incarnation).ok());
  const auto refair =
      ops::Fair(ops_, {"square", 2, FairingOptions{FairingMode::kToTolerance}, false}, {});
  EXPECT_EQ(refair.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(
      refair.status().message(),
      HasSubstr("revision 2 fit_spec.boundary_tolerances.first_layer = 0.05 holds nothing"));
  EXPECT_THAT(refair.status().message(), HasSubstr("fit the grid again"));
  EXPECT_EQ(store_.Get("square").value()->revisions.size(), 2u);
}

TEST_F(OpsTest, FitFairAndDeformPublishRevisions) {
  GridFitOptions options;
  options.boundary_tolerances = BoundaryTolerances();
  const auto fit = ops::Fit(ops_, "naca", options, {});
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_EQ((*fit)->number, 1);
  EXPECT_EQ((*fit)->origin, RevisionOrigin::kFit);
  EXPECT_TRUE((*fit)->report.tolerance_met);

  const auto faired = ops::Fair(ops_, {"naca", 1, std::nullopt, false}, {});
  ASSERT_TRUE(faired.ok()) << faired.status();
  EXPECT_EQ((*faired)->origin, RevisionOrigin::kFair);
  EXPECT_EQ((*faired)->parent, 1);
  EXPECT_EQ((*faired)->fit_options.fairing.mode, FairingMode::kToTolerance);

  EXPECT_FALSE(ops::HasKeptDeformer(ops_, Pitch(1.0)));
  const auto deformed = ops::Deform(ops_, Pitch(1.0, /*base=*/2), {});
  ASSERT_TRUE(deformed.ok()) << deformed.status();
  EXPECT_EQ((*deformed)->number, 3);
  EXPECT_EQ((*deformed)->origin, RevisionOrigin::kDeform);
  EXPECT_EQ((*deformed)->parent, 1);
  EXPECT_EQ((*deformed)->step, 7);
  EXPECT_EQ((*deformed)->deform.check.folded, 0);
  // The deformer is kept for the same reference and options with the gate of its check level;
  // other options need their own, and so does another level's gate.
  EXPECT_TRUE(ops::HasKeptDeformer(ops_, Pitch(2.0)));
  ops::DeformRequest wider = Pitch(2.0);
  wider.options.decay_radius = 3.0;
  EXPECT_FALSE(ops::HasKeptDeformer(ops_, wider));
  ops::DeformRequest finer = Pitch(2.0);
  finer.check_level = 1;
  EXPECT_FALSE(ops::HasKeptDeformer(ops_, finer));
  ASSERT_TRUE(ops::Deform(ops_, finer, {}).ok());
  EXPECT_TRUE(ops::HasKeptDeformer(ops_, finer));
}

TEST_F(OpsTest, RefusedDeformsStoreNothing) {
  GridFitOptions options;
  options.boundary_tolerances = BoundaryTolerances();
  ASSERT_TRUE(ops::Fit(ops_, "naca", options, {}).ok());
  ASSERT_TRUE(ops::Deform(ops_, Pitch(1.0), {}).ok());
  const int64_t latest = Latest();

  EXPECT_EQ(ops::Deform(ops_, Pitch(2.0, /*base=*/1), {}).status().code(),
            absl::StatusCode::kAborted);  // stale base
  ops::DeformRequest bad_level = Pitch(2.0);
  bad_level.check_level = ops::kMaxDeformCheckLevel + 1;
  EXPECT_THAT(ops::Deform(ops_, bad_level, {}).status().message(), HasSubstr("check_level = 5"));
  ops::DeformRequest bad_time = Pitch(2.0);
  bad_time.time = std::nan("");
  EXPECT_THAT(ops::Deform(ops_, bad_time, {}).status().message(), HasSubstr("time = nan"));
  ops::DeformRequest bad_control = Pitch(0.0);
  bad_control.motion = std::vector<BlockControlDisplacements>{{0, {-1}, {0.0, 0.0}}};
  EXPECT_THAT(ops::Deform(ops_, bad_control, {}).status().message(),
              HasSubstr("controls.blocks[0].controls[0] = -1 does not carry the moved boundary"));
  // Everything a third of a chord away stays while the nose turns by 60 degrees: it tears.
  ops::DeformRequest tear = Pitch(60.0);
  tear.options.decay_radius = 0.3;
  const absl::Status folds = ops::Deform(ops_, tear, {}).status();
  EXPECT_EQ(folds.code(), absl::StatusCode::kFailedPrecondition) << folds;
  EXPECT_THAT(folds.message(), HasSubstr("nothing was stored"));
  EXPECT_EQ(Latest(), latest);
}

// A revision is made from the grid a call read: if that grid is deleted and another one created
// under its id while the call works, the revision is not the new grid's and is not stored there
// (it was: a fit of the old points became revision 1 of a grid imported by someone else).
TEST_F(OpsTest, ARevisionOfAGridDeletedAndCreatedAgainMeanwhileIsRefused) {
  bool replaced = false;
  const CancelCheck replace_the_grid = [&] {
    if (!replaced) {
      replaced = true;
      EXPECT_TRUE(store_.Delete("naca").ok());
      ops::ImportedSource source;
      source.imported.grid = Naca();
      source.imported.format = "plot3d";
      EXPECT_TRUE(ops::StoreImported(ops_, {"naca", "", "someone-else"}, std::move(source)).ok());
    }
    return false;
  };
  GridFitOptions options;
  options.boundary_tolerances = BoundaryTolerances();
  const absl::Status fit = ops::Fit(ops_, "naca", options, replace_the_grid).status();
  ASSERT_TRUE(replaced);
  EXPECT_EQ(fit.code(), absl::StatusCode::kAborted) << fit;
  EXPECT_THAT(fit.message(), HasSubstr("grids/naca was deleted and created again"));
  const std::shared_ptr<const StoredGrid> now = store_.Get("naca").value();
  EXPECT_EQ(now->owner, "someone-else");
  EXPECT_TRUE(now->revisions.empty());
}

// Every creation of an id has its own incarnation, which a grid loaded from a log (dir: store)
// keeps, and the store publishes a revision only on the incarnation it was made from.
TEST_F(OpsTest, EveryCreationOfAnIdHasItsOwnIncarnation) {
  const std::shared_ptr<const StoredGrid> first = store_.Get("naca").value();
  EXPECT_EQ(first->incarnation.size(), 16u);
  ASSERT_TRUE(store_.Delete("naca").ok());
  AddNaca("naca", 0);
  const std::shared_ptr<const StoredGrid> second = store_.Get("naca").value();
  EXPECT_NE(second->incarnation, first->incarnation);
  EXPECT_EQ(store_.AddRevision("naca", GridRevision{}, 0, first->incarnation).status().code(),
            absl::StatusCode::kAborted);
  EXPECT_TRUE(store_.AddRevision("naca", GridRevision{}, 0, second->incarnation).ok());

  // A grid loaded from a log keeps its creation's incarnation (a watch resumed across a
  // restart still watches it); one written before incarnations were kept gets a new one.
  auto older = std::make_shared<StoredGrid>(*second);
  older->id = "older";
  older->incarnation.clear();
  MemoryStore loaded(/*max_deform_revisions=*/4, nullptr, {second, older});
  EXPECT_EQ(loaded.Get("naca").value()->incarnation, second->incarnation);
  const std::string drawn = loaded.Get("older").value()->incarnation;
  EXPECT_EQ(drawn.size(), 16u);
  EXPECT_NE(drawn, second->incarnation);
}

// The memory store (and so the dir: store, the same class with a log) keeps what retention keeps
// of a grid created with many deformed revisions (an imported archive), as the Redis store does
// (RedisStoreTest).
TEST_F(OpsTest, ACreatedGridKeepsOnlyTheDeformedRevisionsRetentionKeeps) {
  auto grid = std::make_shared<StoredGrid>(*store_.Get("naca").value());
  grid->id = "imported";
  grid->revisions.clear();
  for (int64_t n = 1; n <= 6; ++n) {
    auto revision = std::make_shared<GridRevision>();
    revision->number = n;
    revision->origin = n == 1 ? RevisionOrigin::kFit : RevisionOrigin::kDeform;
    grid->revisions.push_back(std::move(revision));
  }
  MemoryStore store(/*max_deform_revisions=*/3);
  ASSERT_TRUE(store.Create(grid).ok());
  std::vector<int64_t> numbers;
  for (const auto& r : store.Get("imported").value()->revisions) numbers.push_back(r->number);
  EXPECT_EQ(numbers, (std::vector<int64_t>{1, 4, 5, 6}));
}

// A kept deformer keeps its fold gate per check level, charged to the memory budget until the
// deformer goes, unless the gate's reference is larger than the cap (level 4 of the 224 x 64
// cells is 3.7M cells): then it is made for each call and charged while the call holds it. A
// budget that cannot hold the gate refuses the call, naming the gate.
TEST_F(OpsTest, KeptDeformersKeepTheirGatesWithinTheCapAndChargeTheBudget) {
  const std::shared_ptr<const StoredGrid> grid = store_.Get("naca").value();
  GridFitOptions options;
  options.boundary_tolerances = BoundaryTolerances();
  const GridFit fit = FitGrid(grid->source->grid(), options).value();
  std::vector<FittedBlock> blocks;
  for (const BlockFit& b : fit.blocks) blocks.push_back(b.fitted);
  const Deformer deformer = Deformer::Create(blocks, fit.kinds, DeformOptions()).value();
  const int64_t before = budget_.used();
  {
    const KeptDeformer kept(deformer);
    const auto level0 = kept.Gate(0, budget_).value();
    EXPECT_EQ(kept.Gate(0, budget_).value(), level0);
    EXPECT_EQ(level0->num_cells(), 224 * 64);
    EXPECT_GT(level0->bytes(), 224 * 64 * 9);
    EXPECT_EQ(budget_.used() - before, level0->bytes());
    {
      const auto level4 = kept.Gate(4, budget_).value();
      EXPECT_GT(level4->num_cells(), KeptDeformer::kMaxKeptGateCells);
      EXPECT_EQ(budget_.used() - before, level0->bytes() + level4->bytes());
      EXPECT_NE(kept.Gate(4, budget_).value(), level4);
    }
    EXPECT_EQ(budget_.used() - before, level0->bytes());  // the call's gate went with it
  }
  EXPECT_EQ(budget_.used(), before);  // the kept one went with the deformer
  MemoryBudget tight(1000);
  const KeptDeformer kept(deformer);
  const absl::Status refused = kept.Gate(0, tight).status();
  EXPECT_EQ(refused.code(), absl::StatusCode::kResourceExhausted) << refused;
  EXPECT_THAT(refused.message(), HasSubstr("the fold gate of check_level 0"));
  EXPECT_EQ(tight.used(), 0);
}

TEST_F(OpsTest, WallCurvatureSamplesTheWallLinesWithinTheMessageLimit) {
  GridFitOptions options;
  options.boundary_tolerances = BoundaryTolerances();
  ASSERT_TRUE(ops::Fit(ops_, "naca", options, {}).ok());
  ops::WallCurvatureRequest request{"naca", 0, 1, {}, int64_t{4} << 20};
  const ops::WallCurvatureResult result = ops::WallCurvature(ops_, request, {}).value();
  EXPECT_EQ(result.revision, 1);
  EXPECT_EQ(result.spatial_dim, 2);
  ASSERT_FALSE(result.lines.empty());
  int64_t samples = 0;
  for (const ops::WallCurvatureLine& line : result.lines) {
    EXPECT_EQ(static_cast<int64_t>(line.samples.size()), 2 * (line.line.length - 1) + 1);
    samples += line.samples.size();
  }
  EXPECT_GT(samples, 200);
  request.max_bytes = samples * 4 * 8 - 1;  // one byte short of (x, y, arc length, curvature)
  EXPECT_EQ(ops::WallCurvature(ops_, request, {}).status().code(),
            absl::StatusCode::kResourceExhausted);
  request.max_bytes = int64_t{4} << 20;
  request.level = ops::kMaxCurvatureLevel + 1;
  EXPECT_THAT(ops::WallCurvature(ops_, request, {}).status().message(),
              HasSubstr("refinement_level = 5 is outside [0, 4]"));
  request.level = 0;
  request.blocks = {1};
  EXPECT_THAT(ops::WallCurvature(ops_, request, {}).status().message(),
              HasSubstr("blocks: 1 is outside [0, 0]"));
}

TEST_F(OpsTest, EvaluatePointsEvaluatesTheRevisionAskedFor) {
  GridFitOptions options;
  options.boundary_tolerances = BoundaryTolerances();
  ASSERT_TRUE(ops::Fit(ops_, "naca", options, {}).ok());
  ASSERT_TRUE(ops::Deform(ops_, Pitch(3.0), {}).ok());
  const std::vector<int32_t> blocks = {0};
  const std::vector<double> parameters = {0.0, 0.0, 0.0, 0.25, 0.5, 0.0, 1.0, 1.0, 0.0};
  ops::PointsRequest request{.grid_id = "naca",
                             .revision = 1,
                             .step = std::nullopt,
                             .blocks = blocks,
                             .parameters = parameters,
                             .derivatives = true,
                             .max_points = 100,
                             .max_bytes = int64_t{4} << 20};
  const ops::EvaluatedPoints fitted = ops::EvaluatePoints(ops_, request).value();
  EXPECT_EQ(fitted.revision, 1);
  ASSERT_EQ(fitted.spatial_dim, 2);
  ASSERT_EQ(fitted.points.size(), 6u);
  ASSERT_EQ(fitted.dw.size(), 6u);
  const TensorSpline& spline = store_.Get("naca").value()->revisions[0]->blocks[0].fitted.spline;
  for (int p = 0; p < 3; ++p) {
    const Point3 uvw = {parameters[3 * p], parameters[3 * p + 1], parameters[3 * p + 2]};
    const PartialDerivatives d = EvaluateDerivatives(spline, uvw, 1);
    for (int c = 0; c < 2; ++c) {
      EXPECT_EQ(fitted.points[2 * p + c], d(0, 0, 0)[c]);
      EXPECT_EQ(fitted.du[2 * p + c], d(1, 0, 0)[c]);
      EXPECT_EQ(fitted.dv[2 * p + c], d(0, 1, 0)[c]);
    }
  }
  // The latest (the pitched one) differs; by step, the same revision.
  request.revision = 0;
  request.derivatives = false;
  const ops::EvaluatedPoints pitched = ops::EvaluatePoints(ops_, request).value();
  EXPECT_EQ(pitched.revision, 2);
  EXPECT_TRUE(pitched.du.empty());
  EXPECT_NE(pitched.points[2], fitted.points[2]);
  request.step = 7;
  EXPECT_EQ(ops::EvaluatePoints(ops_, request).value().points, pitched.points);
}

TEST_F(OpsTest, EvaluatePointsRefusesBadBatchesNamingTheField) {
  GridFitOptions options;
  options.boundary_tolerances = BoundaryTolerances();
  ASSERT_TRUE(ops::Fit(ops_, "naca", options, {}).ok());
  std::vector<int32_t> blocks = {0};
  std::vector<double> parameters = {0.5, 0.5, 0.0, 0.5, 1.5, 0.0};
  ops::PointsRequest request{.grid_id = "naca",
                             .revision = 0,
                             .step = std::nullopt,
                             .blocks = blocks,
                             .parameters = parameters,
                             .derivatives = false,
                             .max_points = 100,
                             .max_bytes = int64_t{4} << 20};
  EXPECT_THAT(ops::EvaluatePoints(ops_, request).status().message(),
              HasSubstr("parameters[4] (v of point 1) = 1.5 is outside [0, 1]"));
  parameters[4] = std::nan("");
  EXPECT_THAT(ops::EvaluatePoints(ops_, request).status().message(),
              HasSubstr("parameters[4] (v of point 1) = nan"));
  parameters[4] = 0.5;
  blocks = {0, 1};
  request.blocks = blocks;
  EXPECT_THAT(ops::EvaluatePoints(ops_, request).status().message(),
              HasSubstr("blocks[1] = 1 is outside [0, 0]"));
  blocks = {0, 0, 0};
  request.blocks = blocks;
  EXPECT_THAT(ops::EvaluatePoints(ops_, request).status().message(),
              HasSubstr("blocks: 3 values for 2 points"));
  request.blocks = std::span<const int32_t>(blocks).first(1);
  request.parameters = std::span<const double>(parameters).first(5);
  EXPECT_THAT(ops::EvaluatePoints(ops_, request).status().message(),
              HasSubstr("parameters: 5 values is not a multiple of 3"));
  request.parameters = parameters;
  request.max_points = 1;
  EXPECT_EQ(ops::EvaluatePoints(ops_, request).status().code(), absl::StatusCode::kOutOfRange);
  request.max_points = 100;
  request.revision = 9;
  EXPECT_EQ(ops::EvaluatePoints(ops_, request).status().code(), absl::StatusCode::kNotFound);
  request.grid_id = "nothing";
  EXPECT_EQ(ops::EvaluatePoints(ops_, request).status().code(), absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace splinegrid::server
