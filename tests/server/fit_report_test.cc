// Fits to tolerances by boundary kind, their report, FairGrid and GetWallCurvature through the
// service, and the errors of those requests.
#include <cmath>

#include "gmock/gmock.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::testing {
namespace {

class FitReportTest : public ServiceTest {
 protected:
  void SetUp() override {
    ServiceTest::SetUp();
    ImportShared("grids/n0012_113-33.p2dfmt", "naca");
  }
  // The paper's tolerances (the spec's defaults).
  v1::FitGridResponse FitByKind() {
    v1::FitSpec spec;
    spec.mutable_boundary_tolerances();
    absl::StatusOr<v1::FitGridResponse> fit = client_->Fit("naca", spec);
    EXPECT_TRUE(fit.ok()) << fit.status();
    return fit.ok() ? *fit : v1::FitGridResponse();
  }
};

TEST_F(FitReportTest, FitByBoundaryKindMeetsEachKindsToleranceAndReportsIt) {
  const v1::FitGridResponse fit = FitByKind();
  const v1::FitReport& report = fit.report();
  EXPECT_TRUE(report.tolerance_met()) << report.unmet_reason();
  // The C-grid's wake cut is a match of the block with itself; fitted once, it is watertight.
  EXPECT_GE(report.num_matches(), 1);
  EXPECT_LT(report.max_gap(), 1e-12);
  EXPECT_EQ(report.folded_cells(), 0);
  EXPECT_GT(report.min_jacobian_ratio(), 0.0);
  EXPECT_EQ(report.wall_curvature().lines(), 1);  // the airfoil
  EXPECT_GT(report.wall_curvature().samples(), 4 * 50);
  ASSERT_EQ(fit.blocks_size(), 1);
  const v1::DeviationByKind& by_kind = fit.blocks(0).deviation_by_kind();
  ASSERT_TRUE(by_kind.has_wall() && by_kind.has_interface() && by_kind.has_outer());
  EXPECT_LE(by_kind.wall(), 0.15e-3);
  EXPECT_LE(by_kind.interface(), 2e-3);
  EXPECT_LE(by_kind.outer(), 8e-3);
  EXPECT_GT(fit.blocks(0).quality().cells_checked(), 32 * 112 * (1 + 4 + 16) / 2);
  EXPECT_GT(fit.compression_ratio(), 1.5);

  // The stored revision carries the same report, and the grid its connectivity.
  const v1::Grid grid = client_->Get("naca", 0, v1::GRID_VIEW_FULL).value();
  EXPECT_EQ(grid.revision().report().SerializeAsString(), report.SerializeAsString());
  EXPECT_EQ(grid.source().num_matches(), report.num_matches());
  ASSERT_EQ(grid.source().connectivity_size(), report.num_matches());
  const v1::BoundaryMatch& cut = grid.source().connectivity(0);
  EXPECT_EQ(cut.a().block(), 0);
  EXPECT_EQ(cut.b().block(), 0);
  EXPECT_EQ(cut.a().face(), v1::BLOCK_FACE_J_MIN);
  EXPECT_THAT(cut.description(), ::testing::HasSubstr("reversed"));
  // The basic view lists them too (a CGNS writer needs them without the nets: a large grid's
  // FULL view is over the message limit); a listing only counts them.
  const v1::Grid basic = client_->Get("naca").value();
  EXPECT_EQ(basic.source().num_matches(), report.num_matches());
  EXPECT_EQ(basic.source().connectivity_size(), report.num_matches());
  const std::vector<v1::Grid> listed = client_->List().value();
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_EQ(listed[0].source().num_matches(), report.num_matches());
  EXPECT_EQ(listed[0].source().connectivity_size(), 0);
}

TEST_F(FitReportTest, FairGridAddsAFairedRevisionWithinTheSameTolerances) {
  const v1::FitGridResponse fit = FitByKind();
  const v1::FitGridResponse faired = client_->Fair("naca", fit.revision()).value();
  EXPECT_EQ(faired.revision(), fit.revision() + 1);
  EXPECT_TRUE(faired.report().tolerance_met()) << faired.report().unmet_reason();
  EXPECT_LT(faired.report().max_gap(), 1e-12);
  // To tolerance: the same knots unfaired are reported for comparison.
  ASSERT_TRUE(faired.report().has_unfaired_wall_curvature());
  EXPECT_EQ(faired.report().unfaired_wall_curvature().samples(),
            faired.report().wall_curvature().samples());
  const v1::DeviationByKind& by_kind = faired.blocks(0).deviation_by_kind();
  EXPECT_LE(by_kind.wall(), 0.15e-3);
  EXPECT_LE(by_kind.outer(), 8e-3);
  const v1::Grid grid = client_->Get("naca").value();
  EXPECT_EQ(grid.revision().origin(), v1::REVISION_ORIGIN_FAIR);
  EXPECT_EQ(grid.revision().parent_revision(), fit.revision());
  EXPECT_EQ(grid.revision().fit_spec().fairing().mode(), v1::FAIRING_MODE_TO_TOLERANCE);
}

TEST_F(FitReportTest, FairGridOfACountsRevisionNeedsAWeight) {
  FitCounts("naca", 40, 16);
  EXPECT_THAT(client_->Fair("naca", 0).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "give a fairing weight"));
  v1::Fairing tolerance;
  tolerance.set_mode(v1::FAIRING_MODE_TO_TOLERANCE);
  EXPECT_THAT(client_->Fair("naca", 0, &tolerance).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "fairing to tolerance needs"));
  v1::Fairing weight;
  weight.set_mode(v1::FAIRING_MODE_WEIGHT);
  weight.set_weight(1e-3);
  const v1::FitGridResponse faired =
      client_->Fair("naca", 1, &weight, /*allow_folds=*/true).value();
  EXPECT_DOUBLE_EQ(faired.report().fairing_weight(), 1e-3);
  const v1::Grid grid = client_->Get("naca").value();
  EXPECT_EQ(grid.revision().fit_spec().fairing().mode(), v1::FAIRING_MODE_WEIGHT);
  EXPECT_DOUBLE_EQ(grid.revision().fit_spec().fairing().weight(), 1e-3);
  // Fairing changes the control points (same counts).
  const v1::Grid one = client_->Get("naca", 1, v1::GRID_VIEW_FULL).value();
  const v1::Grid two = client_->Get("naca", 2, v1::GRID_VIEW_FULL).value();
  ASSERT_EQ(one.revision().blocks(0).control_points_size(),
            two.revision().blocks(0).control_points_size());
  EXPECT_NE(one.revision().blocks(0).SerializeAsString(),
            two.revision().blocks(0).SerializeAsString());
}

