// The stored revision format: bitwise round trips of real fits (planar C-grid and a 3D volume)
// through the wire, and hostile messages refused with the field named (revision_codec.h,
// archive_convert.h). The source points' chunks are in archive_codec_source_test.cc.
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <span>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/bspline/evaluation.h"
#include "core/fit/grid_fit.h"
#include "core/grid/sampling.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "proto/convert/archive_convert.h"
#include "server/store/revision_codec.h"
#include "tests/core/synthetic_grids.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::server {
namespace {

using ::splinegrid::testing::StatusIs;

// Same bits (so NaN payloads, -0 and infinities count, and 0 != -0).
bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

void ExpectSameDoubles(std::span<const double> a, std::span<const double> b,
                       const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0) << what;
}

#define EXPECT_SAME_BITS(a, b) EXPECT_TRUE(SameBits(a, b)) << #a << " = " << (a) << " vs " << (b)

void ExpectSameCellQuality(const CellQuality& a, const CellQuality& b) {
  EXPECT_EQ(a.cells_checked, b.cells_checked);
  EXPECT_EQ(a.cells_skipped, b.cells_skipped);
  EXPECT_EQ(a.folded, b.folded);
  EXPECT_EQ(a.out_of_size, b.out_of_size);
  EXPECT_SAME_BITS(a.min_ratio, b.min_ratio);
  EXPECT_SAME_BITS(a.max_ratio, b.max_ratio);
  EXPECT_EQ(a.worst_cell, b.worst_cell);
  EXPECT_EQ(a.worst_level, b.worst_level);
  EXPECT_EQ(a.num_bad_cells, b.num_bad_cells);
  EXPECT_EQ(a.bad_cells, b.bad_cells);
}

void ExpectSameBlock(const BlockFit& a, const BlockFit& b) {
  const TensorSpline &sa = a.fitted.spline, &sb = b.fitted.spline;
  EXPECT_EQ(sa.spatial_dim(), sb.spatial_dim());
  for (int d = 0; d < 3; ++d) {
    EXPECT_EQ(sa.knots(d).order(), sb.knots(d).order());
    ExpectSameDoubles(sa.knots(d).knots(), sb.knots(d).knots(), absl::StrCat("knots ", d));
    ExpectSameDoubles(a.fitted.distribution.params(d), b.fitted.distribution.params(d),
                      absl::StrCat("params ", d));
    EXPECT_EQ(a.fitted.distribution.breaks(d), b.fitted.distribution.breaks(d));
  }
  ExpectSameDoubles(sa.control(), sb.control(), "control net");
  const FitSummary &fa = a.fitted.summary, &fb = b.fitted.summary;
  EXPECT_SAME_BITS(fa.deviation.max, fb.deviation.max);
  EXPECT_SAME_BITS(fa.deviation.rms, fb.deviation.rms);
  EXPECT_EQ(fa.deviation.max_at, fb.deviation.max_at);
  EXPECT_EQ(fa.deviation.num_points, fb.deviation.num_points);
  EXPECT_SAME_BITS(fa.deviation.max_ratio, fb.deviation.max_ratio);
  EXPECT_EQ(fa.deviation.max_ratio_at, fb.deviation.max_ratio_at);
  EXPECT_EQ(fa.num_points, fb.num_points);
  EXPECT_EQ(fa.num_control_points, fb.num_control_points);
  EXPECT_SAME_BITS(fa.compression_ratio, fb.compression_ratio);
  EXPECT_SAME_BITS(fa.seconds, fb.seconds);
  EXPECT_EQ(a.tolerance_met, b.tolerance_met);
  EXPECT_EQ(a.unmet_reason, b.unmet_reason);
  EXPECT_SAME_BITS(a.deviation_by_kind.wall, b.deviation_by_kind.wall);
  EXPECT_SAME_BITS(a.deviation_by_kind.interface, b.deviation_by_kind.interface);
  EXPECT_SAME_BITS(a.deviation_by_kind.outer, b.deviation_by_kind.outer);
  EXPECT_SAME_BITS(a.deviation_by_kind.interior, b.deviation_by_kind.interior);
  EXPECT_SAME_BITS(a.deviation_by_kind.first_layer, b.deviation_by_kind.first_layer);
  ExpectSameCellQuality(a.quality, b.quality);
  // The mapping itself: evaluation at refinement level 1 gives the same bits.
  Resolution level1;
  level1.level = 1;
  const auto params = SampleParameters(a.fitted.distribution, level1).value();
  ExpectSameDoubles(EvaluateGrid(sa, params).coords(), EvaluateGrid(sb, params).coords(),
                    "evaluation at level 1");
}

