// The operations behind the streaming calls (server/ops), without gRPC or protobuf: a grid
// evaluated in chunks gives exactly the kernel's values and covers the output once; a revision
// feed gives the stored revisions, then new ones, and ends with the grid; imports refuse
// unfittable grids and keep the connectivity they find; archived grids must bring the
// connectivity their points have.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "core/bspline/evaluation.h"
#include "core/grid/connectivity.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/ops/archive.h"
#include "server/ops/evaluate_grid.h"
#include "server/ops/fit.h"
#include "server/ops/import.h"
#include "server/ops/watch.h"
#include "server/store/grid_archive.h"
#include "server/store/memory_store.h"
#include "tests/server/ops_fixture.h"

namespace splinegrid::server {
namespace {

using ::testing::HasSubstr;

class OpsStreamsTest : public OpsFixture {
 protected:
  ops::GridEvaluationRequest Evaluation(int level) {
    ops::GridEvaluationRequest request;
    request.grid_id = "naca";
    request.resolution.level = level;
    request.derivatives = true;
    request.max_points = int64_t{1} << 24;
    request.chunk_values = 1 << 16;
    return request;
  }
};

TEST_F(OpsStreamsTest, GridEvaluationChunksCoverTheOutputOnceWithTheKernelsValues) {
  AddNaca("naca", 1);
  const std::shared_ptr<const GridRevision> revision = store_.Get("naca").value()->revisions.back();
  // 2 values per point, 449 points per line at level 1: 300 values split lines into pieces,
  // 4096 take several whole lines at a time.
  for (const int64_t chunk_values : {int64_t{300}, int64_t{4096}}) {
    ops::GridEvaluationRequest request = Evaluation(1);
    request.chunk_values = chunk_values;
    auto plan = ops::GridEvaluation::Plan(ops_, request);
    ASSERT_TRUE(plan.ok()) << plan.status();
    ops::GridEvaluation& evaluation = **plan;
    ASSERT_EQ(evaluation.blocks().size(), 1u);
    const Extents extents = evaluation.blocks()[0].extents;
    EXPECT_EQ(extents, (Extents{449, 129, 1}));
    EXPECT_EQ(evaluation.total_points(), 449 * 129);
    EXPECT_EQ(evaluation.revision(), revision->number);
    ASSERT_EQ(evaluation.num_fields(), 4);

    const int64_t size = 2 * evaluation.total_points();
    std::array<std::vector<double>, 4> got;
    for (auto& field : got) field.assign(size, std::nan(""));
    int64_t expected_offset = 0, chunks = 0;
    while (!evaluation.done()) {
      const ops::EvaluationChunk chunk = evaluation.Next();
      ASSERT_EQ(chunk.offset, expected_offset);  // contiguous, in order, none twice
      ASSERT_GT(chunk.count, 0);
      ASSERT_LE(chunk.count, chunk_values);
      evaluation.EvaluateNext({got[0].data() + chunk.offset, got[1].data() + chunk.offset,
                               got[2].data() + chunk.offset, got[3].data() + chunk.offset});
      expected_offset += chunk.count;
      ++chunks;
    }
    EXPECT_EQ(expected_offset, size);
    EXPECT_GT(chunks, 1);

    const TensorSpline& spline = revision->blocks[0].fitted.spline;
    GridEvaluator direct(
        spline,
        SampleParameters(revision->blocks[0].fitted.distribution, request.resolution).value(),
        /*first_derivatives=*/true);
    std::array<std::vector<double>, 4> want;
    for (auto& field : want) field.resize(size);
    direct.EvaluateLines(0, direct.num_lines(), want[0].data(), want[1].data(), want[2].data(),
                         want[3].data());
    for (int f = 0; f < 4; ++f) {
      EXPECT_TRUE(std::equal(got[f].begin(), got[f].end(), want[f].begin()))
          << "field " << f << ", chunks of " << chunk_values << " values";
    }
  }
}

// The points (field 0) of a whole evaluation, drained in chunks.
std::vector<double> Drain(ops::GridEvaluation& evaluation) {
  std::vector<double> points(evaluation.spatial_dim() * evaluation.total_points());
  std::array<std::vector<double>, 3> derivatives;
  for (auto& field : derivatives) field.resize(points.size());
  while (!evaluation.done()) {
    const ops::EvaluationChunk chunk = evaluation.Next();
    evaluation.EvaluateNext({points.data() + chunk.offset, derivatives[0].data() + chunk.offset,
                             derivatives[1].data() + chunk.offset,
                             derivatives[2].data() + chunk.offset});
  }
  return points;
}

// Twice the signed area of quadrilateral (i, j), (i+1, j), (i+1, j+1), (i, j+1) of a 2D grid
// stored i fastest, by the shoelace formula.
double CellArea(const std::vector<double>& x, int ni, int i, int j) {
  const int64_t corners[4] = {int64_t{j} * ni + i, int64_t{j} * ni + i + 1,
                              int64_t{j + 1} * ni + i + 1, int64_t{j + 1} * ni + i};
  double area = 0.0;
  for (int c = 0; c < 4; ++c) {
    const int64_t p = corners[c], q = corners[(c + 1) % 4];
    area += x[2 * p] * x[2 * q + 1] - x[2 * q] * x[2 * p + 1];
  }
  return area;
}

TEST_F(OpsStreamsTest, NewWallSpacingKeepsTheWallExactlyAndFoldsNoCell) {
  AddNaca("naca", 1);
  for (const int level : {0, 1, 2}) {
    ops::GridEvaluationRequest original = Evaluation(level);
    original.chunk_values = 1000;
    auto plan = ops::GridEvaluation::Plan(ops_, original);
    ASSERT_TRUE(plan.ok()) << plan.status();
    const std::vector<double> before = Drain(**plan);
    const Extents n = (*plan)->blocks()[0].extents;

    // A first spacing of 2e-6 chords off the wall (the original's is about 1e-5 at the
    // airfoil), in chunks that split lines.
    ops::GridEvaluationRequest request = original;
    request.resolution.distributions[1] = {Distribution::Kind::kGeometric, 2e-6};
    auto measured = ops::GridEvaluation::Plan(ops_, request);
    ASSERT_TRUE(measured.ok()) << measured.status();
    const std::vector<double> after = Drain(**measured);
    ASSERT_EQ(after.size(), before.size());
    for (int i = 0; i < n[0]; ++i) {
      // The wall row is the same curve at the same parameters: the same points (up to the
      // rounding of the two evaluation orders, 1e-15 relative).
      for (int c : {0, 1}) {
        EXPECT_NEAR(after[2 * i + c], before[2 * i + c],
                    1e-15 * (1.0 + std::abs(before[2 * i + c])))
            << "level " << level << ", i = " << i;
      }
      // The first interval is as asked on every wall-normal line: its arc length is (the
      // kernel test checks that to 1e-12 on straight lines); the straight distance measured
      // here is shorter by the fitted line's bending inside the original first interval
      // (1e-5 chords), up to 2.4e-4 relative on this grid. The far field is kept.
      const int64_t first = int64_t{n[0]} + i, last = int64_t{n[1] - 1} * n[0] + i;
      EXPECT_NEAR(
          std::hypot(after[2 * first] - after[2 * i], after[2 * first + 1] - after[2 * i + 1]),
          2e-6, 2e-6 * 1e-3)
          << "level " << level << ", i = " << i;
      for (int c : {0, 1}) {
        EXPECT_NEAR(after[2 * last + c], before[2 * last + c],
                    1e-13 * (1.0 + std::abs(before[2 * last + c])));
      }
    }
    // No cell changes orientation from the original's (all of one sign there).
    const double sign = CellArea(before, n[0], 0, 0) > 0 ? 1.0 : -1.0;
    int folded = 0, folded_before = 0;
    for (int j = 0; j + 1 < n[1]; ++j) {
      for (int i = 0; i + 1 < n[0]; ++i) {
        folded += sign * CellArea(after, n[0], i, j) <= 0.0;
        folded_before += sign * CellArea(before, n[0], i, j) <= 0.0;
      }
    }
    EXPECT_EQ(folded_before, 0) << "level " << level;
    EXPECT_EQ(folded, 0) << "level " << level;
  }
  // Uniform arc length along the C (an isotropic spacing for an Euler grid): even chords along
  // the wall line (to the chord/arc difference) and no fold.
  ops::GridEvaluationRequest request = Evaluation(1);
  request.resolution.distributions[0] = {Distribution::Kind::kUniformArcLength};
  auto plan = ops::GridEvaluation::Plan(ops_, request);
  ASSERT_TRUE(plan.ok()) << plan.status();
  const std::vector<double> x = Drain(**plan);
  const Extents n = (*plan)->blocks()[0].extents;
  std::vector<double> chords;
  for (int i = 1; i < n[0]; ++i) {
    chords.push_back(std::hypot(x[2 * i] - x[2 * i - 2], x[2 * i + 1] - x[2 * i - 1]));
  }
  const auto [shortest, longest] = std::minmax_element(chords.begin(), chords.end());
  EXPECT_GT(*shortest / *longest, 0.95);
  const double sign = CellArea(x, n[0], n[0] / 2, 0) > 0 ? 1.0 : -1.0;
  int folded = 0;
  for (int j = 0; j + 1 < n[1]; ++j) {
    for (int i = 0; i + 1 < n[0]; ++i) folded += sign * CellArea(x, n[0], i, j) <= 0.0;
  }
  EXPECT_EQ(folded, 0);
}

TEST_F(OpsStreamsTest, GridEvaluationRefusesNamingTheFieldAndReservesItsMemory) {
  AddNaca("naca", 1);
  ops::GridEvaluationRequest request = Evaluation(0);
  request.blocks = {1};
  EXPECT_THAT(ops::GridEvaluation::Plan(ops_, request).status().message(),
              HasSubstr("blocks[0] = 1 is outside [0, 0]"));
  request.blocks = {0, 0};
  EXPECT_THAT(ops::GridEvaluation::Plan(ops_, request).status().message(),
              HasSubstr("blocks[1] = 0 is repeated"));
  request.blocks = {};
  request.max_points = 1000;
  EXPECT_EQ(ops::GridEvaluation::Plan(ops_, request).status().code(),
            absl::StatusCode::kOutOfRange);
  request = Evaluation(0);
  request.step = 3;
  EXPECT_EQ(ops::GridEvaluation::Plan(ops_, request).status().code(), absl::StatusCode::kNotFound);

  // The plan holds its memory (the evaluator's nets, parameters and the caller's buffers)
  // until it is destroyed; a level whose parameters exceed the budget is refused before they
  // are sampled.
  request = Evaluation(0);
  request.buffer_bytes = 1 << 20;
  const int64_t before = budget_.used();
  {
    auto plan = ops::GridEvaluation::Plan(ops_, request);
    ASSERT_TRUE(plan.ok()) << plan.status();
    EXPECT_GT(budget_.used(), before + (1 << 20));
  }
  EXPECT_EQ(budget_.used(), before);
  request = Evaluation(13);  // 1.8M x 0.5M points: nets of gigabytes
  request.max_points = int64_t{1} << 62;
  request.derivatives = false;
  request.blocks = {0};
  EXPECT_EQ(ops::GridEvaluation::Plan(ops_, request).status().code(),
            absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(budget_.used(), before);
  // Beyond 2^40 points in a block nothing is sized at all.
  request = Evaluation(20);
  request.max_points = int64_t{1} << 62;
  EXPECT_THAT(ops::GridEvaluation::Plan(ops_, request).status().message(),
              HasSubstr("points, over 2^40 in one block"));
  EXPECT_EQ(budget_.used(), before);
}

class NoWatcher : public GridWatcher {
 public:
  void Wake() override {}
};

TEST_F(OpsStreamsTest, RevisionFeedGivesStoredThenNewRevisionsAndEndsWithTheGrid) {
  AddNaca("naca", 2);
  auto watcher = std::make_shared<NoWatcher>();
  auto feed = ops::RevisionFeed::Open(ops_, "naca", 0, watcher, 8);
  ASSERT_TRUE(feed.ok()) << feed.status();
  auto only_new = ops::RevisionFeed::Open(ops_, "naca", -1, watcher, 8);
  ASSERT_TRUE(only_new.ok()) << only_new.status();
  auto after_one = ops::RevisionFeed::Open(ops_, "naca", 1, watcher, 8);
  ASSERT_TRUE(after_one.ok()) << after_one.status();

  std::vector<int64_t> taken;
  while (auto r = (*feed)->Next()) taken.push_back(r->number);
  EXPECT_EQ(taken, (std::vector<int64_t>{1, 2}));
  EXPECT_FALSE((*feed)->ended());
  EXPECT_FALSE((*only_new)->Next().has_value());
  EXPECT_EQ((*after_one)->Next()->number, 2);

  GridFitOptions options;
  options.boundary_tolerances = BoundaryTolerances();
  ASSERT_TRUE(ops::Fit(ops_, "naca", options, {}).ok());
  EXPECT_EQ((*feed)->Next()->number, 3);
  EXPECT_EQ((*only_new)->Next()->number, 3);
  ASSERT_TRUE(store_.Delete("naca").ok());
  EXPECT_FALSE((*feed)->Next().has_value());
  EXPECT_TRUE((*feed)->ended());
  EXPECT_TRUE((*feed)->end_status().ok());
  // A feed behind the deletion still gets what was published before it.
  EXPECT_EQ((*after_one)->Next()->number, 3);
  EXPECT_FALSE((*after_one)->Next().has_value());
  EXPECT_TRUE((*after_one)->ended());

  EXPECT_THAT(ops::RevisionFeed::Open(ops_, "naca", 0, watcher, 8).status().code(),
              absl::StatusCode::kNotFound);
  EXPECT_THAT(ops::RevisionFeed::Open(ops_, "x", -2, watcher, 8).status().message(),
              HasSubstr("after_revision = -2 is below -1"));
}

TEST_F(OpsStreamsTest, RevisionFeedEndsWhenItsReaderLags) {
  AddNaca("naca", 0);
  auto watcher = std::make_shared<NoWatcher>();
  auto feed = ops::RevisionFeed::Open(ops_, "naca", -1, watcher, /*max_lag=*/1);
  ASSERT_TRUE(feed.ok()) << feed.status();
  GridFitOptions options;
  options.boundary_tolerances = BoundaryTolerances();
  for (int f = 0; f < 3; ++f) ASSERT_TRUE(ops::Fit(ops_, "naca", options, {}).ok());
  EXPECT_FALSE((*feed)->Next().has_value());
  EXPECT_TRUE((*feed)->ended());
  EXPECT_EQ((*feed)->end_status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT((*feed)->end_status().message(), HasSubstr("watch again with after_revision = 0"));
}

TEST_F(OpsStreamsTest, StoreImportedRefusesUnfittableGridsAndKeepsTheConnectivityItFinds) {
  ops::ImportedSource collapsed;
  StructuredBlock point({3, 2, 1}, 2);
  std::fill(point.coords().begin(), point.coords().end(), 1.5);
  collapsed.imported.grid.blocks.push_back(point);
  const auto refused = ops::StoreImported(ops_, {"flat", "", ""}, std::move(collapsed));
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(refused.status().message(), HasSubstr("block 0: all 6 points are equal"));
  EXPECT_EQ(store_.Get("flat").status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(ops::StoreImported(ops_, {"none", "", ""}, {}).status().code(),
            absl::StatusCode::kInvalidArgument);

  ops::ImportedSource source;
  source.imported.grid = Naca();
  source.imported.format = "plot3d";
  const int64_t before = budget_.used();
  const auto stored = ops::StoreImported(ops_, {"naca", "NACA 0012", "alice"}, std::move(source));
  ASSERT_TRUE(stored.ok()) << stored.status();
  EXPECT_EQ((*stored)->owner, "alice");
  EXPECT_EQ((*stored)->display_name, "NACA 0012");
  EXPECT_EQ((*stored)->source->connectivity(), FindConnectivity(Naca()).value());
  EXPECT_EQ((*stored)->source->connectivity().matches.size(), 1u);  // the wake cut
  EXPECT_EQ(budget_.used() - before, SourceBytes(Naca()));
  EXPECT_EQ(ops::StoreImported(ops_, {"naca", "", ""}, ops::ImportedSource{}).status().code(),
            absl::StatusCode::kInvalidArgument);  // no blocks, checked before the id
}

TEST_F(OpsStreamsTest, StoreImportedStopsWhenTheCallIsCancelledAndStoresNothing) {
  // 3 x 70,000 points: 140,000 boundary points, more than one poll's worth (2^16).
  StructuredBlock strip({3, 70000, 1}, 2);
  for (int j = 0; j < 70000; ++j) {
    for (int i = 0; i < 3; ++i) {
      strip.Point(i, j, 0)[0] = i;
      strip.Point(i, j, 0)[1] = 1e-3 * j;
    }
  }
  ops::ImportedSource source;
  source.imported.grid.blocks.push_back(std::move(strip));
  const int64_t before = budget_.used();
  int polls = 0;
  const auto stopped = ops::StoreImported(ops_, {"naca", "", "", [&polls] { return ++polls > 0; }},
                                          std::move(source));
  EXPECT_EQ(stopped.status().code(), absl::StatusCode::kCancelled);
  EXPECT_EQ(polls, 1);  // stopped at the first poll
  EXPECT_EQ(store_.Get("naca").status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(budget_.used(), before);
}

TEST_F(OpsStreamsTest, ArchivedGridsMustBringTheConnectivityOfTheirPoints) {
  AddNaca("naca", 1);
  const std::shared_ptr<const StoredGrid> original = store_.Get("naca").value();
  auto copy = [&](const std::string& id) {
    auto grid = std::make_shared<StoredGrid>(*original);
    grid->id = id;
    return grid;
  };
  const Connectivity found = original->source->connectivity();
  ASSERT_EQ(found.matches.size(), 1u);
  const absl::Status damaged = ops::StoreArchived(ops_, copy("damaged"), Connectivity(), "bob");
  EXPECT_EQ(damaged.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(damaged.message(), HasSubstr("header.connectivity does not match"));
  EXPECT_EQ(store_.Get("damaged").status().code(), absl::StatusCode::kNotFound);
  Connectivity moved = found;
  ++moved.matches[0].a.end[0];
  EXPECT_THAT(ops::StoreArchived(ops_, copy("moved"), moved, "bob").message(),
              HasSubstr("this server finds 1 other ones"));
  ASSERT_TRUE(ops::StoreArchived(ops_, copy("intact"), found, "bob").ok());
  EXPECT_EQ(store_.Get("intact").value()->owner, "bob");

  // The export's memory: held while the records exist, as much as the writer keeps.
  const int64_t before = budget_.used();
  auto memory = ops::ExportSnapshot(ops_, "intact", [](const StoredGrid& grid) {
    return absl::StatusOr<int64_t>(SourceBytes(grid.source->grid()) + 1000);
  });
  ASSERT_TRUE(memory.ok()) << memory.status();
  EXPECT_EQ(budget_.used() - before, SourceBytes(Naca()) + 1000);
  *memory = MemoryReservation();
  EXPECT_EQ(budget_.used(), before);
  EXPECT_EQ(ops::ExportSnapshot(ops_, "missing", [](const StoredGrid&) { return int64_t{0}; })
                .status()
                .code(),
            absl::StatusCode::kNotFound);
}

// Records of a stored grid whose points were made unfittable (every coordinate equal): the
// assembler takes the revisions (they match the extents) but refuses the grid as a whole, as
// the dir store's loader and ImportArchive see it, and a record after the refusal gets the
// same error instead of touching a source that is not there.
TEST_F(OpsStreamsTest, AnArchiveWithUnfittablePointsIsRefusedWhole) {
  AddNaca("naca", 2);
  std::vector<v1::ArchiveRecord> records;
  ASSERT_TRUE(ForEachRecord(*store_.Get("naca").value(), [&](const v1::ArchiveRecord& record) {
                records.push_back(record);
                return absl::OkStatus();
              }).ok());
  GridAssembler intact(&budget_, "copy");
  for (const v1::ArchiveRecord& record : records) ASSERT_TRUE(intact.Add(record).ok());
  const auto copy = intact.Finish(/*check_counts=*/true);
  ASSERT_TRUE(copy.ok()) << copy.status();
  EXPECT_EQ((*copy)->source->connectivity(), intact.stated_connectivity());
  EXPECT_EQ((*copy)->revisions.size(), 2u);

  for (v1::ArchiveRecord& record : records) {
    if (!record.has_source()) continue;
    for (double& x : *record.mutable_source()->mutable_coords()) x = 1.0;
  }
  GridAssembler damaged(&budget_, "damaged");
  for (const v1::ArchiveRecord& record : records) ASSERT_TRUE(damaged.Add(record).ok());
  const absl::Status refused = damaged.Finish(/*check_counts=*/true).status();
  EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(refused.message(),
              HasSubstr("the archive's source points: block 0: all 14625 points are equal"));

  // A source that does not assemble (one chunk short) is kept as the error of what follows.
  GridAssembler truncated(&budget_, "truncated");
  bool skipped = false;
  absl::Status status;
  for (const v1::ArchiveRecord& record : records) {
    if (record.has_source() && !skipped) {
      skipped = true;
      continue;
    }
    status = truncated.Add(record);
    if (!status.ok()) break;
  }
  EXPECT_THAT(status.message(), HasSubstr("source points are incomplete"));
  EXPECT_EQ(truncated.Add(records.back()).message(), status.message());
  EXPECT_EQ(truncated.Finish(false).status().message(), status.message());
}

}  // namespace
}  // namespace splinegrid::server
