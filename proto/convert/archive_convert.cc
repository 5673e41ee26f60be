// Stored revision parts <-> kernel types (archive_convert.h): report, boundary kinds, fit
// options, deformation check. Blocks are in archive_block.cc; the header's connectivity and the
// source points in archive_source.cc.
#include "proto/convert/archive_convert.h"

#include <cmath>

#include "core/grid/sampling.h"
#include "core/util/status_macros.h"
#include "proto/convert/archive_util.h"
#include "proto/convert/convert.h"

namespace splinegrid {
namespace {

using archive_internal::Annotate;
using archive_internal::CheckNonNegative;
using archive_internal::Invalid;

absl::StatusOr<BoundaryKind> ParseKind(int value, const std::string& field) {
  const std::optional<BoundaryKind> kind = ParseBoundaryKind(value);
  if (!kind) return Invalid(field, " = ", value, " is not WALL, INTERFACE or OUTER");
  return *kind;
}

void EncodeCurvatureMetrics(const CurvatureMetrics& metrics, v1::CurvatureReport* out) {
  EncodeCurvature(metrics, out);  // grid.proto's CurvatureReport holds every field exactly
}

absl::StatusOr<CurvatureMetrics> ParseCurvatureMetrics(const v1::CurvatureReport& stored,
                                                       const std::string& field) {
  CurvatureMetrics metrics;
  metrics.lines = stored.lines();
  metrics.samples = stored.samples();
  metrics.extrema = stored.extrema();
  metrics.sum_squared_differences = stored.sum_squared_differences();
  metrics.max_abs_curvature = stored.max_abs_curvature();
  SG_RETURN_IF_ERROR(CheckNonNegative(metrics.lines, field + ".lines"));
  SG_RETURN_IF_ERROR(CheckNonNegative(metrics.samples, field + ".samples"));
  SG_RETURN_IF_ERROR(CheckNonNegative(metrics.extrema, field + ".extrema"));
  return metrics;
}

}  // namespace

// ---- GridFitReport ----

void EncodeFitReport(const GridFitReport& report, v1::StoredFitReport* out) {
  out->set_num_points(report.num_points);
  out->set_num_control_points(report.num_control_points);
  out->set_max_deviation(report.max_deviation);
  out->set_tolerance_met(report.tolerance_met);
  out->set_unmet_reason(report.unmet_reason);
  out->set_quality_met(report.quality_met);
  out->set_num_matches(report.num_matches);
  out->set_max_gap(report.max_gap);
  out->set_fairing_weight(report.fairing_weight);
  EncodeCurvatureMetrics(report.wall_curvature, out->mutable_wall_curvature());
  EncodeCurvatureMetrics(report.unfaired_wall_curvature, out->mutable_unfaired_wall_curvature());
  out->set_iterations(report.iterations);
  out->set_knots_inserted(report.knots_inserted);
  out->set_knots_removed(report.knots_removed);
  out->set_quality_rounds(report.quality_rounds);
  out->set_seconds(report.seconds);
  for (const std::string& adjustment : report.adjustments) out->add_adjustments(adjustment);
  out->set_reference_length(report.reference.length);
  out->set_reference_length_source(EncodeReferenceLengthSource(report.reference.source));
  out->set_reference_length_description(report.reference.description);
  if (report.tolerances) {
    const BoundaryTolerances& t = *report.tolerances;
    v1::StoredBoundaryTolerances* stored = out->mutable_tolerances();
    stored->set_wall(t.wall);
    stored->set_interface(t.interface);
    stored->set_outer(t.outer);
    stored->set_interior(t.interior);
    stored->set_edge(t.edge);
    stored->set_first_layer(t.first_layer);
  }
}

absl::StatusOr<GridFitReport> ParseFitReport(const v1::StoredFitReport& stored,
                                             const std::string& field) {
  GridFitReport report;
  report.num_points = stored.num_points();
  report.num_control_points = stored.num_control_points();
  report.max_deviation = stored.max_deviation();
  report.tolerance_met = stored.tolerance_met();
  report.unmet_reason = stored.unmet_reason();
  report.quality_met = stored.quality_met();
  report.num_matches = stored.num_matches();
  report.max_gap = stored.max_gap();
  report.fairing_weight = stored.fairing_weight();
  SG_ASSIGN_OR_RETURN(report.wall_curvature,
                      ParseCurvatureMetrics(stored.wall_curvature(), field + ".wall_curvature"));
  SG_ASSIGN_OR_RETURN(
      report.unfaired_wall_curvature,
      ParseCurvatureMetrics(stored.unfaired_wall_curvature(), field + ".unfaired_wall_curvature"));
  report.iterations = stored.iterations();
  report.knots_inserted = stored.knots_inserted();
  report.adjustments.assign(stored.adjustments().begin(), stored.adjustments().end());
  report.knots_removed = stored.knots_removed();
  report.quality_rounds = stored.quality_rounds();
  report.seconds = stored.seconds();
  // Archives from before reference lengths have none: the report keeps the default (1, given).
  if (stored.reference_length_source() != v1::REFERENCE_LENGTH_SOURCE_UNSPECIFIED) {
    const std::optional<ReferenceLengthSource> source =
        ParseReferenceLengthSource(stored.reference_length_source());
    if (!source) {
      return Invalid(field, ".reference_length_source = ",
                     static_cast<int>(stored.reference_length_source()), " is not a known value");
    }
    report.reference =
        ReferenceLength{stored.reference_length(), *source, stored.reference_length_description()};
  }
  if (stored.has_tolerances()) {
    const v1::StoredBoundaryTolerances& t = stored.tolerances();
    report.tolerances = BoundaryTolerances{t.wall(),     t.interface(), t.outer(),
                                           t.interior(), t.edge(),      t.first_layer()};
  }
  SG_RETURN_IF_ERROR(CheckNonNegative(report.num_points, field + ".num_points"));
  SG_RETURN_IF_ERROR(CheckNonNegative(report.num_control_points, field + ".num_control_points"));
  SG_RETURN_IF_ERROR(CheckNonNegative(report.num_matches, field + ".num_matches"));
  SG_RETURN_IF_ERROR(CheckNonNegative(report.iterations, field + ".iterations"));
  SG_RETURN_IF_ERROR(CheckNonNegative(report.knots_inserted, field + ".knots_inserted"));
  SG_RETURN_IF_ERROR(CheckNonNegative(report.knots_removed, field + ".knots_removed"));
  SG_RETURN_IF_ERROR(CheckNonNegative(report.quality_rounds, field + ".quality_rounds"));
  return report;
}

// ---- BoundaryKinds ----

void EncodeBoundaryKinds(const BoundaryKinds& kinds, v1::StoredBoundaryKinds* out) {
  for (size_t b = 0; b < kinds.point_kinds.size(); ++b) {
    v1::StoredBlockKinds* block = out->add_blocks();
    const std::vector<uint8_t>& points = kinds.point_kinds[b];
    block->set_point_kinds(reinterpret_cast<const char*>(points.data()), points.size());
    if (b < kinds.face_kinds.size()) {
      for (BoundaryKind kind : kinds.face_kinds[b]) block->add_face_kinds(EncodeBoundaryKind(kind));
    }
  }
}

absl::StatusOr<BoundaryKinds> ParseBoundaryKinds(const v1::StoredBoundaryKinds& stored,
                                                 const std::vector<Extents>& blocks,
                                                 const std::string& field) {
  if (stored.blocks_size() != static_cast<int>(blocks.size())) {
    return Invalid(field, ".blocks: ", stored.blocks_size(), " entries for ", blocks.size(),
                   " blocks");
  }
  constexpr uint8_t kAllKinds = static_cast<uint8_t>(BoundaryKind::kWall) |
                                static_cast<uint8_t>(BoundaryKind::kInterface) |
                                static_cast<uint8_t>(BoundaryKind::kOuter);
  BoundaryKinds kinds;
  kinds.point_kinds.resize(blocks.size());
  kinds.face_kinds.resize(blocks.size());
  for (size_t b = 0; b < blocks.size(); ++b) {
    const v1::StoredBlockKinds& block = stored.blocks(static_cast<int>(b));
    const std::string at = absl::StrCat(field, ".blocks[", b, "]");
    const std::string& points = block.point_kinds();
    if (static_cast<int64_t>(points.size()) != NumPoints(blocks[b])) {
      return Invalid(at, ".point_kinds: ", points.size(), " values for ", NumPoints(blocks[b]),
                     " points");
    }
    for (size_t p = 0; p < points.size(); ++p) {
      const uint8_t mask = static_cast<uint8_t>(points[p]);
      if ((mask & ~kAllKinds) != 0) {
        return Invalid(at, ".point_kinds[", p, "] = ", static_cast<int>(mask),
                       " has bits other than wall 1, interface 2, outer 4");
      }
    }
    kinds.point_kinds[b].assign(points.begin(), points.end());
    const int faces = 2 * ActiveDirections(blocks[b]);
    if (block.face_kinds_size() != faces) {
      return Invalid(at, ".face_kinds: ", block.face_kinds_size(), " kinds for ", faces, " faces");
    }
    for (int f = 0; f < faces; ++f) {
      SG_ASSIGN_OR_RETURN(BoundaryKind kind,
                          ParseKind(block.face_kinds(f), absl::StrCat(at, ".face_kinds[", f, "]")));
      kinds.face_kinds[b].push_back(kind);
    }
  }
  return kinds;
}

// ---- GridFitOptions ----

void EncodeGridFitOptions(const GridFitOptions& options, v1::StoredFitOptions* out) {
  out->set_order(options.order);
  out->set_parametrization(EncodeParametrization(options.parametrization));
  if (options.tolerance) out->set_tolerance(*options.tolerance);
  if (options.boundary_tolerances) {
    const BoundaryTolerances& t = *options.boundary_tolerances;
    v1::StoredBoundaryTolerances* stored = out->mutable_boundary_tolerances();
    stored->set_wall(t.wall);
    stored->set_interface(t.interface);
    stored->set_outer(t.outer);
    stored->set_interior(t.interior);
    stored->set_edge(t.edge);
    stored->set_first_layer(t.first_layer);
  }
  EncodeExtents(options.control_counts, out->mutable_control_counts());
  for (const auto& [block, counts] : options.block_control_counts) {
    v1::BlockControlCounts* entry = out->add_block_control_counts();
    entry->set_block(block);
    EncodeExtents(counts, entry->mutable_control_counts());
  }
  out->set_max_controls_per_direction(options.max_controls_per_direction);
  EncodeFairing(options.fairing, out->mutable_fairing());
  out->mutable_fairing()->set_weight(options.fairing.weight);  // kept with the mode off, too
  for (const FaceKindOverride& o : options.face_kinds) {
    v1::FaceKind* entry = out->add_face_kinds();
    entry->set_block(o.face.block);
    entry->set_face(EncodeBlockFace(o.face.normal, o.face.upper));
    entry->set_kind(EncodeBoundaryKind(o.kind));
  }
  out->set_check_quality(options.check_quality);
  out->set_allow_folds(options.allow_folds);
  out->set_relative_kinds(options.relative_kinds);
  if (options.reference_length) out->set_reference_length(*options.reference_length);
}

absl::StatusOr<GridFitOptions> ParseGridFitOptions(const v1::StoredFitOptions& stored,
                                                   const std::string& field) {
  GridFitOptions options;
  options.order = stored.order();
  if (options.order < 2 || options.order > kMaxOrder) {
    return Invalid(field, ".order = ", options.order, " is outside [2, ", kMaxOrder, "]");
  }
  // The parametrization as stored: UNSPECIFIED (the API's "default") is never written.
  const int parametrization = stored.parametrization();
  if (parametrization == v1::PARAMETRIZATION_UNSPECIFIED) {
    return Invalid(field, ".parametrization = 0 is not UNIFORM, CHORD_LENGTH or CENTRIPETAL");
  }
  absl::StatusOr<Parametrization> p = ParseParametrization(stored.parametrization());
  if (!p.ok()) return Annotate(p.status(), field);
  options.parametrization = *p;
  if (stored.has_tolerance() && stored.has_boundary_tolerances()) {
    return Invalid(field, ": tolerance and boundary_tolerances are both set");
  }
  if (stored.has_tolerance()) {
    if (!(stored.tolerance() > 0.0) || !std::isfinite(stored.tolerance())) {
      return Invalid(field, ".tolerance = ", stored.tolerance(), " is not positive and finite");
    }
    options.tolerance = stored.tolerance();
  }
  if (stored.has_boundary_tolerances()) {
    const v1::StoredBoundaryTolerances& t = stored.boundary_tolerances();
    const BoundaryTolerances tolerances{t.wall(),     t.interface(), t.outer(),
                                        t.interior(), t.edge(),      t.first_layer()};
    if (absl::Status s = tolerances.Validate(); !s.ok()) {
      // The message names boundary_tolerances.<kind>: under this field, as a request field is.
      return absl::InvalidArgumentError(absl::StrCat(field, ".", s.message()));
    }
    options.boundary_tolerances = tolerances;
  }
  options.control_counts = ParseExtents(stored.control_counts());
  for (int d = 0; d < 3; ++d) {
    SG_RETURN_IF_ERROR(
        CheckNonNegative(options.control_counts[d],
                         absl::StrCat(field, ".control_counts.", std::string(1, "ijk"[d]))));
  }
  for (int q = 0; q < stored.block_control_counts_size(); ++q) {
    const v1::BlockControlCounts& entry = stored.block_control_counts(q);
    const std::string at = absl::StrCat(field, ".block_control_counts[", q, "]");
    SG_RETURN_IF_ERROR(CheckNonNegative(entry.block(), at + ".block"));
    const Extents counts = ParseExtents(entry.control_counts());
    for (int d = 0; d < 3; ++d) {
      SG_RETURN_IF_ERROR(CheckNonNegative(
          counts[d], absl::StrCat(at, ".control_counts.", std::string(1, "ijk"[d]))));
    }
    options.block_control_counts.emplace_back(entry.block(), counts);
  }
  options.max_controls_per_direction = stored.max_controls_per_direction();
  SG_RETURN_IF_ERROR(
      CheckNonNegative(options.max_controls_per_direction, field + ".max_controls_per_direction"));
  switch (static_cast<int>(stored.fairing().mode())) {
    case v1::FAIRING_MODE_OFF:
      options.fairing.mode = FairingMode::kOff;
      break;
    case v1::FAIRING_MODE_WEIGHT:
      options.fairing.mode = FairingMode::kWeight;
      break;
    case v1::FAIRING_MODE_TO_TOLERANCE:
      options.fairing.mode = FairingMode::kToTolerance;
      break;
    default:
      return Invalid(field, ".fairing.mode = ", static_cast<int>(stored.fairing().mode()),
                     " is not OFF, WEIGHT or TO_TOLERANCE");
  }
  options.fairing.weight = stored.fairing().weight();
  if (absl::Status s = options.fairing.Validate(); !s.ok()) return Annotate(s, field + ".fairing");
  for (int q = 0; q < stored.face_kinds_size(); ++q) {
    const v1::FaceKind& entry = stored.face_kinds(q);
    const std::string at = absl::StrCat(field, ".face_kinds[", q, "]");
    SG_ASSIGN_OR_RETURN(const Face face, ParseBlockFace(entry.block(), entry.face(), at));
    SG_ASSIGN_OR_RETURN(const BoundaryKind kind, ParseKind(entry.kind(), at + ".kind"));
    options.face_kinds.push_back({face, kind});
  }
  options.check_quality = stored.check_quality();
  options.allow_folds = stored.allow_folds();
  if (stored.relative_kinds() > kAllKindsRelative) {
    return Invalid(field, ".relative_kinds = ", stored.relative_kinds(), " is not a mask of ",
                   static_cast<int>(kAllKindsRelative));
  }
  options.relative_kinds = static_cast<uint8_t>(stored.relative_kinds());
  if (stored.has_reference_length()) options.reference_length = stored.reference_length();
  return options;
}

// ---- DeformationCheck ----

void EncodeDeformationCheck(const DeformationCheck& check, v1::StoredDeformationCheck* out) {
  out->set_level(check.level);
  out->set_cells_checked(check.cells_checked);
  out->set_folded(check.folded);
  out->set_min_jacobian_ratio(check.min_jacobian_ratio);
  out->set_max_jacobian_ratio(check.max_jacobian_ratio);
  out->set_worst_block(check.worst_block);
  EncodeExtents(check.worst_cell, out->mutable_worst_cell());
  out->set_max_orthogonality_change_degrees(check.max_orthogonality_change_degrees);
  out->set_wall_samples(check.wall_samples);
}

absl::StatusOr<DeformationCheck> ParseDeformationCheck(const v1::StoredDeformationCheck& stored,
                                                       const std::string& field) {
  DeformationCheck check;
  check.level = stored.level();
  if (check.level < 0 || check.level > kMaxRefinementLevel) {
    return Invalid(field, ".level = ", check.level, " is outside [0, ", kMaxRefinementLevel, "]");
  }
  check.cells_checked = stored.cells_checked();
  check.folded = stored.folded();
  check.min_jacobian_ratio = stored.min_jacobian_ratio();
  check.max_jacobian_ratio = stored.max_jacobian_ratio();
  check.worst_block = stored.worst_block();
  check.worst_cell = ParseExtents(stored.worst_cell());
  check.max_orthogonality_change_degrees = stored.max_orthogonality_change_degrees();
  check.wall_samples = stored.wall_samples();
  SG_RETURN_IF_ERROR(CheckNonNegative(check.cells_checked, field + ".cells_checked"));
  SG_RETURN_IF_ERROR(CheckNonNegative(check.folded, field + ".folded"));
  SG_RETURN_IF_ERROR(CheckNonNegative(check.worst_block, field + ".worst_block"));
  SG_RETURN_IF_ERROR(CheckNonNegative(check.wall_samples, field + ".wall_samples"));
  return check;
}

}  // namespace splinegrid