void ExpectSameOptions(const GridFitOptions& a, const GridFitOptions& b) {
  EXPECT_EQ(a.order, b.order);
  EXPECT_EQ(a.parametrization, b.parametrization);
  ASSERT_EQ(a.tolerance.has_value(), b.tolerance.has_value());
  if (a.tolerance) {
    EXPECT_SAME_BITS(*a.tolerance, *b.tolerance);
  }
  ASSERT_EQ(a.boundary_tolerances.has_value(), b.boundary_tolerances.has_value());
  if (a.boundary_tolerances) {
    const BoundaryTolerances &ta = *a.boundary_tolerances, &tb = *b.boundary_tolerances;
    EXPECT_SAME_BITS(ta.wall, tb.wall);
    EXPECT_SAME_BITS(ta.interface, tb.interface);
    EXPECT_SAME_BITS(ta.outer, tb.outer);
    EXPECT_SAME_BITS(ta.interior, tb.interior);
    EXPECT_SAME_BITS(ta.edge, tb.edge);
    EXPECT_SAME_BITS(ta.first_layer, tb.first_layer);
  }
  EXPECT_EQ(a.control_counts, b.control_counts);
  EXPECT_EQ(a.block_control_counts, b.block_control_counts);
  EXPECT_EQ(a.max_controls_per_direction, b.max_controls_per_direction);
  EXPECT_EQ(a.fairing.mode, b.fairing.mode);
  EXPECT_SAME_BITS(a.fairing.weight, b.fairing.weight);
  ASSERT_EQ(a.face_kinds.size(), b.face_kinds.size());
  for (size_t q = 0; q < a.face_kinds.size(); ++q) {
    EXPECT_EQ(a.face_kinds[q].face, b.face_kinds[q].face);
    EXPECT_EQ(a.face_kinds[q].kind, b.face_kinds[q].kind);
  }
  EXPECT_EQ(a.check_quality, b.check_quality);
}

void ExpectSameCurvature(const CurvatureMetrics& a, const CurvatureMetrics& b) {
  EXPECT_EQ(a.lines, b.lines);
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.extrema, b.extrema);
  EXPECT_SAME_BITS(a.sum_squared_differences, b.sum_squared_differences);
  EXPECT_SAME_BITS(a.max_abs_curvature, b.max_abs_curvature);
}

void ExpectSameReport(const GridFitReport& a, const GridFitReport& b) {
  EXPECT_EQ(a.num_points, b.num_points);
  EXPECT_EQ(a.num_control_points, b.num_control_points);
  EXPECT_SAME_BITS(a.max_deviation, b.max_deviation);
  EXPECT_EQ(a.tolerance_met, b.tolerance_met);
  EXPECT_EQ(a.unmet_reason, b.unmet_reason);
  EXPECT_EQ(a.quality_met, b.quality_met);
  EXPECT_EQ(a.num_matches, b.num_matches);
  EXPECT_SAME_BITS(a.max_gap, b.max_gap);
  EXPECT_SAME_BITS(a.fairing_weight, b.fairing_weight);
  ExpectSameCurvature(a.wall_curvature, b.wall_curvature);
  ExpectSameCurvature(a.unfaired_wall_curvature, b.unfaired_wall_curvature);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.knots_inserted, b.knots_inserted);
  EXPECT_EQ(a.knots_removed, b.knots_removed);
  EXPECT_EQ(a.quality_rounds, b.quality_rounds);
  EXPECT_SAME_BITS(a.seconds, b.seconds);
}

