#include "proto/convert/convert.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "core/util/status_macros.h"

namespace splinegrid {

void EncodeExtents(const Extents& extents, v1::Extents* out) {
  out->set_i(extents[0]);
  out->set_j(extents[1]);
  out->set_k(extents[2]);
}

Extents ParseExtents(const v1::Extents& extents) { return {extents.i(), extents.j(), extents.k()}; }

v1::BoundaryKind EncodeBoundaryKind(BoundaryKind kind) {
  switch (kind) {
    case BoundaryKind::kWall:
      return v1::BOUNDARY_KIND_WALL;
    case BoundaryKind::kInterface:
      return v1::BOUNDARY_KIND_INTERFACE;
    case BoundaryKind::kOuter:
      return v1::BOUNDARY_KIND_OUTER;
  }
  return v1::BOUNDARY_KIND_UNSPECIFIED;
}

std::optional<BoundaryKind> ParseBoundaryKind(int value) {
  switch (value) {
    case v1::BOUNDARY_KIND_WALL:
      return BoundaryKind::kWall;
    case v1::BOUNDARY_KIND_INTERFACE:
      return BoundaryKind::kInterface;
    case v1::BOUNDARY_KIND_OUTER:
      return BoundaryKind::kOuter;
    default:
      return std::nullopt;
  }
}

v1::Parametrization EncodeParametrization(Parametrization p) {
  switch (p) {
    case Parametrization::kUniform:
      return v1::PARAMETRIZATION_UNIFORM;
    case Parametrization::kChordLength:
      return v1::PARAMETRIZATION_CHORD_LENGTH;
    case Parametrization::kCentripetal:
      return v1::PARAMETRIZATION_CENTRIPETAL;
  }
  return v1::PARAMETRIZATION_UNSPECIFIED;
}

absl::StatusOr<Parametrization> ParseParametrization(v1::Parametrization p) {
  switch (p) {
    case v1::PARAMETRIZATION_UNSPECIFIED:
    case v1::PARAMETRIZATION_CHORD_LENGTH:
      return Parametrization::kChordLength;
    case v1::PARAMETRIZATION_UNIFORM:
      return Parametrization::kUniform;
    case v1::PARAMETRIZATION_CENTRIPETAL:
      return Parametrization::kCentripetal;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat("parametrization = ", static_cast<int>(p), " is not a known value"));
  }
}

absl::StatusOr<GridFitOptions> ParseFitSpec(const v1::FitSpec& spec) {
  GridFitOptions options;
  if (spec.order() != 0) options.order = spec.order();
  SG_ASSIGN_OR_RETURN(options.parametrization, ParseParametrization(spec.parametrization()));
  switch (spec.resolution_case()) {
    case v1::FitSpec::kTolerance:
      options.tolerance = spec.tolerance();
      break;
    case v1::FitSpec::kBoundaryTolerances: {
      const v1::BoundaryTolerances& given = spec.boundary_tolerances();
      // A kind given is absolute; a kind left unset keeps its default, a fraction of the
      // reference length.
      BoundaryTolerances t;
      uint8_t relative = kAllKindsRelative;
      auto take = [&relative](double value, double& field, uint8_t bit) {
        if (value != 0.0) field = value, relative &= ~bit;
      };
      take(given.wall(), t.wall, kRelativeWall);
      take(given.interface(), t.interface, kRelativeInterface);
      take(given.outer(), t.outer, kRelativeOuter);
      take(given.interior(), t.interior, kRelativeInterior);
      options.relative_kinds = relative;
      if (given.has_edge()) t.edge = given.edge();
      t.first_layer = given.first_layer();
      if (absl::Status s = t.Validate(); !s.ok()) {
        return absl::InvalidArgumentError(absl::StrCat("spec.", s.message()));
      }
      options.boundary_tolerances = t;
      break;
    }
    case v1::FitSpec::kControlCounts: {
      const Extents counts = ParseExtents(spec.control_counts());
      for (int d = 0; d < 3; ++d) {
        if (counts[d] < 0) {
          return absl::InvalidArgumentError(absl::StrCat(
              "spec.control_counts.", std::string(1, "ijk"[d]), " = ", counts[d], " is negative"));
        }
      }
      options.control_counts = counts;
      break;
    }
    case v1::FitSpec::RESOLUTION_NOT_SET:
      break;  // interpolation unless per-block counts say otherwise
  }
  for (const v1::BlockControlCounts& entry : spec.block_control_counts()) {
    options.block_control_counts.emplace_back(entry.block(), ParseExtents(entry.control_counts()));
  }
  options.max_controls_per_direction = spec.max_controls_per_direction();
  SG_ASSIGN_OR_RETURN(options.fairing, ParseFairing(spec.fairing(), "spec.fairing"));
  for (int q = 0; q < spec.face_kinds_size(); ++q) {
    const v1::FaceKind& entry = spec.face_kinds(q);
    const std::string field = absl::StrCat("spec.face_kinds[", q, "]");
    SG_ASSIGN_OR_RETURN(const Face face, ParseBlockFace(entry.block(), entry.face(), field));
    const std::optional<BoundaryKind> kind = ParseBoundaryKind(entry.kind());
    if (!kind) {
      return absl::InvalidArgumentError(absl::StrCat(
          field, ".kind = ", static_cast<int>(entry.kind()), " is not WALL, INTERFACE or OUTER"));
    }
    options.face_kinds.push_back(FaceKindOverride{face, *kind});
  }
  options.check_quality = !spec.skip_quality_refinement();
  options.allow_folds = spec.allow_folds();
  if (spec.reference_length() != 0.0) options.reference_length = spec.reference_length();
  return options;
}

