// DeformGrid through the service: rigid pitching of a shared NACA 0012 grid as a coupled solver
// would drive it (revisions stamped with time and step, addressable by step), control
// displacements and boundary points, every error without side effects, concurrent writers, and
// the retention of deformed revisions.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <thread>

#include "absl/synchronization/notification.h"
#include "core/bspline/evaluation.h"
#include "core/io/planar_view.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "proto/convert/convert.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::testing {
namespace {

using ::testing::HasSubstr;

constexpr double kPi = 3.14159265358979323846;
constexpr double kWallTolerance = 1e-12;  // the moved wall is exact up to rounding

// A rigid pitch of the walls by `degrees` about the quarter chord, relative to revision 1.
v1::DeformGridRequest Pitch(const std::string& id, double degrees, int64_t step) {
  v1::DeformGridRequest r;
  r.set_name("grids/" + id);
  r.set_reference_revision(1);
  r.set_time(0.01 * step);
  r.set_step(step);
  r.set_check_level(1);
  r.mutable_rigid()->add_center(0.25);
  r.mutable_rigid()->add_center(0.0);
  r.mutable_rigid()->set_angle_degrees(degrees);
  return r;
}

// `request` (a Pitch) turned into a boundary-points motion of block 0's wall between the grid
// indices breaks[0] and breaks[1] at `level`: the range added, its coordinates to be given.
v1::BoundaryPointMotion* WallPoints(v1::DeformGridRequest& request, const std::vector<int>& breaks,
                                    int level) {
  request.clear_rigid();
  v1::BoundaryPointMotion* range = request.mutable_boundary_points()->add_ranges();
  range->mutable_range()->set_face(v1::BLOCK_FACE_J_MIN);
  range->mutable_range()->mutable_begin()->set_i(breaks[0]);
  range->mutable_range()->mutable_end()->set_i(breaks[1]);
  range->set_refinement_level(level);
  return range;
}

std::array<double, 2> Rotate(const double* x, double degrees) {
  const double a = degrees * kPi / 180.0, dx = x[0] - 0.25, dy = x[1];
  return {0.25 + std::cos(a) * dx - std::sin(a) * dy, std::sin(a) * dx + std::cos(a) * dy};
}

class DeformTest : public ServiceTest {
 protected:
  // Imports `file` (the planar view of a two-plane .fmt) as `id` and fits it to the default
  // tolerances by kind.
  void ImportAndFit(const std::string& file, const std::string& id) {
    ImportShared(file, id, /*planar=*/file.ends_with(".fmt"));
    v1::FitSpec spec;
    spec.mutable_boundary_tolerances();
    ASSERT_TRUE(client_->Fit(id, spec).ok());
  }
  // Block 0 of `revision` with its spline and point distribution.
  FittedBlock Block(const std::string& id, int64_t revision) {
    const v1::Grid grid = client_->Get(id, revision, v1::GRID_VIEW_FULL).value();
    return ParseSplineBlock(grid.revision().blocks(0)).value();
  }
  StructuredBlock Points(const std::string& id, int64_t revision) {
    v1::EvaluateGridRequest request;
    request.set_name("grids/" + id);
    request.set_revision(revision);
    request.set_refinement_level(0);
    return client_->Evaluate(request).value().blocks.at(0).points;
  }
};

TEST_F(DeformTest, RigidPitchingStepsAreStampedAddressableRevisions) {
  ImportAndFit("grids/n0012_pitch_257x129.fmt", "pitch");
  for (int step = 1; step <= 3; ++step) {
    const v1::DeformGridResponse r = client_->Deform(Pitch("pitch", 2.0 * step, step)).value();
    EXPECT_EQ(r.revision(), 1 + step);
    const v1::DeformReport& report = r.report();
    EXPECT_EQ(report.check_level(), 1);
    EXPECT_GT(report.cells_checked(), 257 * 129);
    EXPECT_GT(report.min_jacobian_ratio(), 0.5);  // no fold, no crushed cell
    EXPECT_LT(report.max_jacobian_ratio(), 2.0);
    EXPECT_GT(report.moved_controls(), 10);
    EXPECT_LT(report.max_orthogonality_change_degrees(), 1.0);
    EXPECT_GT(report.decay_radius(), 1.0);
  }
  const v1::Grid grid = client_->Get("pitch").value();
  ASSERT_EQ(grid.revisions_size(), 4);
  EXPECT_EQ(grid.latest_revision(), 4);
  for (int step = 1; step <= 3; ++step) {
    const v1::RevisionInfo& info = grid.revisions(step);
    EXPECT_EQ(info.revision(), 1 + step);
    EXPECT_EQ(info.origin(), v1::REVISION_ORIGIN_DEFORM);
    EXPECT_EQ(info.parent_revision(), 1);
    EXPECT_EQ(info.step(), step);
    EXPECT_DOUBLE_EQ(info.time(), 0.01 * step);
  }
  // Step 2 is revision 3, whichever way it is asked for.
  v1::GetGridRequest get;
  get.set_name("grids/pitch");
  get.set_step(2);
  v1::Grid by_step;
  {
    grpc::ClientContext context;
    ASSERT_TRUE(client_->stub().GetGrid(&context, get, &by_step).ok());
  }
  EXPECT_EQ(by_step.revision().revision(), 3);
  EXPECT_EQ(by_step.revision().origin(), v1::REVISION_ORIGIN_DEFORM);
  EXPECT_EQ(by_step.revision().step(), 2);
  EXPECT_GT(by_step.revision().deform_report().moved_controls(), 0);
  v1::EvaluatePointsRequest points;
  points.set_name("grids/pitch");
  points.set_step(2);
  points.add_blocks(0);
  for (double p : {0.5, 0.0, 0.0}) points.add_parameters(p);
  const v1::EvaluatePointsResponse at = client_->EvaluatePoints(points).value();
  EXPECT_EQ(at.revision(), 3);
  v1::EvaluateGridRequest eval;
  eval.set_name("pitch");
  eval.set_step(2);
  eval.set_refinement_level(0);
  EXPECT_EQ(client_->Evaluate(eval).value().revision, 3);

  // The wall of step 2 is the reference wall turned by 4 degrees; the far field stays.
  const std::vector<int> breaks = Block("pitch", 1).distribution.breaks(0);
  ASSERT_EQ(breaks.size(), 2u);  // the trailing-edge points of the C-grid
  const StructuredBlock reference = Points("pitch", 1), moved = Points("pitch", 3);
  const int ni = reference.extent(0), nj = reference.extent(1);
  for (int i = breaks[0]; i <= breaks[1]; ++i) {
    const std::array<double, 2> want = Rotate(reference.Point(i, 0, 0), 4.0);
    EXPECT_NEAR(moved.Point(i, 0, 0)[0], want[0], kWallTolerance) << "wall point " << i;
    EXPECT_NEAR(moved.Point(i, 0, 0)[1], want[1], kWallTolerance) << "wall point " << i;
  }
  EXPECT_NEAR(at.points(0), moved.Point((ni - 1) / 2, 0, 0)[0], 1e-3);  // the leading edge
  for (int i = 0; i < ni; ++i) {
    EXPECT_EQ(moved.Point(i, nj - 1, 0)[0], reference.Point(i, nj - 1, 0)[0]) << i;
    EXPECT_EQ(moved.Point(i, nj - 1, 0)[1], reference.Point(i, nj - 1, 0)[1]) << i;
  }
}

TEST_F(DeformTest, ControlDisplacementsAndBoundaryPointsMoveTheWall) {
  ImportAndFit("grids/n0012_pitch_257x129.fmt", "pitch");
  const FittedBlock reference = Block("pitch", 1);
  const Extents n = reference.spline.control_extents();
  // A bump on the controls around the leading edge (the middle of the C's wall row).
  v1::DeformGridRequest bump = Pitch("pitch", 0.0, 1);
  bump.clear_rigid();
  v1::ControlDisplacements* given = bump.mutable_controls()->add_blocks();
  for (int a = n[0] / 2 - 2; a <= n[0] / 2 + 2; ++a) {
    given->add_controls(a);  // row j = 0
    given->add_values(-1e-3);
    given->add_values(2e-3);
  }
  ASSERT_EQ(client_->Deform(bump).value().revision(), 2);
  const FittedBlock bumped = Block("pitch", 2);
  auto moved_by = [&](int a, int b, double dx, double dy) {
    const double* was = reference.spline.ControlPoint(a, b, 0);
    const double* now = bumped.spline.ControlPoint(a, b, 0);
    return std::abs(now[0] - was[0] - dx) < 1e-14 && std::abs(now[1] - was[1] - dy) < 1e-14;
  };
  // The listed controls move exactly as given; the far field and the outflow corners stay (the
  // wake cut's free controls follow the bump a little).
  for (int a = n[0] / 2 - 2; a <= n[0] / 2 + 2; ++a) EXPECT_TRUE(moved_by(a, 0, -1e-3, 2e-3)) << a;
  for (int a = 0; a < n[0]; ++a) EXPECT_TRUE(moved_by(a, n[1] - 1, 0.0, 0.0)) << a;
  EXPECT_TRUE(moved_by(0, 0, 0.0, 0.0));
  EXPECT_TRUE(moved_by(n[0] - 1, 0, 0.0, 0.0));

  // The wall's points at refinement level 1, turned by 3 degrees: the wall passes through them.
  const std::vector<int>& breaks = reference.distribution.breaks(0);
  const std::vector<double> u = reference.distribution.Refined(0, breaks[0], breaks[1], 1);
  v1::DeformGridRequest points = Pitch("pitch", 0.0, 2);
  v1::BoundaryPointMotion* range = WallPoints(points, breaks, 1);
  v1::EvaluatePointsRequest wall;
  wall.set_name("grids/pitch");
  wall.set_revision(3);
  wall.add_blocks(0);
  std::vector<std::array<double, 2>> want;
  for (double t : u) {
    const Point3 x = EvaluatePoint(reference.spline, {t, 0.0, 0.0});
    want.push_back(Rotate(x.data(), 3.0));
    range->add_coordinates(want.back()[0]);
    range->add_coordinates(want.back()[1]);
    for (double p : {t, 0.0, 0.0}) wall.add_parameters(p);
  }
  const v1::DeformGridResponse moved = client_->Deform(points).value();
  EXPECT_EQ(moved.revision(), 3);
  EXPECT_GT(moved.report().min_jacobian_ratio(), 0.0);
  EXPECT_LT(moved.report().boundary_error(), 1e-10);  // a turned wall is in its own basis
  const v1::EvaluatePointsResponse at = client_->EvaluatePoints(wall).value();
  ASSERT_EQ(at.points_size(), 2 * static_cast<int>(u.size()));
  for (size_t s = 0; s < u.size(); ++s) {
    EXPECT_NEAR(at.points(2 * s), want[s][0], 1e-10) << s;
    EXPECT_NEAR(at.points(2 * s + 1), want[s][1], 1e-10) << s;
  }
}

// Boundary points the wall's basis cannot follow (a bump of height 0.002 and width 0.02 chord,
// narrower than the wall's knot spans there) are refused by default, naming the point and the
// wall tolerance; allowed a larger miss, the deformation is stored and its report gives the
// miss, which equals the distance measured here from the evaluated wall. A trial's solver got
// OK for a wall 53% of the bump away from where it asked.
TEST_F(DeformTest, ABoundaryThatCannotFollowThePointsIsRefusedOrReported) {
  ImportAndFit("grids/n0012_pitch_257x129.fmt", "pitch");
  const FittedBlock reference = Block("pitch", 1);
  const std::vector<int>& breaks = reference.distribution.breaks(0);
  const std::vector<double> u = reference.distribution.Refined(0, breaks[0], breaks[1], 0);
  v1::DeformGridRequest bump = Pitch("pitch", 0.0, 1);
  v1::BoundaryPointMotion* range = WallPoints(bump, breaks, 0);
  range->set_displacements(true);
  std::vector<std::array<double, 2>> want;
  v1::EvaluatePointsRequest wall;
  wall.set_name("grids/pitch");
  wall.set_revision(2);
  wall.add_blocks(0);
  for (double t : u) {
    const Point3 x = EvaluatePoint(reference.spline, {t, 0.0, 0.0});
    const double dy = 0.002 * std::exp(-std::pow((x[0] - 0.5) / 0.02, 2));
    range->add_coordinates(0.0);
    range->add_coordinates(dy);
    want.push_back({x[0], x[1] + dy});
    for (double p : {t, 0.0, 0.0}) wall.add_parameters(p);
  }
  const absl::Status refused = client_->Deform(bump).status();
  EXPECT_EQ(refused.code(), absl::StatusCode::kFailedPrecondition) << refused;
  EXPECT_THAT(refused.message(), HasSubstr("the deformed boundary misses boundary_points[0] by "));
  EXPECT_THAT(refused.message(),
              HasSubstr("(the default: twice the fit's tolerance of the moved boundary's kind)"));
  EXPECT_EQ(client_->Get("pitch").value().latest_revision(), 1);

  bump.set_max_boundary_error(0.01);
  const v1::DeformGridResponse stored = client_->Deform(bump).value();
  EXPECT_EQ(stored.revision(), 2);
  const v1::EvaluatePointsResponse at = client_->EvaluatePoints(wall).value();
  double largest = 0.0;
  size_t worst = 0;
  for (size_t s = 0; s < want.size(); ++s) {
    const double d = std::hypot(at.points(2 * s) - want[s][0], at.points(2 * s + 1) - want[s][1]);
    if (d > largest) largest = d, worst = s;
  }
  EXPECT_GT(largest, 2e-4);  // the miss is real: a tenth of the bump or more
  EXPECT_NEAR(stored.report().boundary_error(), largest, 1e-12);
  // The refusal named that point: its grid index on the wall (j = 0) at level 0.
  EXPECT_THAT(refused.message(),
              HasSubstr(absl::StrCat("at point (", breaks[0] + static_cast<int>(worst),
                                     ", 0, 0) of block 0 at level 0")));
  bump.set_max_boundary_error(-1.0);
  EXPECT_THAT(client_->Deform(bump).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "max_boundary_error = -1"));