void ExpectSameRevision(const GridRevision& a, const GridRevision& b) {
  EXPECT_EQ(a.number, b.number);
  EXPECT_EQ(a.create_time, b.create_time);
  EXPECT_EQ(a.origin, b.origin);
  ExpectSameOptions(a.fit_options, b.fit_options);
  EXPECT_EQ(a.parent, b.parent);
  EXPECT_SAME_BITS(a.time, b.time);
  EXPECT_EQ(a.step, b.step);
  const DeformationCheck &ca = a.deform.check, &cb = b.deform.check;
  EXPECT_EQ(ca.level, cb.level);
  EXPECT_EQ(ca.cells_checked, cb.cells_checked);
  EXPECT_EQ(ca.folded, cb.folded);
  EXPECT_SAME_BITS(ca.min_jacobian_ratio, cb.min_jacobian_ratio);
  EXPECT_SAME_BITS(ca.max_jacobian_ratio, cb.max_jacobian_ratio);
  EXPECT_EQ(ca.worst_block, cb.worst_block);
  EXPECT_EQ(ca.worst_cell, cb.worst_cell);
  EXPECT_SAME_BITS(ca.max_orthogonality_change_degrees, cb.max_orthogonality_change_degrees);
  EXPECT_EQ(ca.wall_samples, cb.wall_samples);
  EXPECT_EQ(a.deform.moved_controls, b.deform.moved_controls);
  EXPECT_SAME_BITS(a.deform.decay_radius, b.deform.decay_radius);
  EXPECT_SAME_BITS(a.deform.seconds, b.deform.seconds);
  ASSERT_EQ(a.blocks.size(), b.blocks.size());
  for (size_t i = 0; i < a.blocks.size(); ++i) {
    SCOPED_TRACE(absl::StrCat("block ", i));
    ExpectSameBlock(a.blocks[i], b.blocks[i]);
  }
  EXPECT_EQ(a.kinds.point_kinds, b.kinds.point_kinds);
  EXPECT_EQ(a.kinds.face_kinds, b.kinds.face_kinds);
  ExpectSameReport(a.report, b.report);
  EXPECT_EQ(b.memory.bytes(), 0);  // not stored: the loader reserves
}

// Encode, serialise, parse the bytes, Parse: what a store or an export file does.
absl::StatusOr<GridRevision> ThroughTheWire(const GridRevision& revision) {
  v1::StoredRevision stored;
  EncodeRevision(revision, &stored);
  std::string bytes;
  EXPECT_TRUE(stored.SerializeToString(&bytes));
  v1::StoredRevision read;
  EXPECT_TRUE(read.ParseFromString(bytes));
  absl::StatusOr<GridRevision> parsed = ParseRevision(read);
  if (parsed.ok()) {  // and once more: the encoding of the parsed revision is the same bytes
    v1::StoredRevision again;
    EncodeRevision(*parsed, &again);
    EXPECT_EQ(again.SerializeAsString(), bytes);
  }
  return parsed;
}

// A revision of `fit` with everything set that a fitted revision has.
GridRevision MakeRevision(GridFit fit, const GridFitOptions& options, int64_t number) {
  GridRevision revision;
  revision.number = number;
  revision.create_time = absl::FromUnixNanos(1732400000123456789);
  revision.origin = RevisionOrigin::kFit;
  revision.fit_options = options;
  revision.blocks = std::move(fit.blocks);
  revision.kinds = std::move(fit.kinds);
  revision.report = fit.report;
  return revision;
}

// The NACA 0012 C-grid (225 x 65), fitted to boundary tolerances once for the suite.
class ArchiveCodecTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    grid_ = new MultiBlockGrid(ReadPlot3dFile(SharedDataPath("grids/n0012_225-65.p2dfmt")).value());
    options_ = new GridFitOptions();
    BoundaryTolerances tolerances;  // interior stays +infinity: a sentinel that must survive
    tolerances.wall = 1e-3;
    tolerances.interface = 1e-2;
    tolerances.outer = 5e-2;
    tolerances.first_layer = 0.3;  // held, so that the tolerances' field is stored too
    options_->boundary_tolerances = tolerances;
    options_->max_controls_per_direction = 120;
    fit_ = new GridFit(FitGrid(*grid_, *options_).value());
  }
  static void TearDownTestSuite() {
    delete fit_;
    delete options_;
    delete grid_;
  }

  static GridRevision Fitted() { return MakeRevision(*fit_, *options_, 3); }
  static v1::StoredRevision Stored() {
    v1::StoredRevision stored;
    EncodeRevision(Fitted(), &stored);
    return stored;
  }

  static MultiBlockGrid* grid_;
  static GridFitOptions* options_;
  static GridFit* fit_;
};
MultiBlockGrid* ArchiveCodecTest::grid_ = nullptr;
GridFitOptions* ArchiveCodecTest::options_ = nullptr;
GridFit* ArchiveCodecTest::fit_ = nullptr;

