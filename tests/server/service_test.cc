// Every method of splinegrid.v1.SplineGrid through Server::InProcessChannel.
#include <cmath>

#include "core/io/planar_view.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "proto/convert/convert.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::testing {
namespace {

using ::testing::HasSubstr;

MultiBlockGrid ReadShared(const std::string& relative) {
  return ReadPlot3dFile(SharedDataPath(relative)).value();
}

TEST_F(ServiceTest, ImportPlot3dDescribesTheSource) {
  const v1::Grid grid = ImportShared("grids/n0012_113-33.p2dfmt", "naca");
  EXPECT_EQ(grid.name(), "grids/naca");
  EXPECT_EQ(grid.display_name(), "grids/n0012_113-33.p2dfmt");
  EXPECT_EQ(grid.source().spatial_dim(), 2);
  ASSERT_EQ(grid.source().blocks_size(), 1);
  EXPECT_EQ(grid.source().blocks(0).i(), 113);
  EXPECT_EQ(grid.source().blocks(0).j(), 33);
  EXPECT_EQ(grid.source().num_points(), 113 * 33);
  EXPECT_THAT(grid.source().format(), HasSubstr("plot3d"));
  EXPECT_EQ(grid.latest_revision(), 0);
  EXPECT_FALSE(grid.has_revision());
  EXPECT_GT(grid.create_time().seconds(), 0);
}

TEST_F(ServiceTest, ImportPlanarViewOfTwoPlaneFile) {
  const v1::Grid grid = ImportShared("grids/rae2822_257x97.fmt", "rae", /*planar=*/true);
  EXPECT_EQ(grid.source().spatial_dim(), 2);
  EXPECT_EQ(grid.source().blocks(0).i(), 257);
  EXPECT_EQ(grid.source().blocks(0).j(), 97);
  EXPECT_THAT(grid.source().format(), HasSubstr("planar view"));
}

// planar_view_if_two_planes (what the CLI and the Python client send): the server decides from
// the file it parsed; a 3D file with an extent of 2 that is a real box and a 2D file are stored
// as read.
TEST_F(ServiceTest, ImportPlanarViewIfTwoPlanesIsDecidedByTheServer) {
  auto import = [&](const std::string& relative, const std::string& id) {
    v1::Plot3dSource options;
    options.set_planar_view_if_two_planes(true);
    const std::string bytes = ReadFileToString(SharedDataPath(relative)).value();
    absl::StatusOr<v1::Grid> grid = client_->ImportPlot3d(bytes, id, relative, options);
    EXPECT_TRUE(grid.ok()) << relative << ": " << grid.status();
    return grid.ok() ? *grid : v1::Grid();
  };
  const v1::Grid rae = import("grids/rae2822_257x97.fmt", "rae");
  EXPECT_EQ(rae.source().spatial_dim(), 2);
  EXPECT_EQ(rae.source().blocks(0).k(), 1);
  EXPECT_THAT(rae.source().format(), HasSubstr("planar view"));
  const v1::Grid box = import("surfaces/ffd_box_6x2x6.fmt", "box");
  EXPECT_EQ(box.source().spatial_dim(), 3);
  EXPECT_EQ(box.source().blocks(0).j(), 2);
  EXPECT_THAT(box.source().format(), ::testing::Not(HasSubstr("planar view")));
  const v1::Grid naca = import("grids/n0012_225-65.p2dfmt", "naca");
  EXPECT_EQ(naca.source().spatial_dim(), 2);
  EXPECT_THAT(naca.source().format(), ::testing::Not(HasSubstr("planar view")));
}

TEST_F(ServiceTest, ImportPointsWithServerChosenId) {
  const MultiBlockGrid sphere = ReadShared("surfaces/even_sphere.fmt");
  const v1::Grid grid = client_->ImportPoints(sphere, "", "sphere").value();
  EXPECT_THAT(grid.name(), ::testing::StartsWith("grids/grid-"));
  EXPECT_EQ(grid.source().blocks_size(), 6);
  EXPECT_EQ(grid.source().format(), "points");
}

TEST_F(ServiceTest, FitWithCountsThenGetBasicAndFullViews) {
  ImportShared("grids/n0012_113-33.p2dfmt", "naca");
  const v1::FitGridResponse fit = FitCounts("naca", 40, 20);
  EXPECT_EQ(fit.revision(), 1);
  ASSERT_EQ(fit.blocks_size(), 1);
  EXPECT_EQ(fit.num_points(), 113 * 33);
  EXPECT_EQ(fit.num_control_points(), 800);
  EXPECT_NEAR(fit.compression_ratio(), 113.0 * 33 / 800, 1e-12);
  EXPECT_GT(fit.max_deviation(), 0.0);
  EXPECT_FALSE(fit.blocks(0).has_tolerance_met());

  const v1::Grid basic = client_->Get("naca").value();
  EXPECT_EQ(basic.latest_revision(), 1);
  EXPECT_EQ(basic.revision().blocks(0).directions(0).num_controls(), 40);
  EXPECT_EQ(basic.revision().blocks(0).control_points_size(), 0);
  EXPECT_EQ(basic.revision().fit_spec().control_counts().i(), 40);

  const v1::Grid full = client_->Get("naca", 0, v1::GRID_VIEW_FULL).value();
  const v1::SplineBlock& block = full.revision().blocks(0);
  EXPECT_EQ(block.control_points_size(), 2 * 800);
  EXPECT_EQ(block.directions(0).knots_size(), 40 + 4);
  EXPECT_EQ(block.directions(0).parameters_size(), 113);
  // The FULL view is enough to rebuild the mapping exactly.
  const FittedBlock rebuilt = ParseSplineBlock(block).value();
  EXPECT_EQ(rebuilt.spline.control_extents(), (Extents{40, 20, 1}));
  EXPECT_DOUBLE_EQ(rebuilt.summary.deviation.max, fit.blocks(0).max_deviation());
}

TEST_F(ServiceTest, RevisionsAreImmutableAndAddressable) {
  ImportShared("grids/n0012_113-33.p2dfmt", "naca");
  FitCounts("naca", 20, 10);
  const v1::Grid first = client_->Get("naca", 1, v1::GRID_VIEW_FULL).value();
  FitCounts("naca", 60, 30);
  const v1::Grid grid = client_->Get("naca").value();
  EXPECT_EQ(grid.latest_revision(), 2);
  ASSERT_EQ(grid.revisions_size(), 2);
  EXPECT_EQ(grid.revisions(0).origin(), v1::REVISION_ORIGIN_FIT);
  const v1::Grid again = client_->Get("naca", 1, v1::GRID_VIEW_FULL).value();
  EXPECT_EQ(again.revision().SerializeAsString(), first.revision().SerializeAsString());
  EXPECT_EQ(client_->Get("naca", 3).status().code(), absl::StatusCode::kNotFound);
}

TEST_F(ServiceTest, FitToToleranceMeetsIt) {
  ImportShared("surfaces/m6_small.fmt", "m6");
  v1::FitSpec spec;
  spec.set_tolerance(1e-3);
  const v1::FitGridResponse fit = client_->Fit("m6", spec).value();
  ASSERT_EQ(fit.blocks_size(), 9);
  for (const v1::BlockFitSummary& block : fit.blocks()) {
    ASSERT_TRUE(block.has_tolerance_met());
    EXPECT_TRUE(block.tolerance_met()) << block.unmet_reason();
    EXPECT_LE(block.max_deviation(), 1e-3);
  }
  EXPECT_GT(fit.compression_ratio(), 20.0);
}

TEST_F(ServiceTest, ListPagesThroughEveryGrid) {
  for (const char* id : {"e", "a", "d", "b", "c"}) ImportShared("surfaces/even_sphere.fmt", id);
  std::vector<std::string> names;
  v1::ListGridsRequest request;
  request.set_page_size(2);
  int pages = 0;
  do {
    grpc::ClientContext context;
    v1::ListGridsResponse response;
    ASSERT_TRUE(client_->stub().ListGrids(&context, request, &response).ok());
    for (const v1::Grid& g : response.grids()) names.push_back(g.name());
    request.set_page_token(response.next_page_token());
    ++pages;
  } while (!request.page_token().empty());
  EXPECT_EQ(pages, 3);
  EXPECT_THAT(names, ::testing::ElementsAre("grids/a", "grids/b", "grids/c", "grids/d", "grids/e"));
  EXPECT_EQ(client_->List().value().size(), 5u);
}

TEST_F(ServiceTest, DeleteRemovesTheGrid) {
  ImportShared("surfaces/even_sphere.fmt", "s");
  ASSERT_TRUE(client_->Delete("grids/s").ok());
  EXPECT_EQ(client_->Get("s").status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(client_->Delete("s").code(), absl::StatusCode::kNotFound);
  EXPECT_TRUE(client_->List().value().empty());
}

v1::EvaluateGridRequest Level(const std::string& name, int level) {
  v1::EvaluateGridRequest request;
  request.set_name(name);
  request.set_refinement_level(level);
  return request;
}

TEST_F(ServiceTest, EvaluateAtOriginalResolutionReproducesThePoints) {
  ImportShared("grids/n0012_113-33.p2dfmt", "naca");
  const v1::FitGridResponse fit = FitCounts("naca", 60, 25);
  const client::EvaluatedGrid eval = client_->Evaluate(Level("naca", 0)).value();
  ASSERT_EQ(eval.blocks.size(), 1u);
  const MultiBlockGrid source = ReadShared("grids/n0012_113-33.p2dfmt");
  const StructuredBlock& original = source.blocks[0];
  ASSERT_EQ(eval.blocks[0].points.extents(), original.extents());
  double worst = 0.0;
  for (int64_t p = 0; p < original.num_points(); ++p) {
    const double dx = eval.blocks[0].points.coords()[2 * p] - original.coords()[2 * p];
    const double dy = eval.blocks[0].points.coords()[2 * p + 1] - original.coords()[2 * p + 1];
    worst = std::max(worst, std::hypot(dx, dy));
  }
  EXPECT_NEAR(worst, fit.max_deviation(), 1e-9 * (1 + fit.max_deviation()));
}

TEST_F(ServiceTest, EvaluateRefinedBoxCountsAndFloat) {
  ImportShared("grids/n0012_113-33.p2dfmt", "naca");
  FitCounts("naca", 60, 25);
  const client::EvaluatedGrid level0 = client_->Evaluate(Level("naca", 0)).value();
  const client::EvaluatedGrid level2 = client_->Evaluate(Level("naca", 2)).value();
  const StructuredBlock& coarse = level0.blocks[0].points;
  const StructuredBlock& fine = level2.blocks[0].points;
  ASSERT_EQ(fine.extents(), (Extents{112 * 4 + 1, 32 * 4 + 1, 1}));
  for (int j = 0; j < 33; j += 4) {
    for (int i = 0; i < 113; i += 7) {
      EXPECT_NEAR(fine.Point(4 * i, 4 * j, 0)[0], coarse.Point(i, j, 0)[0], 1e-12);
      EXPECT_NEAR(fine.Point(4 * i, 4 * j, 0)[1], coarse.Point(i, j, 0)[1], 1e-12);
    }
  }
  // An index box at level 2 is the same slice of the block, bit for bit.
  v1::EvaluateGridRequest box = Level("naca", 2);
  box.mutable_index_box()->mutable_begin()->set_i(10);
  box.mutable_index_box()->mutable_end()->set_i(20);
  box.mutable_index_box()->mutable_begin()->set_j(3);
  box.mutable_index_box()->mutable_end()->set_j(5);
  const StructuredBlock part = client_->Evaluate(box).value().blocks[0].points;
  ASSERT_EQ(part.extents(), (Extents{41, 9, 1}));
  for (int j = 0; j < 9; ++j) {
    for (int i = 0; i < 41; ++i) {
      EXPECT_EQ(part.Point(i, j, 0)[0], fine.Point(40 + i, 12 + j, 0)[0]);
      EXPECT_EQ(part.Point(i, j, 0)[1], fine.Point(40 + i, 12 + j, 0)[1]);
    }
  }
  v1::EvaluateGridRequest counts;
  counts.set_name("naca");
  counts.mutable_counts()->set_i(300);
  counts.mutable_counts()->set_j(50);
  counts.mutable_counts()->set_k(1);
  counts.set_precision(v1::PRECISION_FLOAT);
  const StructuredBlock resampled = client_->Evaluate(counts).value().blocks[0].points;
  ASSERT_EQ(resampled.extents(), (Extents{300, 50, 1}));
  // Float transfer: the first and last points are the block's corners.
  EXPECT_NEAR(resampled.Point(0, 0, 0)[0], coarse.Point(0, 0, 0)[0],
              1e-6 * std::abs(coarse.Point(0, 0, 0)[0]) + 1e-6);
  EXPECT_NEAR(resampled.Point(299, 49, 0)[1], coarse.Point(112, 32, 0)[1],
              1e-6 * std::abs(coarse.Point(112, 32, 0)[1]) + 1e-6);
}

TEST_F(ServiceTest, EvaluateStreamsLargeResultsInChunksOfAbout256KiB) {
  ImportShared("grids/n0012_225-65.p2dfmt", "big");
  FitCounts("big", 40, 20);
  v1::EvaluateGridRequest request = Level("grids/big", 3);
  request.set_derivatives(true);
  grpc::ClientContext context;
  auto reader = client_->stub().EvaluateGrid(&context, request);
  v1::EvaluateGridResponse message;
  ASSERT_TRUE(reader->Read(&message));
  ASSERT_TRUE(message.has_header());
  const int64_t total = message.header().total_points();
  EXPECT_EQ(total, int64_t{224 * 8 + 1} * (64 * 8 + 1));
  int64_t values[5] = {0, 0, 0, 0, 0};
  int chunks = 0;
  while (reader->Read(&message)) {
    ASSERT_TRUE(message.has_chunk());
    EXPECT_LE(message.ByteSizeLong(), (256u << 10) + 64);
    values[message.chunk().field()] += message.chunk().values_size();
    ++chunks;
  }
  ASSERT_TRUE(reader->Finish().ok());
  for (int f = v1::FIELD_POINTS; f <= v1::FIELD_DW; ++f) EXPECT_EQ(values[f], 2 * total);
  EXPECT_GT(chunks, 4 * 10);
}

TEST_F(ServiceTest, EvaluatePointsMatchesGridEvaluationWithDerivatives) {
  ImportShared("surfaces/m6_small.fmt", "m6");
  FitCounts("m6", 12, 12);
  v1::EvaluateGridRequest grid_request;
  grid_request.set_name("m6");
  grid_request.mutable_counts()->set_i(5);
  grid_request.mutable_counts()->set_j(4);
  grid_request.mutable_counts()->set_k(1);
  grid_request.add_blocks(3);
  grid_request.set_derivatives(true);
  const client::EvaluatedBlock block = client_->Evaluate(grid_request).value().blocks[0];
  EXPECT_EQ(block.block, 3);
  // The same points through EvaluatePoints, at the parameters the grid used.
  const v1::Grid full = client_->Get("m6", 0, v1::GRID_VIEW_FULL, {3}).value();
  const FittedBlock fitted = ParseSplineBlock(full.revision().blocks(3)).value();
  Resolution resolution;
  resolution.kind = Resolution::Kind::kCounts;
  resolution.counts = {5, 4, 1};
  const auto params = SampleParameters(fitted.distribution, resolution).value();
  v1::EvaluatePointsRequest points;
  points.set_name("m6");
  points.add_blocks(3);
  points.set_derivatives(true);
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 5; ++i) {
      points.add_parameters(params[0][i]);
      points.add_parameters(params[1][j]);
      points.add_parameters(0.0);
    }
  }
  const v1::EvaluatePointsResponse response = client_->EvaluatePoints(points).value();
  ASSERT_EQ(response.points_size(), 60);
  for (int x = 0; x < 60; ++x) {
    EXPECT_NEAR(response.points(x), block.points.coords()[x], 1e-13);
    EXPECT_NEAR(response.du(x), block.du[x], 1e-10);
    EXPECT_NEAR(response.dv(x), block.dv[x], 1e-10);
    EXPECT_NEAR(response.dw(x), block.dw[x], 1e-10);
  }
}

}  // namespace
}  // namespace splinegrid::testing