TEST_F(FitReportTest, WallCurvatureSamplesEveryWallLine) {
  const v1::FitGridResponse fit = FitByKind();
  const v1::GetWallCurvatureResponse level2 = client_->WallCurvature("naca", 0, 2).value();
  EXPECT_EQ(level2.revision(), fit.revision());
  EXPECT_EQ(level2.spatial_dim(), 2);
  ASSERT_EQ(level2.lines_size(), 1);
  const v1::WallCurvatureLine& line = level2.lines(0);
  EXPECT_EQ(line.direction(), 0);
  const int samples = (line.length() - 1) * 4 + 1;
  EXPECT_EQ(line.curvature_size(), samples);
  EXPECT_EQ(line.arc_length_size(), samples);
  EXPECT_EQ(line.points_size(), 2 * samples);
  // The airfoil's arc length is a bit over two chords; the leading edge radius of a NACA 0012
  // is 0.0158 chords (|curvature| about 63 there).
  EXPECT_NEAR(line.arc_length(samples - 1), 2.03, 0.02);
  double largest = 0.0;
  for (double k : line.curvature()) largest = std::max(largest, std::abs(k));
  EXPECT_GT(largest, 40.0);
  EXPECT_EQ(level2.metrics().SerializeAsString(),
            fit.report().wall_curvature().SerializeAsString());
  const v1::GetWallCurvatureResponse level0 = client_->WallCurvature("naca", 0, 0).value();
  EXPECT_EQ(level0.lines(0).curvature_size(), line.length());
}