TEST_F(ArchiveCodecTest, FittedRevisionRoundTripsBitwise) {
  const GridRevision revision = Fitted();
  ASSERT_GT(revision.report.knots_inserted + revision.report.iterations, 0);
  ASSERT_TRUE(std::isinf(revision.fit_options.boundary_tolerances->interior));
  absl::StatusOr<GridRevision> parsed = ThroughTheWire(revision);
  ASSERT_TRUE(parsed.ok()) << parsed.status();
  ExpectSameRevision(revision, *parsed);
  EXPECT_TRUE(CheckRevisionMatchesSource(*parsed, *grid_).ok());
  EXPECT_GT(parsed->blocks[0].deviation_by_kind.first_layer, 0.0);
  EXPECT_EQ(parsed->fit_options.boundary_tolerances->first_layer, 0.3);
  // An archive from before the first layer was measured or held: not measured (-1), not held.
  v1::StoredRevision old = Stored();
  for (v1::StoredBlockFit& block : *old.mutable_blocks()) {
    block.mutable_deviation_by_kind()->clear_first_layer();
  }
  old.mutable_fit_options()->mutable_boundary_tolerances()->clear_first_layer();
  old.mutable_report()->mutable_tolerances()->clear_first_layer();
  absl::StatusOr<GridRevision> before = ParseRevision(old);
  ASSERT_TRUE(before.ok()) << before.status();
  EXPECT_EQ(before->blocks[0].deviation_by_kind.first_layer, -1.0);
  EXPECT_EQ(before->fit_options.boundary_tolerances->first_layer, 0.0);
  EXPECT_EQ(before->report.tolerances->first_layer, 0.0);
  EXPECT_EQ(parsed->report.tolerances->first_layer, 0.3);
}

// A deformed revision: parent, time, step, the gate's summary with an infinite decay radius,
// and options that use every field (control counts, overrides, weight fairing, face kinds).
TEST_F(ArchiveCodecTest, DeformedRevisionWithInfiniteDecayRoundTripsBitwise) {
  GridRevision revision = Fitted();
  revision.number = 7;
  revision.origin = RevisionOrigin::kDeform;
  revision.parent = 3;
  revision.time = 0.125;
  revision.step = 42;
  revision.create_time = absl::FromUnixNanos(-1);  // before 1970: nanos stay non-negative
  GridFitOptions& options = revision.fit_options;
  options.order = 5;
  options.parametrization = Parametrization::kCentripetal;
  options.boundary_tolerances.reset();
  options.control_counts = {40, 0, 1};
  options.block_control_counts = {{0, {30, 20, 1}}};
  options.fairing = {FairingMode::kWeight, 7.5};
  options.face_kinds = {{Face{0, 1, true}, BoundaryKind::kOuter}};
  options.check_quality = false;
  DeformSummary& deform = revision.deform;
  deform.check.level = 2;
  deform.check.cells_checked = 57600;
  deform.check.min_jacobian_ratio = 0.8125;
  deform.check.max_jacobian_ratio = 1.25;
  deform.check.worst_block = 0;
  deform.check.worst_cell = {17, 3, 0};
  deform.check.max_orthogonality_change_degrees = 1.5;
  deform.check.wall_samples = 513;
  deform.moved_controls = 99;
  deform.decay_radius = std::numeric_limits<double>::infinity();
  deform.seconds = -std::numeric_limits<double>::quiet_NaN();  // reported: any bits survive
  revision.report.max_gap = -0.0;
  absl::StatusOr<GridRevision> parsed = ThroughTheWire(revision);
  ASSERT_TRUE(parsed.ok()) << parsed.status();
  ExpectSameRevision(revision, *parsed);
  EXPECT_TRUE(std::isinf(parsed->deform.decay_radius));
}

