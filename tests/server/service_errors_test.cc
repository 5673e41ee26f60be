// Every error of the service: the status code, a message naming the field and value, and no
// change to stored grids.
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::testing {
namespace {

using ::testing::HasSubstr;

// A status matcher: code and a message fragment.
class ServiceErrorsTest : public ServiceTest {
 protected:
  void SetUp() override {
    ServiceTest::SetUp();
    ImportShared("grids/n0012_113-33.p2dfmt", "naca");
    FitCounts("naca", 30, 12);
    before_ = client_->Get("naca", 0, v1::GRID_VIEW_FULL).value().SerializeAsString();
  }
  void TearDown() override {
    // Whatever failed, the stored grid is exactly as it was.
    EXPECT_EQ(client_->Get("naca", 0, v1::GRID_VIEW_FULL).value().SerializeAsString(), before_);
  }
  // Imports through the raw stream, so that malformed sequences can be sent.
  absl::Status RawImport(const std::vector<v1::ImportGridRequest>& messages) {
    grpc::ClientContext context;
    v1::Grid grid;
    auto writer = client_->stub().ImportGrid(&context, &grid);
    for (const auto& m : messages) {
      if (!writer->Write(m)) break;
    }
    writer->WritesDone();
    return client::FromGrpc(writer->Finish());
  }
  v1::ImportGridRequest PointsHeader(const std::string& id, int s, std::vector<Extents> blocks) {
    v1::ImportGridRequest r;
    r.mutable_header()->set_grid_id(id);
    r.mutable_header()->mutable_points()->set_spatial_dim(s);
    for (const Extents& e : blocks) {
      v1::Extents* x = r.mutable_header()->mutable_points()->add_blocks();
      x->set_i(e[0]);
      x->set_j(e[1]);
      x->set_k(e[2]);
    }
    return r;
  }
  v1::ImportGridRequest Points(int block, std::vector<double> values) {
    v1::ImportGridRequest r;
    r.mutable_points()->set_block(block);
    r.mutable_points()->mutable_coordinates()->Assign(values.begin(), values.end());
    return r;
  }
  std::string before_;
};

TEST_F(ServiceErrorsTest, UnknownGridIsNotFound) {
  v1::FitSpec spec;
  EXPECT_THAT(client_->Fit("nope", spec).status(),
              StatusIs(absl::StatusCode::kNotFound, "grids/nope not found"));
  EXPECT_THAT(client_->Get("nope").status(), StatusIs(absl::StatusCode::kNotFound, "grids/nope"));
  EXPECT_THAT(client_->Delete("nope"), StatusIs(absl::StatusCode::kNotFound, "grids/nope"));
  v1::EvaluateGridRequest eval;
  eval.set_name("nope");
  EXPECT_THAT(client_->Evaluate(eval).status(),
              StatusIs(absl::StatusCode::kNotFound, "grids/nope"));
  v1::EvaluatePointsRequest points;
  points.set_name("nope");
  EXPECT_THAT(client_->EvaluatePoints(points).status(),
              StatusIs(absl::StatusCode::kNotFound, "grids/nope"));
}

TEST_F(ServiceErrorsTest, MalformedNamesAreInvalid) {
  grpc::ClientContext context;
  v1::GetGridRequest request;
  request.set_name("naca");  // missing "grids/"
  v1::Grid grid;
  EXPECT_THAT(client::FromGrpc(client_->stub().GetGrid(&context, request, &grid)),
              StatusIs(absl::StatusCode::kInvalidArgument, "name = 'naca'"));
  EXPECT_THAT(client_->Get("grids/Bad_Id").status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "name = 'grids/Bad_Id'"));
}

TEST_F(ServiceErrorsTest, BadFitSpecsAreInvalid) {
  v1::FitSpec spec;
  spec.mutable_control_counts()->set_i(2);
  spec.mutable_control_counts()->set_j(12);
  spec.set_order(4);
  // Two controls are below the order (it is not lowered to 2), and one is below any order.
  EXPECT_THAT(client_->Fit("naca", spec).status(),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       "spec.control_counts[0] = 2 is below order = 4"));
  spec.mutable_control_counts()->set_i(1);
  EXPECT_THAT(client_->Fit("naca", spec).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "control_counts[0] = 1"));
  spec.mutable_control_counts()->set_i(500);
  spec.clear_block_control_counts();
  v1::BlockControlCounts* per_block = spec.add_block_control_counts();
  per_block->set_block(0);
  per_block->mutable_control_counts()->set_i(500);
  per_block->mutable_control_counts()->set_j(12);
  EXPECT_THAT(client_->Fit("naca", spec).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "control_counts[0] = 500"));
  per_block->set_block(7);
  EXPECT_THAT(client_->Fit("naca", spec).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "block_control_counts[0].block = 7"));
  v1::FitSpec tol;
  tol.set_tolerance(std::nan(""));
  EXPECT_THAT(client_->Fit("naca", tol).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "tolerance = nan"));
  tol.set_tolerance(-1e-3);
  EXPECT_THAT(client_->Fit("naca", tol).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "tolerance = -0.001"));
  v1::FitSpec order;
  order.set_order(11);
  EXPECT_THAT(client_->Fit("naca", order).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "order = 11"));
  v1::FitSpec negative;
  negative.mutable_control_counts()->set_j(-3);
  EXPECT_THAT(client_->Fit("naca", negative).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "control_counts.j = -3"));
}