  // A solver sending its original wall nodes as positions is not refused for the fit's own
  // deviation from them: the default allows twice the wall tolerance.
  const MultiBlockGrid source =
      PlanarView(ReadPlot3dFile(SharedDataPath("grids/n0012_pitch_257x129.fmt")).value()).value();
  v1::DeformGridRequest nodes = Pitch("pitch", 0.0, 3);
  v1::BoundaryPointMotion* same = WallPoints(nodes, breaks, 0);
  for (int i = breaks[0]; i <= breaks[1]; ++i) {
    same->add_coordinates(source.blocks[0].Point(i, 0, 0)[0]);
    same->add_coordinates(source.blocks[0].Point(i, 0, 0)[1]);
  }
  const absl::StatusOr<v1::DeformGridResponse> unchanged = client_->Deform(nodes);
  ASSERT_TRUE(unchanged.ok()) << unchanged.status();
  EXPECT_GT(unchanged->report().boundary_error(), 0.0);  // the fit's deviation from its points
  const v1::Grid fitted = client_->Get("pitch", 1).value();
  EXPECT_LE(unchanged->report().boundary_error(),
            2.0 * fitted.revision().report().tolerances().wall());
}

// Every rejected deformation leaves the grid byte-identical, with no revision added.
class DeformErrorsTest : public DeformTest {
 protected:
  void SetUp() override {
    DeformTest::SetUp();
    ImportAndFit("grids/n0012_113-33.p2dfmt", "naca");
    before_ = client_->Get("naca", 0, v1::GRID_VIEW_FULL).value().SerializeAsString();
  }
  void TearDown() override {
    const v1::Grid after = client_->Get("naca", 0, v1::GRID_VIEW_FULL).value();
    EXPECT_EQ(after.latest_revision(), 1);
    EXPECT_EQ(after.SerializeAsString(), before_);
  }
  absl::Status Deform(const v1::DeformGridRequest& request) {
    return client_->Deform(request).status();
  }
  std::string before_;
};