v1::ReferenceLengthSource EncodeReferenceLengthSource(ReferenceLengthSource source) {
  switch (source) {
    case ReferenceLengthSource::kGiven:
      return v1::REFERENCE_LENGTH_SOURCE_GIVEN;
    case ReferenceLengthSource::kWall:
      return v1::REFERENCE_LENGTH_SOURCE_WALL;
    case ReferenceLengthSource::kBoundingBox:
      return v1::REFERENCE_LENGTH_SOURCE_BOUNDING_BOX;
  }
  return v1::REFERENCE_LENGTH_SOURCE_UNSPECIFIED;
}

std::optional<ReferenceLengthSource> ParseReferenceLengthSource(v1::ReferenceLengthSource source) {
  switch (source) {
    case v1::REFERENCE_LENGTH_SOURCE_GIVEN:
      return ReferenceLengthSource::kGiven;
    case v1::REFERENCE_LENGTH_SOURCE_WALL:
      return ReferenceLengthSource::kWall;
    case v1::REFERENCE_LENGTH_SOURCE_BOUNDING_BOX:
      return ReferenceLengthSource::kBoundingBox;
    default:
      return std::nullopt;
  }
}

v1::BlockFace EncodeBlockFace(int normal, bool upper) {
  return static_cast<v1::BlockFace>(1 + 2 * normal + (upper ? 1 : 0));
}

absl::StatusOr<Face> ParseBlockFace(int block, v1::BlockFace face, const std::string& field) {
  const int value = static_cast<int>(face);
  if (value < v1::BLOCK_FACE_I_MIN || value > v1::BLOCK_FACE_K_MAX) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".face = ", value, " is not one of I_MIN .. K_MAX"));
  }
  if (block < 0) {
    return absl::InvalidArgumentError(absl::StrCat(field, ".block = ", block, " is negative"));
  }
  return Face{block, (value - 1) / 2, (value - 1) % 2 == 1};
}

absl::StatusOr<FaceRange> ParseFaceRange(const v1::FaceRange& range, const std::string& field) {
  SG_ASSIGN_OR_RETURN(const Face face, ParseBlockFace(range.block(), range.face(), field));
  FaceRange out{face, ParseExtents(range.begin()), ParseExtents(range.end())};
  return out;
}

void EncodeFaceRange(const FaceRange& range, v1::FaceRange* out) {
  out->set_block(range.face.block);
  out->set_face(EncodeBlockFace(range.face.normal, range.face.upper));
  EncodeExtents(range.begin, out->mutable_begin());
  EncodeExtents(range.end, out->mutable_end());
}