TEST_F(ServiceErrorsTest, MalformedImportsAreInvalid) {
  // No header first.
  EXPECT_THAT(RawImport({Points(0, {1, 2})}),
              StatusIs(absl::StatusCode::kInvalidArgument, "first message"));
  // Bad id, bad spatial dimension, no blocks, absurd extents.
  EXPECT_THAT(RawImport({PointsHeader("9lives", 3, {{2, 2, 1}})}),
              StatusIs(absl::StatusCode::kInvalidArgument, "grid_id = '9lives'"));
  EXPECT_THAT(RawImport({PointsHeader("g", 4, {{2, 2, 1}})}),
              StatusIs(absl::StatusCode::kInvalidArgument, "spatial_dim = 4"));
  EXPECT_THAT(RawImport({PointsHeader("g", 3, {})}),
              StatusIs(absl::StatusCode::kInvalidArgument, "blocks is empty"));
  EXPECT_THAT(RawImport({PointsHeader("g", 3, {{-2, 2, 1}})}),
              StatusIs(absl::StatusCode::kInvalidArgument, "blocks[0]: ni = -2"));
  EXPECT_THAT(RawImport({PointsHeader("g", 3, {{100000, 100000, 100000}})}),
              StatusIs(absl::StatusCode::kInvalidArgument, "exceeds the limit"));
  // Wrong sizes: too many values, too few, unknown block.
  EXPECT_THAT(RawImport({PointsHeader("g", 2, {{2, 2, 1}}), Points(0, std::vector<double>(10))}),
              StatusIs(absl::StatusCode::kInvalidArgument, "more than its 8 coordinates"));
  EXPECT_THAT(RawImport({PointsHeader("g", 2, {{2, 2, 1}}), Points(0, {1, 2, 3})}),
              StatusIs(absl::StatusCode::kInvalidArgument, "received 3 of its 8"));
  EXPECT_THAT(RawImport({PointsHeader("g", 2, {{2, 2, 1}}), Points(1, {1, 2})}),
              StatusIs(absl::StatusCode::kInvalidArgument, "points.block = 1"));
  // NaN and Inf coordinates name the point.
  EXPECT_THAT(RawImport({PointsHeader("g", 2, {{2, 2, 1}}),
                         Points(0, {0, 0, 1, 0, 0, std::nan(""), 1, 1})}),
              StatusIs(absl::StatusCode::kInvalidArgument, "point (0, 1, 0) coordinate y is nan"));
  EXPECT_THAT(
      RawImport({PointsHeader("g", 2, {{2, 2, 1}}), Points(0, {0, 0, 1, 0, 0, 1, INFINITY, 1})}),
      StatusIs(absl::StatusCode::kInvalidArgument, "coordinate x is inf"));
  // Bad Plot3D bytes.
  EXPECT_THAT(client_->ImportPlot3d("1\n3 3\n1 2 3 four\n", "g", "", false).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "plot3d"));
  EXPECT_THAT(client_->ImportPlot3d("1\n2 2\n0 1 0 1 0 0 1 1\n", "g", "", /*planar=*/true).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, ""));
  // Two ways of asking for the planar view at once: refused before any byte is sent.
  v1::Plot3dSource both;
  both.set_planar_view(true);
  both.set_planar_view_if_two_planes(true);
  EXPECT_THAT(client_->ImportPlot3d("1\n2 2\n0 1 0 1 0 0 1 1\n", "g", "", both).status(),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       "header.plot3d.planar_view and header.plot3d.planar_view_if_two_planes"));
  // Announced size not matched.
  v1::ImportGridRequest header;
  header.mutable_header()->set_grid_id("g");
  header.mutable_header()->mutable_plot3d()->set_total_bytes(100);
  v1::ImportGridRequest chunk;
  chunk.set_plot3d_chunk("1\n2 2\n");
  EXPECT_THAT(RawImport({header, chunk}),
              StatusIs(absl::StatusCode::kInvalidArgument, "6 bytes arrived"));
  // The id is taken.
  EXPECT_THAT(client_->ImportPlot3d("1\n2 2\n0 1 0 1 0 0 1 1\n", "naca", "", false).status(),
              StatusIs(absl::StatusCode::kAlreadyExists, "grids/naca"));
  // Nothing of the failed imports was stored.
  EXPECT_EQ(client_->List().value().size(), 1u);
}