TEST_F(DeformErrorsTest, MalformedRequestsAreInvalidArguments) {
  v1::DeformGridRequest unknown = Pitch("naca", 5.0, 1);
  v1::FaceRange* range = unknown.mutable_boundary()->add_ranges();
  range->set_block(3);
  range->set_face(v1::BLOCK_FACE_J_MIN);
  range->mutable_end()->set_i(5);
  EXPECT_THAT(Deform(unknown), StatusIs(absl::StatusCode::kInvalidArgument, "block 3"));
  EXPECT_THAT(Deform(Pitch("naca", std::nan(""), 1)),
              StatusIs(absl::StatusCode::kInvalidArgument, "angle_degrees = nan"));
  v1::DeformGridRequest centre = Pitch("naca", 1.0, 1);
  centre.mutable_rigid()->set_center(1, std::nan(""));
  EXPECT_THAT(Deform(centre),
              StatusIs(absl::StatusCode::kInvalidArgument, "rigid.center[1] = nan is not finite"));
  v1::DeformGridRequest counts = Pitch("naca", 0.0, 1);
  v1::ControlDisplacements* given = counts.mutable_controls()->add_blocks();
  given->add_controls(20);
  for (int c = 0; c < 3; ++c) given->add_values(0.0);
  EXPECT_THAT(Deform(counts), StatusIs(absl::StatusCode::kInvalidArgument, "3 values for 1"));
  v1::DeformGridRequest off = Pitch("naca", 0.0, 1);
  off.mutable_controls()->add_blocks()->add_controls(0);  // the outflow corner is fixed
  off.mutable_controls()->mutable_blocks(0)->add_values(0.1);
  off.mutable_controls()->mutable_blocks(0)->add_values(0.1);
  EXPECT_THAT(Deform(off),
              StatusIs(absl::StatusCode::kInvalidArgument, "does not carry the moved boundary"));
  v1::DeformGridRequest points = Pitch("naca", 0.0, 1);
  v1::BoundaryPointMotion* wall = points.mutable_boundary_points()->add_ranges();
  wall->mutable_range()->set_face(v1::BLOCK_FACE_J_MIN);
  wall->mutable_range()->mutable_begin()->set_i(50);
  wall->mutable_range()->mutable_end()->set_i(60);
  for (int c = 0; c < 7; ++c) wall->add_coordinates(0.0);
  EXPECT_THAT(Deform(points), StatusIs(absl::StatusCode::kInvalidArgument, "7 values for 11"));
  v1::DeformGridRequest unset = Pitch("naca", 0.0, 1);
  unset.clear_rigid();
  EXPECT_THAT(Deform(unset), StatusIs(absl::StatusCode::kInvalidArgument, "motion is unset"));
  v1::DeformGridRequest level = Pitch("naca", 1.0, 1);
  level.set_check_level(9);
  EXPECT_THAT(Deform(level), StatusIs(absl::StatusCode::kInvalidArgument, "check_level = 9"));
  v1::DeformGridRequest negative = Pitch("naca", 1.0, 1);
  negative.set_base_revision(-1);
  EXPECT_THAT(Deform(negative), StatusIs(absl::StatusCode::kInvalidArgument, "negative"));
  negative.set_base_revision(0);
  negative.set_reference_revision(-2);
  EXPECT_THAT(Deform(negative), StatusIs(absl::StatusCode::kInvalidArgument, "negative"));
  v1::DeformGridRequest missing = Pitch("naca", 1.0, 1);
  missing.set_reference_revision(7);
  EXPECT_THAT(Deform(missing), StatusIs(absl::StatusCode::kNotFound, "has no revision 7"));
  missing.set_name("grids/nothing");
  EXPECT_THAT(Deform(missing), StatusIs(absl::StatusCode::kNotFound, "grids/nothing"));
}