TEST_F(FitReportTest, BadRequestsNameTheFieldAndValue) {
  v1::FitSpec spec;
  spec.mutable_boundary_tolerances()->set_wall(-1.0);
  EXPECT_THAT(client_->Fit("naca", spec).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "spec.boundary_tolerances.wall = -1"));
  spec.mutable_boundary_tolerances()->set_wall(0.0);
  spec.mutable_boundary_tolerances()->set_edge(2.0);
  EXPECT_THAT(client_->Fit("naca", spec).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "spec.boundary_tolerances.edge = 2"));
  v1::FitSpec fairing;
  fairing.mutable_fairing()->set_mode(v1::FAIRING_MODE_WEIGHT);
  EXPECT_THAT(client_->Fit("naca", fairing).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "spec.fairing.weight = 0"));
  fairing.mutable_fairing()->set_weight(std::nan(""));
  EXPECT_THAT(client_->Fit("naca", fairing).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "spec.fairing.weight = nan"));
  fairing.mutable_fairing()->set_mode(v1::FAIRING_MODE_TO_TOLERANCE);
  fairing.mutable_fairing()->set_weight(0.0);
  EXPECT_THAT(client_->Fit("naca", fairing).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "fairing to tolerance needs"));
  v1::FitSpec kinds;
  kinds.mutable_boundary_tolerances();
  v1::FaceKind* face = kinds.add_face_kinds();
  face->set_block(0);
  face->set_face(static_cast<v1::BlockFace>(9));
  face->set_kind(v1::BOUNDARY_KIND_WALL);
  EXPECT_THAT(client_->Fit("naca", kinds).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "spec.face_kinds[0].face = 9"));
  face->set_face(v1::BLOCK_FACE_I_MIN);
  face->set_block(3);
  EXPECT_THAT(client_->Fit("naca", kinds).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "face_kinds: block 3"));

  // Not fitted yet; then bad levels and blocks.
  EXPECT_THAT(client_->WallCurvature("naca", 0, 2).status(),
              StatusIs(absl::StatusCode::kFailedPrecondition, "no revision yet"));
  EXPECT_THAT(client_->Fair("naca", 0).status(),
              StatusIs(absl::StatusCode::kFailedPrecondition, "no revision yet"));
  FitCounts("naca", 30, 12);
  EXPECT_THAT(client_->WallCurvature("naca", 0, 5).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "refinement_level = 5"));
  EXPECT_THAT(client_->WallCurvature("naca", 0, 2, {1}).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "blocks: 1"));
  EXPECT_THAT(client_->WallCurvature("naca", 7, 2).status(),
              StatusIs(absl::StatusCode::kNotFound, "no revision 7"));
  v1::Fairing off;
  off.set_mode(v1::FAIRING_MODE_OFF);
  EXPECT_THAT(client_->Fair("naca", 0, &off).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "fairing.mode = OFF"));
}

// A tolerance below what the control cap allows is reported, naming the boundary point that
// misses it; the revision is still stored (it is the best fit within the cap).
TEST_F(FitReportTest, AnImpossibleToleranceIsReportedNotLooped) {
  v1::FitSpec spec;
  spec.mutable_boundary_tolerances()->set_wall(1e-12);
  spec.set_max_controls_per_direction(20);
  spec.set_allow_folds(true);  // 20 controls fold the C-grid; the unmet tolerance is tested
  const v1::FitGridResponse fit = client_->Fit("naca", spec).value();
  EXPECT_FALSE(fit.report().tolerance_met());
  EXPECT_THAT(fit.report().unmet_reason(), ::testing::HasSubstr("wall point ("));
  EXPECT_THAT(fit.report().unmet_reason(), ::testing::HasSubstr("tolerance of 1e-12"));
  ASSERT_EQ(fit.blocks_size(), 1);
  EXPECT_FALSE(fit.blocks(0).tolerance_met());
  const v1::Grid grid = client_->Get("naca").value();
  EXPECT_LE(grid.revision().blocks(0).directions(0).num_controls(), 20);
}

// A tolerance double precision cannot resolve in the grid is refused, naming the field: a fit
// to 1e-300 was stored with every tolerance missed ("inf times its tolerance").
TEST_F(FitReportTest, AnUnresolvableToleranceIsRefused) {
  v1::FitSpec spec;
  spec.set_tolerance(1e-300);
  EXPECT_THAT(client_->Fit("naca", spec).status(),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       "tolerance = 1e-300 is below what double precision resolves in this grid"));
  v1::FitSpec relative;
  relative.mutable_boundary_tolerances();
  relative.set_reference_length(1e-300);
  EXPECT_THAT(
      client_->Fit("naca", relative).status(),
      StatusIs(absl::StatusCode::kInvalidArgument,
               "spec.boundary_tolerances.wall = 1.5e-304 (with the reference length 1e-300)"));
  EXPECT_EQ(client_->Get("naca").value().latest_revision(), 0);  // nothing stored
}

// A fit whose deadline passes stops at the next poll of the refinement loop: DEADLINE_EXCEEDED,
// no revision, the work's memory back, the server still answering.
TEST_F(FitReportTest, ALongFitHonoursItsDeadline) {
  ImportShared("grids/rae2822_257x97.fmt", "rae");
  const int64_t idle = server_->state().budget.used();
  v1::FitGridRequest request;
  request.set_name("grids/rae");
  request.mutable_spec()->mutable_boundary_tolerances();  // about a second of work
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(50));
  v1::FitGridResponse response;
  const auto start = std::chrono::steady_clock::now();
  const grpc::Status status = client_->stub().FitGrid(&context, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  EXPECT_TRUE(WaitForBudget(idle));
  EXPECT_LT(std::chrono::steady_clock::now() - start,
            std::chrono::milliseconds(1000));  // the whole fit takes ~1.5 s
  EXPECT_EQ(client_->Get("rae").value().latest_revision(), 0);
}

}  // namespace
}  // namespace splinegrid::testing