TEST_F(ServiceErrorsTest, BadEvaluationsAreRejected) {
  v1::EvaluateGridRequest request;
  request.set_name("naca");
  request.set_refinement_level(-1);
  EXPECT_THAT(client_->Evaluate(request).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "refinement_level = -1"));
  request.set_refinement_level(21);
  EXPECT_THAT(client_->Evaluate(request).status(),
              StatusIs(absl::StatusCode::kOutOfRange, "refinement_level = 21"));
  // Over the server's cap (default 2^30 points): 113 x 33 at level 12.
  request.set_refinement_level(12);
  EXPECT_THAT(client_->Evaluate(request).status(),
              StatusIs(absl::StatusCode::kOutOfRange,
                       "gives 60130131969 points in all 1 requested blocks, more than the server's cap of "
                       "1073741824"));
  request.set_refinement_level(0);
  request.add_blocks(3);
  EXPECT_THAT(client_->Evaluate(request).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "blocks[0] = 3"));
  request.set_blocks(0, 0);
  request.add_blocks(0);
  EXPECT_THAT(client_->Evaluate(request).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "blocks[1] = 0 is repeated"));
  request.clear_blocks();
  request.mutable_index_box()->mutable_end()->set_i(200);
  EXPECT_THAT(client_->Evaluate(request).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "index_box i = [0, 200]"));
  request.clear_index_box();
  request.mutable_counts()->set_i(10);
  request.mutable_counts()->set_j(0);
  EXPECT_THAT(client_->Evaluate(request).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "counts.j = 0"));
  request.set_revision(9);
  request.mutable_counts()->set_j(10);
  request.mutable_counts()->set_k(1);
  EXPECT_THAT(client_->Evaluate(request).status(),
              StatusIs(absl::StatusCode::kNotFound, "no revision 9"));

  v1::EvaluatePointsRequest points;
  points.set_name("naca");
  points.add_blocks(0);
  points.add_parameters(0.5);
  points.add_parameters(0.5);
  EXPECT_THAT(client_->EvaluatePoints(points).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "not a multiple of 3"));
  points.add_parameters(1.5);
  EXPECT_THAT(client_->EvaluatePoints(points).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "parameters[2] (w of point 0) = 1.5"));
  points.set_parameters(2, std::nan(""));
  EXPECT_THAT(client_->EvaluatePoints(points).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "= nan"));
  points.set_parameters(2, 0.0);
  points.set_blocks(0, 2);
  EXPECT_THAT(client_->EvaluatePoints(points).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "blocks[0] = 2"));
}

// Every call that names a revision resolves it in one place (StoredGrid::ResolveRevision): a
// negative one is INVALID_ARGUMENT naming the field, an absent one NOT_FOUND, in every call.
TEST_F(ServiceErrorsTest, RevisionsResolveAlikeInEveryCall) {
  std::vector<std::pair<std::string, absl::Status>> negative, absent;
  for (int64_t revision : {-1, 9}) {
    auto& out = revision < 0 ? negative : absent;
    v1::EvaluateGridRequest grid;
    grid.set_name("naca");
    grid.set_revision(revision);
    out.emplace_back("EvaluateGrid", client_->Evaluate(grid).status());
    v1::EvaluatePointsRequest points;
    points.set_name("naca");
    points.set_revision(revision);
    points.add_blocks(0);
    for (int c = 0; c < 3; ++c) points.add_parameters(0.5);
    out.emplace_back("EvaluatePoints", client_->EvaluatePoints(points).status());
    out.emplace_back("GetGrid", client_->Get("naca", revision).status());
    out.emplace_back("FairGrid", client_->Fair("naca", revision).status());
    out.emplace_back("GetWallCurvature", client_->WallCurvature("naca", revision, 0).status());
    v1::DeformGridRequest deform;
    deform.set_name("naca");
    deform.set_reference_revision(revision);
    deform.mutable_rigid()->set_angle_degrees(1.0);
    out.emplace_back("DeformGrid", client_->Deform(deform).status());
    v1::GenerateGridRequest generate;
    generate.set_grid_id("generated");
    generate.mutable_stored_wall()->set_name("grids/naca");
    generate.mutable_stored_wall()->set_revision(revision);
    out.emplace_back("GenerateGrid", client_->Generate(generate).status());
  }
  for (const auto& [call, status] : negative) {
    const std::string field = call == "DeformGrid"     ? "reference_revision = -1"
                              : call == "GenerateGrid" ? "stored_wall.revision = -1"
                                                       : "revision = -1";
    EXPECT_THAT(status, StatusIs(absl::StatusCode::kInvalidArgument, field + " is negative"))
        << call;
  }
  for (const auto& [call, status] : absent) {
    EXPECT_THAT(status, StatusIs(absl::StatusCode::kNotFound, "has no revision 9")) << call;
  }
  v1::DeformGridRequest stale_base;
  stale_base.set_name("naca");
  stale_base.set_base_revision(-2);
  stale_base.mutable_rigid()->set_angle_degrees(1.0);
  EXPECT_THAT(client_->Deform(stale_base).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "base_revision = -2 is negative"));
  // A negative time step is refused when stored and when looked up (it was stored as given,
  // and then could not be found by it).
  v1::DeformGridRequest negative_step;
  negative_step.set_name("naca");
  negative_step.set_step(-5);
  negative_step.mutable_rigid()->set_angle_degrees(1.0);
  EXPECT_THAT(client_->Deform(negative_step).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "step = -5 is negative"));
  v1::EvaluateGridRequest by_step;
  by_step.set_name("naca");
  by_step.set_step(-1);
  EXPECT_THAT(client_->Evaluate(by_step).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "step = -1 is negative"));
}