absl::StatusOr<BoundarySelection> ParseBoundarySelection(const v1::BoundarySelection& selection) {
  BoundarySelection out;
  if (selection.kinds_size() > 0) out.kinds = 0;
  for (int q = 0; q < selection.kinds_size(); ++q) {
    const std::optional<BoundaryKind> kind = ParseBoundaryKind(selection.kinds(q));
    if (!kind) {
      return absl::InvalidArgumentError(absl::StrCat("boundary.kinds[", q,
                                                     "] = ", static_cast<int>(selection.kinds(q)),
                                                     " is not WALL, INTERFACE or OUTER"));
    }
    out.kinds |= static_cast<uint8_t>(*kind);
  }
  for (int q = 0; q < selection.ranges_size(); ++q) {
    SG_ASSIGN_OR_RETURN(FaceRange range, ParseFaceRange(selection.ranges(q),
                                                        absl::StrCat("boundary.ranges[", q, "]")));
    out.ranges.push_back(range);
  }
  return out;
}

absl::StatusOr<RigidMotion> ParseRigidMotion(const v1::RigidMotion& motion) {
  RigidMotion out;
  auto take = [](const google::protobuf::RepeatedField<double>& values, const char* name,
                 bool allow_two, Point3& into) -> absl::Status {
    if (values.empty()) return absl::OkStatus();
    if (values.size() != 3 && !(allow_two && values.size() == 2)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "rigid.", name, ": ", values.size(), " values; give ", allow_two ? "2 or " : "", "3"));
    }
    into = {0.0, 0.0, 0.0};
    for (int c = 0; c < values.size(); ++c) into[c] = values[c];
    return absl::OkStatus();
  };
  SG_RETURN_IF_ERROR(take(motion.center(), "center", true, out.center));
  SG_RETURN_IF_ERROR(take(motion.axis(), "axis", false, out.axis));
  SG_RETURN_IF_ERROR(take(motion.translation(), "translation", true, out.translation));
  out.angle = motion.angle_degrees() * (3.14159265358979323846 / 180.0);
  if (!std::isfinite(motion.angle_degrees())) {
    return absl::InvalidArgumentError(
        absl::StrCat("rigid.angle_degrees = ", motion.angle_degrees(), " is not finite"));
  }
  if (absl::Status s = out.Validate(); !s.ok()) {
    // The kernel's "motion: center[0] = nan ..." as the request's field, rigid.center[0].
    return absl::InvalidArgumentError(
        absl::StrCat("rigid.", absl::StripPrefix(s.message(), "motion: ")));
  }
  return out;
}

absl::StatusOr<FairingOptions> ParseFairing(const v1::Fairing& fairing, const std::string& field) {
  FairingOptions options;
  const double weight = fairing.weight();
  if (!(weight >= 0.0) || !std::isfinite(weight)) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".weight = ", weight, " is not a finite number >= 0"));
  }
  switch (fairing.mode()) {
    case v1::FAIRING_MODE_UNSPECIFIED:
    case v1::FAIRING_MODE_OFF:
      options.mode = FairingMode::kOff;
      break;
    case v1::FAIRING_MODE_WEIGHT:
      if (weight == 0.0) {
        return absl::InvalidArgumentError(
            absl::StrCat(field, ".weight = 0; mode WEIGHT needs a positive lambda"));
      }
      options.mode = FairingMode::kWeight;
      options.weight = weight;
      break;
    case v1::FAIRING_MODE_TO_TOLERANCE:
      options.mode = FairingMode::kToTolerance;
      if (weight > 0.0) options.weight = weight;
      break;
    default:
      return absl::InvalidArgumentError(absl::StrCat(
          field, ".mode = ", static_cast<int>(fairing.mode()), " is not a known value"));
  }
  return options;
}

void EncodeFairing(const FairingOptions& fairing, v1::Fairing* out) {
  switch (fairing.mode) {
    case FairingMode::kOff:
      out->set_mode(v1::FAIRING_MODE_OFF);
      return;
    case FairingMode::kWeight:
      out->set_mode(v1::FAIRING_MODE_WEIGHT);
      break;
    case FairingMode::kToTolerance:
      out->set_mode(v1::FAIRING_MODE_TO_TOLERANCE);
      break;
  }
  out->set_weight(fairing.weight);
}