TEST_F(DeformErrorsTest, StaleBaseIsAbortedAndAFoldIsRefused) {
  v1::DeformGridRequest stale = Pitch("naca", 1.0, 1);
  stale.set_base_revision(5);
  // Ahead of the latest revision (1) is not "stale" (a trial read that): it is said as it is.
  EXPECT_THAT(Deform(stale),
              StatusIs(absl::StatusCode::kAborted,
                       "base_revision 5 is ahead of the grid (deleted and created again since, or "
                       "not a revision of it); the latest revision is 1"));
  // Everything a third of a chord away stays while the nose turns by 60 degrees: it tears.
  v1::DeformGridRequest fold = Pitch("naca", 60.0, 1);
  fold.set_decay_radius(0.3);
  EXPECT_THAT(Deform(fold), StatusIs(absl::StatusCode::kFailedPrecondition, "folds"));
  EXPECT_THAT(Deform(fold), StatusIs(absl::StatusCode::kFailedPrecondition, "at cell ("));
  EXPECT_THAT(Deform(fold), StatusIs(absl::StatusCode::kFailedPrecondition, "nothing was stored"));
  // Motions are relative to the reference revision: the advice says so.
  EXPECT_THAT(Deform(fold), StatusIs(absl::StatusCode::kFailedPrecondition,
                                     "move less relative to the reference revision"));
  // A whole turn leaves the wall where it was but winds the interior around it (a trial's
  // accumulating rotor angle): the advice names the reduced angle.
  EXPECT_THAT(Deform(Pitch("naca", 360.0, 1)),
              StatusIs(absl::StatusCode::kFailedPrecondition,
                       "a rotation by 360 degrees winds the interior around the body"));
  EXPECT_THAT(Deform(Pitch("naca", 360.0, 1)),
              StatusIs(absl::StatusCode::kFailedPrecondition, "reduced into [-180, 180]"));
}