TEST_F(ServiceErrorsTest, UnfittedGridHasNoRevisionToEvaluate) {
  ImportShared("surfaces/even_sphere.fmt", "raw");
  v1::EvaluateGridRequest request;
  request.set_name("raw");
  EXPECT_THAT(client_->Evaluate(request).status(),
              StatusIs(absl::StatusCode::kFailedPrecondition, "FitGrid first"));
}

class SmallServerTest : public ServiceTest {
 protected:
  void SetUp() override {}
};

TEST_F(SmallServerTest, OverTheMemoryBudgetIsResourceExhausted) {
  options_.memory_budget_bytes = 400 << 10;  // 400 KiB: the 113x33 grid fits, 225x65 does not
  StartServer();
  ImportShared("grids/n0012_113-33.p2dfmt", "small");
  const std::string bytes = ReadFileToString(SharedDataPath("grids/n0012_225-65.p2dfmt")).value();
  EXPECT_THAT(client_->ImportPlot3d(bytes, "big", "", false).status(),
              StatusIs(absl::StatusCode::kResourceExhausted, "memory budget"));
  EXPECT_EQ(client_->List().value().size(), 1u);
}

TEST_F(SmallServerTest, OverTheOutputCapIsOutOfRange) {
  options_.max_output_points = 1000;
  StartServer();
  ImportShared("grids/n0012_113-33.p2dfmt", "g");
  FitCounts("g", 20, 10);
  v1::EvaluateGridRequest request;
  request.set_name("g");
  EXPECT_THAT(client_->Evaluate(request).status(),
              StatusIs(absl::StatusCode::kOutOfRange, "cap of 1000"));
  v1::EvaluatePointsRequest points;
  points.set_name("g");
  points.add_blocks(0);
  for (int p = 0; p < 1001; ++p) {
    points.add_parameters(0.5);
    points.add_parameters(0.5);
    points.add_parameters(0.0);
  }
  EXPECT_THAT(client_->EvaluatePoints(points).status(),
              StatusIs(absl::StatusCode::kOutOfRange, "1001 points"));
}

// A cancelled or expired EvaluateGrid stops its work promptly: the evaluation's reservation
// (held until the call is done) comes back within a moment.
TEST_F(SmallServerTest, CancelledOrExpiredEvaluationStopsPromptly) {
  options_.max_output_points = int64_t{1} << 32;
  StartServer();
  ImportShared("grids/n0012_225-65.p2dfmt", "g");
  FitCounts("g", 40, 20);
  const int64_t idle = server_->state().budget.used();
  v1::EvaluateGridRequest request;
  request.set_name("grids/g");
  request.set_refinement_level(7);  // 28673 x 8193 points: minutes of streaming
  {
    grpc::ClientContext context;
    auto reader = client_->stub().EvaluateGrid(&context, request);
    v1::EvaluateGridResponse message;
    for (int i = 0; i < 5; ++i) ASSERT_TRUE(reader->Read(&message));
    context.TryCancel();
    while (reader->Read(&message)) {
    }
    EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::CANCELLED);
  }
  EXPECT_TRUE(WaitForBudget(idle));
  {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(200));
    auto reader = client_->stub().EvaluateGrid(&context, request);
    v1::EvaluateGridResponse message;
    while (reader->Read(&message)) {
    }
    EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  }
  EXPECT_TRUE(WaitForBudget(idle));
  // The server still answers normally.
  EXPECT_TRUE(client_->Get("g").ok());
}

}  // namespace
}  // namespace splinegrid::testing