void EncodeFitSpec(const GridFitOptions& options, v1::FitSpec* out) {
  out->set_order(options.order);
  out->set_parametrization(EncodeParametrization(options.parametrization));
  if (options.tolerance) {
    out->set_tolerance(*options.tolerance);
  } else if (options.boundary_tolerances) {
    const BoundaryTolerances& t = *options.boundary_tolerances;
    v1::BoundaryTolerances* given = out->mutable_boundary_tolerances();
    // A relative kind is written unset: its default fraction of the reference length (the
    // kernel's other fractions have no FitSpec form).
    auto put = [&options](double value, uint8_t bit) {
      return (options.relative_kinds & bit) || !std::isfinite(value) ? 0.0 : value;
    };
    given->set_wall(put(t.wall, kRelativeWall));
    given->set_interface(put(t.interface, kRelativeInterface));
    given->set_outer(put(t.outer, kRelativeOuter));
    given->set_interior(put(t.interior, kRelativeInterior));
    given->set_edge(t.edge);
    given->set_first_layer(t.first_layer);
  } else {
    EncodeExtents(options.control_counts, out->mutable_control_counts());
  }
  EncodeFairing(options.fairing, out->mutable_fairing());
  for (const FaceKindOverride& o : options.face_kinds) {
    v1::FaceKind* entry = out->add_face_kinds();
    entry->set_block(o.face.block);
    entry->set_face(EncodeBlockFace(o.face.normal, o.face.upper));
    entry->set_kind(EncodeBoundaryKind(o.kind));
  }
  out->set_skip_quality_refinement(!options.check_quality);
  out->set_allow_folds(options.allow_folds);
  if (options.reference_length) out->set_reference_length(*options.reference_length);
  for (const auto& [block, counts] : options.block_control_counts) {
    v1::BlockControlCounts* entry = out->add_block_control_counts();
    entry->set_block(block);
    EncodeExtents(counts, entry->mutable_control_counts());
  }
  out->set_max_controls_per_direction(options.max_controls_per_direction);
}

void EncodeFitSummary(const FitSummary& summary, v1::BlockFitSummary* out) {
  out->set_num_points(summary.num_points);
  out->set_num_control_points(summary.num_control_points);
  out->set_compression_ratio(summary.compression_ratio);
  out->set_max_deviation(summary.deviation.max);
  out->set_rms_deviation(summary.deviation.rms);
  EncodeExtents(summary.deviation.max_at, out->mutable_max_deviation_at());
  out->set_seconds(summary.seconds);
}

void EncodeBlockFit(const BlockFit& block, bool tolerance_mode, v1::BlockFitSummary* out) {
  EncodeFitSummary(block.fitted.summary, out);
  if (tolerance_mode) {
    out->set_tolerance_met(block.tolerance_met);
    out->set_unmet_reason(block.unmet_reason);
  }
  const KindDeviation& d = block.deviation_by_kind;
  v1::DeviationByKind* dev = out->mutable_deviation_by_kind();
  if (d.wall >= 0.0) dev->set_wall(d.wall);
  if (d.interface >= 0.0) dev->set_interface(d.interface);
  if (d.outer >= 0.0) dev->set_outer(d.outer);
  if (d.interior >= 0.0) dev->set_interior(d.interior);
  if (d.first_layer >= 0.0) dev->set_first_layer(d.first_layer);
  const CellQuality& q = block.quality;
  v1::CellQualityReport* quality = out->mutable_quality();
  quality->set_cells_checked(q.cells_checked);
  quality->set_cells_skipped(q.cells_skipped);
  quality->set_folded(q.folded);
  quality->set_out_of_size(q.out_of_size);
  if (q.cells_checked > 0) {
    quality->set_min_ratio(q.min_ratio);
    quality->set_max_ratio(q.max_ratio);
    EncodeExtents(q.worst_cell, quality->mutable_worst_cell());
    quality->set_worst_level(q.worst_level);
    quality->set_max_level(CellQualityOptions().max_level);
  }
  quality->set_num_bad_cells(q.num_bad_cells);
}

void EncodeCurvature(const CurvatureMetrics& metrics, v1::CurvatureReport* out) {
  out->set_lines(metrics.lines);
  out->set_samples(metrics.samples);
  out->set_extrema(metrics.extrema);
  out->set_sum_squared_differences(metrics.sum_squared_differences);
  out->set_max_abs_curvature(metrics.max_abs_curvature);
}