TEST_F(DeformTest, ConcurrentWritersOnOneBaseOneWinsTheOtherIsAborted) {
  ImportAndFit("grids/n0012_113-33.p2dfmt", "naca");
  for (int round = 0; round < 4; ++round) {
    const int64_t base = 1 + round;
    absl::Status status[2];
    std::thread writers[2];
    for (int w = 0; w < 2; ++w) {
      writers[w] = std::thread([&, w] {
        v1::DeformGridRequest request = Pitch("naca", w ? 2.0 : -2.0, round);
        request.set_base_revision(base);
        status[w] = client_->Deform(request).status();
      });
    }
    for (std::thread& t : writers) t.join();
    EXPECT_EQ(status[0].ok() + status[1].ok(), 1) << status[0] << " / " << status[1];
    for (const absl::Status& s : status) {
      if (!s.ok()) {
        EXPECT_THAT(s, StatusIs(absl::StatusCode::kAborted, "is stale"));
      }
    }
    EXPECT_EQ(client_->Get("naca").value().latest_revision(), base + 1);
  }
}

// A deform whose deformer is not kept yet (a solver's first step, or every grid's first step on
// a replica after a failover) was long work and waited for the long workers, behind other
// principals' fits (a trial: 4.6 s instead of 1.5 ms). Once its grid is read it is sized: a small
// one runs as a slice while the long worker is busy; a large one still goes to the long workers.
TEST_F(DeformTest, AFirstSmallDeformDoesNotWaitForTheLongWorkers) {
  ImportAndFit("grids/n0012_113-33.p2dfmt", "naca");  // 112 x 32 cells
  // Hold the one long worker (2 threads) as another principal's fit would. The test reaches the
  // scheduler directly: no call of the API blocks on demand.
  absl::Notification started, release;
  auto& pool = const_cast<server::ServiceState&>(server_->state()).pool;
  ASSERT_TRUE(pool.TrySubmit("another", server::WorkKind::kLong,
                             [&] {
                               started.Notify();
                               release.WaitForNotification();
                             })
                  .ok());
  started.WaitForNotification();
  // Level 1: 14k cells to check, a small deformer: done while the long worker is held.
  const absl::StatusOr<v1::DeformGridResponse> small = client_->Deform(Pitch("naca", 2, 1));
  EXPECT_TRUE(small.ok()) << small.status();
  // Level 4: 918k cells, a large gate: it waits for the long worker.
  v1::DeformGridRequest large = Pitch("naca", 3, 2);
  large.set_check_level(4);
  absl::Notification large_done;
  std::thread deform([&] {
    EXPECT_TRUE(client_->Deform(large).ok());
    large_done.Notify();
  });
  EXPECT_FALSE(large_done.WaitForNotificationWithTimeout(absl::Milliseconds(300)));
  release.Notify();
  EXPECT_TRUE(large_done.WaitForNotificationWithTimeout(absl::Seconds(30)));
  deform.join();
}

