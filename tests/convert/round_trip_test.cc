// proto/convert round trips: what the service encodes for clients parses back to the same kernel
// value, for every encoder with a parser (Parse(Encode(x)) == x), over values that exercise each
// field and each enumerator. The stored forms (archive_convert) have their own bitwise round
// trips in tests/server/archive_codec_test.cc.
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "core/bspline/tensor_spline.h"
#include "core/grid/point_distribution.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "proto/convert/convert.h"
#include "proto/convert/generate_convert.h"

namespace splinegrid {
namespace {

// Every field of two GridFitOptions, one expectation each (the struct has no operator==).
void ExpectSameFitOptions(const GridFitOptions& a, const GridFitOptions& b) {
  EXPECT_EQ(a.order, b.order);
  EXPECT_EQ(a.parametrization, b.parametrization);
  EXPECT_EQ(a.tolerance, b.tolerance);
  ASSERT_EQ(a.boundary_tolerances.has_value(), b.boundary_tolerances.has_value());
  if (a.boundary_tolerances) {
    EXPECT_EQ(a.boundary_tolerances->wall, b.boundary_tolerances->wall);
    EXPECT_EQ(a.boundary_tolerances->interface, b.boundary_tolerances->interface);
    EXPECT_EQ(a.boundary_tolerances->outer, b.boundary_tolerances->outer);
    EXPECT_EQ(a.boundary_tolerances->interior, b.boundary_tolerances->interior);
    EXPECT_EQ(a.boundary_tolerances->edge, b.boundary_tolerances->edge);
    EXPECT_EQ(a.relative_kinds, b.relative_kinds);
  }
  EXPECT_EQ(a.reference_length, b.reference_length);
  EXPECT_EQ(a.control_counts, b.control_counts);
  EXPECT_EQ(a.block_control_counts, b.block_control_counts);
  EXPECT_EQ(a.max_controls_per_direction, b.max_controls_per_direction);
  EXPECT_EQ(a.fairing.mode, b.fairing.mode);
  if (a.fairing.mode != FairingMode::kOff) {
    EXPECT_EQ(a.fairing.weight, b.fairing.weight);
  }
  ASSERT_EQ(a.face_kinds.size(), b.face_kinds.size());
  for (size_t q = 0; q < a.face_kinds.size(); ++q) {
    EXPECT_EQ(a.face_kinds[q].face, b.face_kinds[q].face);
    EXPECT_EQ(a.face_kinds[q].kind, b.face_kinds[q].kind);
  }
  EXPECT_EQ(a.check_quality, b.check_quality);
  EXPECT_EQ(a.allow_folds, b.allow_folds);
}

GridFitOptions RoundTrip(const GridFitOptions& options) {
  v1::FitSpec spec;
  EncodeFitSpec(options, &spec);
  absl::StatusOr<GridFitOptions> parsed = ParseFitSpec(spec);
  EXPECT_TRUE(parsed.ok()) << parsed.status();
  return parsed.ok() ? *parsed : GridFitOptions();
}

TEST(ConvertRoundTripTest, FitSpecCarriesEveryModeAndField) {
  GridFitOptions counts;
  counts.order = 3;
  counts.parametrization = Parametrization::kCentripetal;
  counts.control_counts = {12, 7, 0};
  counts.block_control_counts = {{1, {5, 4, 3}}, {3, {9, 9, 0}}};
  counts.fairing = {FairingMode::kWeight, 2.5e-3};
  counts.face_kinds = {{Face{0, 1, false}, BoundaryKind::kWall},
                       {Face{2, 0, true}, BoundaryKind::kOuter},
                       {Face{1, 2, true}, BoundaryKind::kInterface}};
  counts.check_quality = false;
  counts.allow_folds = true;
  ExpectSameFitOptions(RoundTrip(counts), counts);

  GridFitOptions one;
  one.tolerance = 3e-5;
  one.max_controls_per_direction = 40;
  one.fairing = {FairingMode::kToTolerance, 1e4};
  ExpectSameFitOptions(RoundTrip(one), one);

  // By kind: the stated kinds are absolute, the unset ones the paper's fractions of the
  // reference length (relative), which is given here.
  GridFitOptions kinds;
  kinds.boundary_tolerances = BoundaryTolerances();
  kinds.boundary_tolerances->wall = 2e-4;
  kinds.boundary_tolerances->outer = 0.05;
  kinds.relative_kinds = kRelativeInterface | kRelativeInterior;
  kinds.reference_length = 0.75;
  kinds.parametrization = Parametrization::kUniform;
  ExpectSameFitOptions(RoundTrip(kinds), kinds);

  GridFitOptions defaults;  // the paper's tolerances by kind, every kind relative
  defaults.boundary_tolerances = BoundaryTolerances();
  ExpectSameFitOptions(RoundTrip(defaults), defaults);
}

TEST(ConvertRoundTripTest, EnumsFacesAndFairing) {
  for (Parametrization p :
       {Parametrization::kUniform, Parametrization::kChordLength, Parametrization::kCentripetal}) {
    EXPECT_EQ(ParseParametrization(EncodeParametrization(p)).value(), p);
  }
  for (BoundaryKind k : {BoundaryKind::kWall, BoundaryKind::kInterface, BoundaryKind::kOuter}) {
    EXPECT_EQ(ParseBoundaryKind(EncodeBoundaryKind(k)), k);
  }
  for (ReferenceLengthSource s : {ReferenceLengthSource::kGiven, ReferenceLengthSource::kWall,
                                  ReferenceLengthSource::kBoundingBox}) {
    EXPECT_EQ(ParseReferenceLengthSource(EncodeReferenceLengthSource(s)), s);
  }
  for (int normal = 0; normal < 3; ++normal) {
    for (bool upper : {false, true}) {
      EXPECT_EQ(ParseBlockFace(4, EncodeBlockFace(normal, upper), "face").value(),
                (Face{4, normal, upper}));
    }
  }
  const Extents e = {17, 1, 129};
  v1::Extents encoded;
  EncodeExtents(e, &encoded);
  EXPECT_EQ(ParseExtents(encoded), e);

  const FaceRange range{Face{2, 1, true}, {3, 40, 0}, {90, 40, 6}};
  v1::FaceRange encoded_range;
  EncodeFaceRange(range, &encoded_range);
  const FaceRange parsed = ParseFaceRange(encoded_range, "range").value();
  EXPECT_EQ(parsed.face, range.face);
  EXPECT_EQ(parsed.begin, range.begin);
  EXPECT_EQ(parsed.end, range.end);

  for (const FairingOptions& f : {FairingOptions{FairingMode::kWeight, 0.125},
                                  FairingOptions{FairingMode::kToTolerance, 3e5}}) {
    v1::Fairing out;
    EncodeFairing(f, &out);
    const FairingOptions back = ParseFairing(out, "fairing").value();
    EXPECT_EQ(back.mode, f.mode);
    EXPECT_EQ(back.weight, f.weight);
  }
}

TEST(ConvertRoundTripTest, SplineBlocksBitwise) {
  // A 2D surface block of 5 x 4 controls (orders 4 and 3) with awkward values.
  const KnotVector u = KnotVector::Create(4, {0, 0, 0, 0, 0.3, 1, 1, 1, 1}).value();
  const KnotVector v = KnotVector::Create(3, {0, 0, 0, 0.5, 1, 1, 1}).value();
  std::vector<double> control;
  for (int q = 0; q < 5 * 4; ++q) {
    control.push_back(std::ldexp(1.0 + q / 7.0, q - 10));
    control.push_back(q % 2 ? -std::numeric_limits<double>::denorm_min() : 1.0 / (q + 3));
  }
  FittedBlock block;
  block.spline = TensorSpline::Create({u, v, KnotVector()}, 2, control).value();
  block.distribution =
      PointDistribution::Create({std::vector<double>{0, 0.1, 0.45, 1},
                                 std::vector<double>{0, 0.5, 1}, std::vector<double>{0}})
          .value();
  v1::SplineBlock encoded;
  EncodeSplineBlock(block, 3, /*full=*/true, &encoded);
  const FittedBlock back = ParseSplineBlock(encoded).value();
  ASSERT_EQ(back.spline.control().size(), block.spline.control().size());
  for (size_t q = 0; q < control.size(); ++q) {
    EXPECT_EQ(std::bit_cast<uint64_t>(back.spline.control()[q]),
              std::bit_cast<uint64_t>(block.spline.control()[q]))
        << q;
  }
  for (int d = 0; d < 3; ++d) {
    EXPECT_TRUE(std::ranges::equal(back.spline.knots(d).knots(), block.spline.knots(d).knots()));
    EXPECT_EQ(back.spline.knots(d).order(), block.spline.knots(d).order());
    EXPECT_EQ(back.distribution.params(d), block.distribution.params(d));
  }
}

TEST(ConvertRoundTripTest, ProfileGridParameters) {
  ProfileGridOptions options;
  options.method = LayerMethod::kElliptic;
  options.wall_points = 161;
  options.layers = 48;
  options.first_height = 2.5e-5;
  options.distance = 30.0;
  options.orthogonalize = false;
  options.fit_tolerance = 3e-5;
  v1::GenerateGridRequest request;
  EncodeProfileGridOptions(options, &request);
  const ProfileGridOptions back = ParseProfileGridOptions(request).value();
  EXPECT_EQ(back.method, options.method);
  EXPECT_EQ(back.wall_points, options.wall_points);
  EXPECT_EQ(back.layers, options.layers);
  EXPECT_EQ(back.first_height, options.first_height);
  EXPECT_EQ(back.distance, options.distance);
  EXPECT_EQ(back.orthogonalize, options.orthogonalize);
  EXPECT_EQ(back.fit_tolerance, options.fit_tolerance);
}

TEST(ConvertRoundTripTest, SurfaceMarchParameters) {
  for (const auto& [outward, side] :
       {std::pair{true, 1}, std::pair{false, 1}, std::pair{false, -1}}) {
    SurfaceOffsetOptions options;
    options.layers = 24;
    options.first_height = 2e-4;
    options.distance = 3.0;
    options.outward = outward;
    options.side = side;
    options.normal_smoothing = 40;
    options.symmetry_planes = false;
    v1::GenerateGridRequest request;
    EncodeSurfaceOffsetOptions(options, &request);
    const SurfaceOffsetOptions back = ParseSurfaceOffsetOptions(request).value();
    EXPECT_EQ(back.layers, options.layers);
    EXPECT_EQ(back.first_height, options.first_height);
    EXPECT_EQ(back.distance, options.distance);
    EXPECT_EQ(back.outward, options.outward);
    if (!outward) EXPECT_EQ(back.side, options.side);
    EXPECT_EQ(back.normal_smoothing, options.normal_smoothing);
    EXPECT_EQ(back.symmetry_planes, options.symmetry_planes);
  }
}

}  // namespace
}  // namespace splinegrid