void EncodeWallCurvatureLine(const WallLine& line, const std::vector<CurvatureSample>& samples,
                             int spatial_dim, v1::WallCurvatureLine* out) {
  out->set_block(line.block);
  out->set_direction(line.direction);
  EncodeExtents(line.start, out->mutable_start());
  out->set_length(line.length);
  for (const CurvatureSample& s : samples) {
    out->add_arc_length(s.arc_length);
    for (int c = 0; c < spatial_dim; ++c) out->add_points(s.point[c]);
    out->add_curvature(s.curvature);
  }
}

void EncodeFitReport(const GridFitReport& report, const std::vector<BlockFit>& blocks,
                     v1::FitReport* out) {
  out->set_tolerance_met(report.tolerance_met);
  out->set_unmet_reason(report.unmet_reason);
  out->set_quality_met(report.quality_met);
  out->set_num_matches(report.num_matches);
  out->set_max_gap(report.max_gap);
  out->set_fairing_weight(report.fairing_weight);
  EncodeCurvature(report.wall_curvature, out->mutable_wall_curvature());
  if (report.unfaired_wall_curvature.lines > 0) {
    EncodeCurvature(report.unfaired_wall_curvature, out->mutable_unfaired_wall_curvature());
  }
  out->set_iterations(report.iterations);
  out->set_knots_inserted(report.knots_inserted);
  out->set_knots_removed(report.knots_removed);
  out->set_quality_rounds(report.quality_rounds);
  for (const std::string& adjustment : report.adjustments) out->add_adjustments(adjustment);
  out->set_reference_length(report.reference.length);
  out->set_reference_length_source(EncodeReferenceLengthSource(report.reference.source));
  out->set_reference_length_description(report.reference.description);
  if (report.tolerances) {
    const BoundaryTolerances& t = *report.tolerances;
    v1::BoundaryTolerances* held = out->mutable_tolerances();
    held->set_wall(t.wall);
    held->set_interface(t.interface);
    held->set_outer(t.outer);
    held->set_interior(std::isfinite(t.interior) ? t.interior : 0.0);
    held->set_edge(t.edge);
    held->set_first_layer(t.first_layer);
  }
  double min_ratio = std::numeric_limits<double>::infinity(), size_ratio = 0.0;
  int64_t folded = 0, bad = 0;
  for (const BlockFit& b : blocks) {
    folded += b.quality.folded;
    bad += b.quality.num_bad_cells;
    if (b.quality.cells_checked == 0) continue;
    min_ratio = std::min(min_ratio, b.quality.min_ratio);
    size_ratio = std::max(size_ratio, b.quality.max_ratio);
    if (b.quality.min_ratio > 0.0) size_ratio = std::max(size_ratio, 1.0 / b.quality.min_ratio);
  }
  out->set_folded_cells(folded);
  out->set_bad_cells(bad);
  if (std::isfinite(min_ratio)) {
    out->set_min_jacobian_ratio(min_ratio);
    out->set_max_size_ratio(size_ratio);
  }
}

void EncodeBoundaryMatch(const BoundaryMatch& match, v1::BoundaryMatch* out) {
  auto range = [](const FaceRange& r, v1::FaceRange* o) {
    o->set_block(r.face.block);
    o->set_face(EncodeBlockFace(r.face.normal, r.face.upper));
    EncodeExtents(r.begin, o->mutable_begin());
    EncodeExtents(r.end, o->mutable_end());
  };
  range(match.a, out->mutable_a());
  range(match.b, out->mutable_b());
  for (int d = 0; d < 3; ++d) {
    out->add_b_direction(match.b_direction[d]);
    out->add_reversed(match.reversed[d]);
  }
  out->set_step(match.step);
  out->set_description(match.Describe());
}

void EncodeSplineBlock(const FittedBlock& block, int index, bool full, v1::SplineBlock* out) {
  out->set_index(index);
  out->set_spatial_dim(block.spline.spatial_dim());
  for (int d = 0; d < 3; ++d) {
    const KnotVector& knots = block.spline.knots(d);
    v1::SplineDirection* direction = out->add_directions();
    direction->set_order(knots.order());
    direction->set_num_controls(knots.num_controls());
    if (full) {
      direction->mutable_knots()->Assign(knots.knots().begin(), knots.knots().end());
      const std::vector<double>& params = block.distribution.params(d);
      direction->mutable_parameters()->Assign(params.begin(), params.end());
      const std::vector<int>& breaks = block.distribution.breaks(d);
      direction->mutable_breaks()->Assign(breaks.begin(), breaks.end());
    }
  }
  if (full) {
    out->mutable_control_points()->Assign(block.spline.control().begin(),
                                          block.spline.control().end());
  }
  EncodeFitSummary(block.summary, out->mutable_fit());
}