// An archive's deformed revisions beyond the server's --keep_revisions are dropped when it is
// imported, and the import's reply says what was kept (it listed all of them, and the store
// kept them all until the next deform).
TEST_F(DeformTest, AnImportedArchiveKeepsWhatRetentionKeeps) {
  ImportAndFit("grids/n0012_113-33.p2dfmt", "naca");
  for (int step = 1; step <= 6; ++step)
    ASSERT_TRUE(client_->Deform(Pitch("naca", step, step)).ok());
  const std::string path =
      ::testing::TempDir() + "/retention-" + std::to_string(getpid()) + ".sgrid";
  ASSERT_TRUE(client_->ExportGrid("naca", path).ok());
  options_.max_deform_revisions = 2;
  StartServer();
  const absl::StatusOr<v1::Grid> imported = client_->ImportArchive(path, "copy");
  ASSERT_TRUE(imported.ok()) << imported.status();
  auto numbers = [](const v1::Grid& grid) {
    std::vector<int64_t> out;
    for (const v1::RevisionInfo& r : grid.revisions()) out.push_back(r.revision());
    return out;
  };
  EXPECT_THAT(numbers(*imported), ::testing::ElementsAre(1, 6, 7));
  EXPECT_THAT(numbers(client_->Get("copy").value()), ::testing::ElementsAre(1, 6, 7));
  std::remove(path.c_str());
}