// Tolerance mode with one tolerance, faired to tolerance, and a 3D volume in two blocks whose
// shared face is permuted and reversed (SplitBox).
TEST_F(ArchiveCodecTest, VolumeRevisionRoundTripsBitwise) {
  const MultiBlockGrid box = SplitBox(7);
  GridFitOptions options;
  options.tolerance = 2e-3;
  options.fairing = {FairingMode::kToTolerance, 100.0};
  absl::StatusOr<GridFit> fit = FitGrid(box, options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  ASSERT_EQ(fit->blocks[0].fitted.spline.active_directions(), 3);
  const GridRevision revision = MakeRevision(*std::move(fit), options, 1);
  absl::StatusOr<GridRevision> parsed = ThroughTheWire(revision);
  ASSERT_TRUE(parsed.ok()) << parsed.status();
  ExpectSameRevision(revision, *parsed);
  EXPECT_TRUE(CheckRevisionMatchesSource(*parsed, box).ok());
  // Against another grid: refused, naming the block.
  EXPECT_THAT(CheckRevisionMatchesSource(*parsed, SplitBox(6)),
              StatusIs(absl::StatusCode::kInvalidArgument, "block 0: 7 x 7 x 7 points"));
}

TEST_F(ArchiveCodecTest, ConnectivityRoundTripsAndIsCheckedAgainstTheBlocks) {
  for (const MultiBlockGrid& grid : {*grid_, SplitBox(5), SideBySide(5, 0.0, 9, true)}) {
    const Connectivity connectivity = FindConnectivity(grid).value();
    ASSERT_FALSE(connectivity.matches.empty());
    v1::StoredConnectivity stored;
    EncodeStoredConnectivity(connectivity, &stored);
    absl::StatusOr<Connectivity> parsed = ParseStoredConnectivity(stored, grid);
    ASSERT_TRUE(parsed.ok()) << parsed.status();
    ASSERT_EQ(parsed->matches.size(), connectivity.matches.size());
    for (size_t m = 0; m < connectivity.matches.size(); ++m) {
      EXPECT_EQ(parsed->matches[m].Describe(), connectivity.matches[m].Describe());
      EXPECT_EQ(parsed->matches[m].a.face, connectivity.matches[m].a.face);
      EXPECT_EQ(parsed->matches[m].b_direction, connectivity.matches[m].b_direction);
      EXPECT_EQ(parsed->matches[m].reversed, connectivity.matches[m].reversed);
      EXPECT_EQ(parsed->matches[m].step, connectivity.matches[m].step);
    }
  }
  v1::StoredConnectivity stored;
  EncodeStoredConnectivity(FindConnectivity(*grid_).value(), &stored);
  struct Case {
    std::function<void(v1::BoundaryMatch&)> corrupt;
    std::string message;
  };
  const std::vector<Case> cases = {
      {[](v1::BoundaryMatch& m) { m.mutable_b()->set_block(5); },
       "header.connectivity.matches[0].b.block = 5 is outside [0, 0]"},
      {[](v1::BoundaryMatch& m) { m.mutable_a()->mutable_end()->set_i(225); },
       "matches[0].a: i range"},
      {[](v1::BoundaryMatch& m) { m.mutable_a()->set_face(v1::BLOCK_FACE_K_MIN); },
       "matches[0].a.face: block 0 has one point in direction k"},
      {[](v1::BoundaryMatch& m) { m.mutable_a()->set_face(static_cast<v1::BlockFace>(9)); },
       "matches[0].a.face = 9"},
      {[](v1::BoundaryMatch& m) { m.set_b_direction(0, 7); },
       "matches[0].b_direction[0] = 7 is outside [-1, 2]"},
      {[](v1::BoundaryMatch& m) { m.set_b_direction(0, -1); },
       "matches[0].b_direction[0] = -1, but range a extends along i"},
      {[](v1::BoundaryMatch& m) { m.set_step(3); }, "matches[0].step = 3"},
      {[](v1::BoundaryMatch& m) { m.set_step(2); }, "matches[0].b_direction[0] = 0: range b spans"},
      {[](v1::BoundaryMatch& m) { m.mutable_reversed()->RemoveLast(); }, "exactly 3 of each"},
  };
  for (const Case& c : cases) {
    v1::StoredConnectivity bad = stored;
    c.corrupt(*bad.mutable_matches(0));
    EXPECT_THAT(ParseStoredConnectivity(bad, *grid_).status(),
                StatusIs(absl::StatusCode::kInvalidArgument, c.message));
  }
}

// A dozen and more corruptions of a real stored revision: each is INVALID_ARGUMENT naming the
// field, never a crash.
TEST_F(ArchiveCodecTest, HostileRevisionsAreRefusedNamingTheField) {
  const v1::StoredRevision good = Stored();
  ASSERT_TRUE(ParseRevision(good).ok());
  const int order = good.blocks(0).spline().knots(0).order();
  const int num_knots = good.blocks(0).spline().knots(0).knots_size();
  struct Case {
    std::function<void(v1::StoredRevision&)> corrupt;
    std::string message;
  };
  const std::vector<Case> cases = {
      {[](v1::StoredRevision& r) {
         r.mutable_blocks(0)->mutable_spline()->mutable_control()->RemoveLast();
       },
       "revision.blocks[0].spline.control: "},
      {[](v1::StoredRevision& r) { r.mutable_blocks(0)->mutable_spline()->add_control(1.0); },
       "revision.blocks[0].spline.control: "},
      {[=](v1::StoredRevision& r) {  // an interior knot below its predecessor
         auto* knots = r.mutable_blocks(0)->mutable_spline()->mutable_knots(1)->mutable_knots();
         knots->Set(order + 1, knots->Get(order) - 1e-3);
       },
       "revision.blocks[0].spline.knots[1]: knots["},
      {[](v1::StoredRevision& r) {
         r.mutable_blocks(0)->mutable_spline()->set_control(5, std::nan(""));
       },
       "revision.blocks[0].spline: control[5] = nan is not finite"},
      {[](v1::StoredRevision& r) {
         r.mutable_blocks(0)->mutable_spline()->mutable_knots(0)->set_order(0);
       },
       "revision.blocks[0].spline.knots[0]: order = 0 is outside [1, 10]"},
      {[=](v1::StoredRevision& r) {  // more order than knots allow
         r.mutable_blocks(0)->mutable_spline()->mutable_knots(0)->set_order(num_knots / 2 + 1);
       },
       "revision.blocks[0].spline.knots[0]: "},
      {[](v1::StoredRevision& r) {  // a valid knot vector on [0, 2]
         for (double& t :
              *r.mutable_blocks(0)->mutable_spline()->mutable_knots(0)->mutable_knots()) {
           t *= 2.0;
         }
       },
       "revision.blocks[0].spline.knots[0]: the domain [0, 2] is not [0, 1]"},
      {[](v1::StoredRevision& r) {
         r.mutable_blocks(0)->mutable_spline()->mutable_knots()->RemoveLast();
       },
       "revision.blocks[0].spline.knots: 2 knot vectors"},
      {[](v1::StoredRevision& r) { r.mutable_blocks(0)->mutable_spline()->set_spatial_dim(4); },
       "revision.blocks[0].spline.spatial_dim = 4"},
      {[](v1::StoredRevision& r) { r.set_origin(static_cast<v1::RevisionOrigin>(17)); },
       "revision.origin = 17"},
      {[](v1::StoredRevision& r) {
         r.mutable_fit_options()->set_parametrization(static_cast<v1::Parametrization>(9));
       },
       "revision.fit_options: parametrization = 9"},
      {[](v1::StoredRevision& r) {
         r.mutable_fit_options()->mutable_fairing()->set_mode(static_cast<v1::FairingMode>(0));
       },
       "revision.fit_options.fairing.mode = 0"},
      {[](v1::StoredRevision& r) {
         r.mutable_kinds()->mutable_blocks(0)->set_face_kinds(1, static_cast<v1::BoundaryKind>(42));
       },
       "revision.kinds.blocks[0].face_kinds[1] = 42"},
      {[](v1::StoredRevision& r) {
         r.mutable_kinds()->mutable_blocks(0)->mutable_point_kinds()->pop_back();
       },
       "revision.kinds.blocks[0].point_kinds: 14624 values for 14625 points"},
      {[](v1::StoredRevision& r) {
         (*r.mutable_kinds()->mutable_blocks(0)->mutable_point_kinds())[7] = 9;
       },
       "revision.kinds.blocks[0].point_kinds[7] = 9"},
      {[](v1::StoredRevision& r) { r.mutable_blocks(0)->mutable_quality()->set_cells_checked(-1); },
       "revision.blocks[0].quality.cells_checked = -1 is negative"},
      {[](v1::StoredRevision& r) { r.mutable_blocks(0)->mutable_quality()->add_bad_cells(1); },
       "revision.blocks[0].quality.bad_cells: "},
      {[](v1::StoredRevision& r) { r.mutable_report()->set_iterations(-3); },
       "revision.report.iterations = -3 is negative"},
      {[](v1::StoredRevision& r) { r.mutable_fit_options()->mutable_control_counts()->set_j(-2); },
       "revision.fit_options.control_counts.j = -2 is negative"},
      {[](v1::StoredRevision& r) {
         r.mutable_fit_options()->mutable_boundary_tolerances()->set_wall(-1);
       },
       "revision.fit_options.boundary_tolerances.wall = -1"},
      {[](v1::StoredRevision& r) { r.mutable_fit_options()->set_tolerance(1e-3); },
       "tolerance and boundary_tolerances are both set"},
      {[](v1::StoredRevision& r) { r.mutable_fit_options()->set_order(11); },
       "revision.fit_options.order = 11"},
      {[](v1::StoredRevision& r) {  // parameters no longer increasing
         auto* params =
             r.mutable_blocks(0)->mutable_distribution()->mutable_directions(0)->mutable_params();
         params->Set(3, params->Get(2));
       },
       "revision.blocks[0].distribution: distribution direction 0: parameter 3"},
      {[](v1::StoredRevision& r) {
         r.mutable_blocks(0)->mutable_distribution()->mutable_directions()->RemoveLast();
       },
       "revision.blocks[0].distribution.directions: 2 directions"},
      {[](v1::StoredRevision& r) { r.set_number(0); }, "revision.number = 0"},
      {[](v1::StoredRevision& r) { r.set_parent(3); }, "revision.parent = 3 is outside [0, 2]"},
      {[](v1::StoredRevision& r) { r.mutable_create_time()->set_nanos(-5); },
       "revision.create_time.nanos = -5"},
      {[](v1::StoredRevision& r) { r.mutable_deform()->mutable_check()->set_level(1 << 30); },
       "revision.deform.check.level = 1073741824"},
      {[](v1::StoredRevision& r) { r.clear_blocks(); }, "revision.blocks: none"},
      {[](v1::StoredRevision& r) { r.mutable_kinds()->add_blocks(); },
       "revision.kinds.blocks: 2 entries for 1 blocks"},
  };
  for (size_t c = 0; c < cases.size(); ++c) {
    SCOPED_TRACE(absl::StrCat("case ", c, ": ", cases[c].message));
    v1::StoredRevision bad = good;
    cases[c].corrupt(bad);
    // Through the wire, as a file would bring it.
    v1::StoredRevision read;
    ASSERT_TRUE(read.ParseFromString(bad.SerializeAsString()));
    EXPECT_THAT(ParseRevision(read).status(),
                StatusIs(absl::StatusCode::kInvalidArgument, cases[c].message));
  }
}

// A crafted spline whose three control counts multiply past int64: refused by the count check
// before TensorSpline::Create could overflow.
TEST_F(ArchiveCodecTest, HugeControlCountProductIsRefused) {
  v1::StoredRevision stored = Stored();
  v1::StoredSpline* spline = stored.mutable_blocks(0)->mutable_spline();
  for (int d = 0; d < 3; ++d) {
    v1::StoredKnotVector* knots = spline->mutable_knots(d);
    knots->set_order(2);  // linear: n controls need n + 2 knots, the interior ones simple
    knots->clear_knots();
    const int n = 1 << 21;
    knots->add_knots(0.0);
    for (int t = 0; t < n; ++t) knots->add_knots(static_cast<double>(t) / (n - 1));
    knots->add_knots(1.0);
  }
  EXPECT_THAT(ParseRevision(stored).status(),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       "the knot vectors define 2097152 x 2097152 x 2097152 control points"));
}

TEST(ArchiveCodecTimeTest, StoredTimeRoundTripsAndRefusesBadFields) {
  for (int64_t nanos : {int64_t{0}, int64_t{-1}, int64_t{1732400000123456789}, int64_t{-1000000000},
                        int64_t{-1234567890123}}) {
    google::protobuf::Timestamp stored;
    EncodeStoredTime(absl::FromUnixNanos(nanos), &stored);
    EXPECT_GE(stored.nanos(), 0);
    EXPECT_LT(stored.nanos(), 1000000000);
    EXPECT_EQ(ParseStoredTime(stored, "t").value(), absl::FromUnixNanos(nanos)) << nanos;
  }
  google::protobuf::Timestamp bad;
  bad.set_seconds(std::numeric_limits<int64_t>::max());
  EXPECT_THAT(ParseStoredTime(bad, "header.create_time").status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "header.create_time.seconds = "));
}

}  // namespace
}  // namespace splinegrid::server