absl::StatusOr<FittedBlock> ParseSplineBlock(const v1::SplineBlock& block) {
  if (block.directions_size() != 3) {
    return absl::InvalidArgumentError(
        absl::StrCat("directions: ", block.directions_size(), " given; exactly 3 are needed"));
  }
  std::array<KnotVector, 3> knots;
  std::array<std::vector<double>, 3> params;
  std::array<std::vector<int>, 3> breaks;
  for (int d = 0; d < 3; ++d) {
    const v1::SplineDirection& direction = block.directions(d);
    breaks[d].assign(direction.breaks().begin(), direction.breaks().end());
    absl::StatusOr<KnotVector> kv =
        KnotVector::Create(direction.order(), {direction.knots().begin(), direction.knots().end()});
    if (!kv.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("directions[", d, "]: ", kv.status().message()));
    }
    knots[d] = *std::move(kv);
    params[d].assign(direction.parameters().begin(), direction.parameters().end());
  }
  SG_ASSIGN_OR_RETURN(
      TensorSpline spline,
      TensorSpline::Create(std::move(knots), block.spatial_dim(),
                           {block.control_points().begin(), block.control_points().end()}));
  SG_ASSIGN_OR_RETURN(PointDistribution distribution,
                      PointDistribution::Create(std::move(params), std::move(breaks)));
  FittedBlock fitted{std::move(spline), std::move(distribution), {}};
  const v1::BlockFitSummary& fit = block.fit();
  fitted.summary.num_points = fit.num_points();
  fitted.summary.num_control_points = fit.num_control_points();
  fitted.summary.compression_ratio = fit.compression_ratio();
  fitted.summary.deviation.max = fit.max_deviation();
  fitted.summary.deviation.rms = fit.rms_deviation();
  fitted.summary.deviation.max_at = ParseExtents(fit.max_deviation_at());
  fitted.summary.deviation.num_points = fit.num_points();
  fitted.summary.seconds = fit.seconds();
  return fitted;
}

absl::StatusOr<Resolution> ParseResolution(const v1::EvaluateGridRequest& request) {
  Resolution resolution;
  switch (request.resolution_case()) {
    case v1::EvaluateGridRequest::kCounts:
      resolution.kind = Resolution::Kind::kCounts;
      resolution.counts = ParseExtents(request.counts());
      break;
    case v1::EvaluateGridRequest::kRefinementLevel:
    case v1::EvaluateGridRequest::RESOLUTION_NOT_SET:
      resolution.kind = Resolution::Kind::kLevel;
      resolution.level = request.refinement_level();
      break;
  }
  if (request.has_index_box()) {
    resolution.box = IndexBox{ParseExtents(request.index_box().begin()),
                              ParseExtents(request.index_box().end())};
  }
  const v1::Distributions& wanted = request.distributions();
  const std::array<const v1::Distribution*, 3> per_direction = {&wanted.i(), &wanted.j(),
                                                                &wanted.k()};
  for (int d = 0; d < 3; ++d) {
    const v1::Distribution& in = *per_direction[d];
    Distribution& out = resolution.distributions[d];
    switch (in.kind()) {
      case v1::Distribution::KIND_ORIGINAL:
        out.kind = Distribution::Kind::kOriginal;
        break;
      case v1::Distribution::KIND_UNIFORM_PARAMETER:
        out.kind = Distribution::Kind::kUniformParameter;
        break;
      case v1::Distribution::KIND_UNIFORM_ARC_LENGTH:
        out.kind = Distribution::Kind::kUniformArcLength;
        break;
      case v1::Distribution::KIND_GEOMETRIC:
        out.kind = Distribution::Kind::kGeometric;
        break;
      default:
        return absl::InvalidArgumentError(absl::StrCat("distributions.", std::string(1, "ijk"[d]),
                                                       ".kind = ", in.kind(),
                                                       " is not a known distribution"));
    }
    out.first_spacing = in.first_spacing();
    out.from_end = in.from_end();
  }
  return resolution;
}

}  // namespace splinegrid