TEST_F(DeformTest, RetentionKeepsTheFitAndTheNewestDeformedRevisions) {
  options_.max_deform_revisions = 3;
  StartServer();
  ImportAndFit("grids/n0012_113-33.p2dfmt", "naca");
  int64_t used_after_three = 0;
  for (int step = 1; step <= 6; ++step) {
    EXPECT_EQ(client_->Deform(Pitch("naca", step, step)).value().revision(), 1 + step);
    if (step == 3) used_after_three = server_->state().budget.used();
  }
  auto numbers = [&] {
    std::vector<int64_t> out;
    const v1::Grid grid = client_->Get("naca").value();
    for (const v1::RevisionInfo& r : grid.revisions()) out.push_back(r.revision());
    return out;
  };
  EXPECT_THAT(numbers(), ::testing::ElementsAre(1, 5, 6, 7));
  // The dropped revisions' memory is back in the budget.
  EXPECT_TRUE(WaitForBudget(used_after_three));
  EXPECT_THAT(client_->Get("naca", 3).status(),
              StatusIs(absl::StatusCode::kNotFound, "revision 3 was dropped by retention"));
  EXPECT_THAT(client_->Get("naca", 8).status(),
              StatusIs(absl::StatusCode::kNotFound, "has no revision 8"));
  v1::EvaluateGridRequest dropped_step;
  dropped_step.set_name("naca");
  dropped_step.set_step(1);
  dropped_step.set_refinement_level(0);
  EXPECT_THAT(client_->Evaluate(dropped_step).status(),
              StatusIs(absl::StatusCode::kNotFound, "dropped by retention"));
  // A step never stored is not blamed on retention.
  dropped_step.set_step(99);
  EXPECT_THAT(client_->Evaluate(dropped_step).status(),
              StatusIs(absl::StatusCode::kNotFound,
                       "has no revision of step 99 (the newest step stored is 6)"));
  // A faired revision is kept like the fit; numbers continue.
  v1::Fairing fairing;
  fairing.set_mode(v1::FAIRING_MODE_WEIGHT);
  fairing.set_weight(1e-6);
  EXPECT_EQ(client_->Fair("naca", 1, &fairing).value().revision(), 8);
  EXPECT_EQ(client_->Deform(Pitch("naca", 7.0, 7)).value().revision(), 9);
  EXPECT_THAT(numbers(), ::testing::ElementsAre(1, 6, 7, 8, 9));
  // Fairing refits the imported points: a deformed revision is refused, naming the fit the
  // deformations start from (it stored the undeformed grid as the latest revision), and so is
  // fairing a faired revision again as it was faired (it stored the same grid again).
  EXPECT_THAT(client_->Fair("naca", 0, &fairing).status(),
              StatusIs(absl::StatusCode::kFailedPrecondition,
                       "grids/naca revision 9 is deformed: FairGrid refits the grid's imported "
                       "points, which do not carry the deformation, so the faired grid would "
                       "undo it; fair revision 1"));
  EXPECT_THAT(
      client_->Fair("naca", 8, &fairing).status(),
      StatusIs(absl::StatusCode::kFailedPrecondition, "revision 8 is faired already, as asked"));
  EXPECT_THAT(numbers(), ::testing::ElementsAre(1, 6, 7, 8, 9));  // nothing stored
  // Steps 5, 6 and 7 are kept: a step between them that was never stored (a trial's step whose
  // deform failed) is not blamed on retention either.
  EXPECT_EQ(client_->Deform(Pitch("naca", 9.0, 9)).value().revision(), 10);
  dropped_step.set_step(8);
  EXPECT_THAT(client_->Evaluate(dropped_step).status(),
              StatusIs(absl::StatusCode::kNotFound,
                       "has no revision of step 8 (none was stored for it; the deformed "
                       "revisions kept range from step 6 to 9)"));
}

}  // namespace
}  // namespace splinegrid::testing
