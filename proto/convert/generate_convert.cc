#include "proto/convert/generate_convert.h"

#include <cmath>
#include <initializer_list>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"

namespace splinegrid {
namespace {

// INVALID_ARGUMENT "<field> is set: <why>" for the first field of `fields` (set, name) that is
// set: a field of the other kind of generation.
absl::Status RefuseSetFields(std::initializer_list<std::pair<bool, const char*>> fields,
                             const char* why) {
  for (const auto& [set, field] : fields) {
    if (set) return absl::InvalidArgumentError(absl::StrCat(field, " is set: ", why));
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<ProfileGridOptions> ParseProfileGridOptions(const v1::GenerateGridRequest& request) {
  ProfileGridOptions options;
  switch (request.method()) {
    case v1::LAYER_METHOD_UNSPECIFIED:
    case v1::LAYER_METHOD_OFFSETS:
      options.method = LayerMethod::kOffsets;
      break;
    case v1::LAYER_METHOD_TRANSFINITE:
      options.method = LayerMethod::kTransfinite;
      break;
    case v1::LAYER_METHOD_ELLIPTIC:
      options.method = LayerMethod::kElliptic;
      break;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat("method = ", static_cast<int>(request.method()), " is not a known value"));
  }
  SG_RETURN_IF_ERROR(RefuseSetFields({{request.side() != v1::MARCH_SIDE_OUTWARD, "side"},
                                      {request.has_normal_smoothing(), "normal_smoothing"},
                                      {request.has_symmetry_planes(), "symmetry_planes"}},
                                     "it applies to a stored_surface, not to a profile"));
  if (request.has_wall_points()) options.wall_points = request.wall_points();
  if (request.has_layers()) options.layers = request.layers();
  if (request.has_first_height()) options.first_height = request.first_height();
  if (request.has_distance()) options.distance = request.distance();
  if (request.has_orthogonalize()) options.orthogonalize = request.orthogonalize();
  if (request.has_fit_tolerance()) options.fit_tolerance = request.fit_tolerance();
  SG_RETURN_IF_ERROR(options.Validate());
  return options;
}

void EncodeProfileGridOptions(const ProfileGridOptions& options, v1::GenerateGridRequest* out) {
  switch (options.method) {
    case LayerMethod::kOffsets:
      out->set_method(v1::LAYER_METHOD_OFFSETS);
      break;
    case LayerMethod::kTransfinite:
      out->set_method(v1::LAYER_METHOD_TRANSFINITE);
      break;
    case LayerMethod::kElliptic:
      out->set_method(v1::LAYER_METHOD_ELLIPTIC);
      break;
  }
  out->set_wall_points(options.wall_points);
  out->set_layers(options.layers);
  if (options.first_height) out->set_first_height(*options.first_height);
  if (options.distance) out->set_distance(*options.distance);
  out->set_orthogonalize(options.orthogonalize);
  if (options.fit_tolerance) out->set_fit_tolerance(*options.fit_tolerance);
}

absl::StatusOr<StructuredBlock> ParseProfilePoints(const v1::ProfilePoints& points,
                                                   const std::string& field) {
  const int values = points.xy_size();
  if (values % 2 != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".xy has ", values, " values, an odd count: give x, y pairs"));
  }
  if (values < 10) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".xy has ", values / 2, " points; a profile needs at least 5"));
  }
  for (int q = 0; q < values; ++q) {
    if (!std::isfinite(points.xy(q))) {
      return absl::InvalidArgumentError(absl::StrCat(field, ".xy[", q, "] = ", points.xy(q), " (",
                                                     q % 2 == 0 ? "x" : "y", " of point ", q / 2,
                                                     ") is not finite"));
    }
  }
  StructuredBlock block({values / 2, 1, 1}, 2);
  std::copy(points.xy().begin(), points.xy().end(), block.coords().begin());
  return block;
}

void EncodeGenerationReport(const ProfileGrid& grid, const Extents& extents, int64_t profile_points,
                            v1::GenerationReport* out) {
  EncodeExtents(extents, out->mutable_extents());
  v1::ProfileFitReport* profile = out->mutable_profile();
  profile->set_num_points(static_cast<int32_t>(profile_points));
  profile->set_num_control_points(grid.profile.num_control_points);
  profile->set_max_deviation(grid.profile.max_deviation);
  profile->set_sharp_trailing_edge(grid.profile.sharp_trailing_edge);
  profile->set_features(static_cast<int32_t>(grid.profile.features.size()));
  profile->set_fairing_weight(grid.profile.fairing_weight);
  out->set_growth_ratio(grid.growth_ratio);
  out->set_retries(grid.retries);
  out->set_marched_layers(grid.marched_layers);
  if (grid.coarse_sweeps > 0 || grid.fine_sweeps > 0) {
    v1::EllipticReport* elliptic = out->mutable_elliptic();
    elliptic->set_converged(grid.elliptic_converged);
    elliptic->set_coarse_sweeps(grid.coarse_sweeps);
    elliptic->set_fine_sweeps(grid.fine_sweeps);
    elliptic->set_restarts(grid.elliptic_restarts);
    elliptic->set_relaxation(grid.elliptic_relaxation);
    elliptic->set_coarse_seconds(grid.coarse_seconds);
    elliptic->set_fine_seconds(grid.fine_seconds);
  }
  const OGridQuality& q = grid.quality;
  v1::OGridQuality* quality = out->mutable_quality();
  quality->set_negative_cells(q.negative_cells);
  quality->set_min_cell_area(q.min_cell_area);
  quality->set_first_height_min(q.first_height_min);
  quality->set_first_height_max(q.first_height_max);
  quality->set_wall_orthogonality_degrees(q.wall_orthogonality_degrees);
  quality->set_outer_distance_min(q.outer_distance_min);
  quality->set_outer_distance_max(q.outer_distance_max);
  quality->set_self_intersecting_layers(q.self_intersecting_layers);
  quality->set_first_self_intersecting_layer(q.first_self_intersecting_layer);
  out->set_wall_corners(static_cast<int32_t>(grid.wall.corners.size()));
  out->set_fit_seconds(grid.fit_seconds);
  out->set_wall_seconds(grid.wall_seconds);
  out->set_layer_seconds(grid.layer_seconds);
  out->set_measure_seconds(grid.measure_seconds);
}

absl::StatusOr<SurfaceOffsetOptions> ParseSurfaceOffsetOptions(
    const v1::GenerateGridRequest& request) {
  if (request.method() != v1::LAYER_METHOD_UNSPECIFIED &&
      request.method() != v1::LAYER_METHOD_OFFSETS) {
    return absl::InvalidArgumentError(absl::StrCat(
        "method = ", v1::LayerMethod_Name(request.method()),
        ": layers off a surface are marched (OFFSETS); transfinite and elliptic grids are made "
        "around profiles only"));
  }
  SG_RETURN_IF_ERROR(RefuseSetFields({{request.has_wall_points(), "wall_points"},
                                      {request.has_orthogonalize(), "orthogonalize"},
                                      {request.has_fit_tolerance(), "fit_tolerance"}},
                                     "it applies to profiles; a stored_surface keeps its own "
                                     "points"));
  SurfaceOffsetOptions options;
  if (request.has_layers()) options.layers = request.layers();
  if (request.has_first_height()) options.first_height = request.first_height();
  if (request.has_distance()) options.distance = request.distance();
  switch (request.side()) {
    case v1::MARCH_SIDE_OUTWARD:
      options.outward = true;
      break;
    case v1::MARCH_SIDE_ALONG_NORMAL:
      options.side = +1;
      break;
    case v1::MARCH_SIDE_AGAINST_NORMAL:
      options.side = -1;
      break;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat("side = ", static_cast<int>(request.side()), " is not a known value"));
  }
  if (request.has_normal_smoothing()) options.normal_smoothing = request.normal_smoothing();
  if (request.has_symmetry_planes()) options.symmetry_planes = request.symmetry_planes();
  SG_RETURN_IF_ERROR(options.Validate());
  return options;
}

void EncodeSurfaceOffsetOptions(const SurfaceOffsetOptions& options, v1::GenerateGridRequest* out) {
  out->set_method(v1::LAYER_METHOD_OFFSETS);
  out->set_layers(options.layers);
  out->set_first_height(options.first_height);
  out->set_distance(options.distance);
  out->set_side(options.outward    ? v1::MARCH_SIDE_OUTWARD
                : options.side > 0 ? v1::MARCH_SIDE_ALONG_NORMAL
                                   : v1::MARCH_SIDE_AGAINST_NORMAL);
  out->set_normal_smoothing(options.normal_smoothing);
  out->set_symmetry_planes(options.symmetry_planes);
}

void EncodeVolumeReport(const SurfaceOffsetGrid& grid, const std::vector<Extents>& extents,
                        const std::vector<bool>& reversed_i, v1::VolumeReport* out) {
  out->set_blocks(static_cast<int32_t>(extents.size()));
  for (const Extents& e : extents) EncodeExtents(e, out->add_block_extents());
  for (bool reversed : reversed_i) out->add_reversed_i(reversed);
  for (const SymmetryPlane& plane : grid.symmetry_planes) {
    v1::SymmetryPlane* p = out->add_symmetry_planes();
    p->set_axis(std::string(1, "xyz"[plane.axis]));
    p->set_value(plane.value);
  }
  out->set_components(grid.components);
  out->set_surface_gap(grid.surface_gap);
  out->set_refits_dropped(grid.refits_dropped);
  out->set_limited_steps(grid.limited_steps);
  out->set_shortfall(grid.shortfall);
  out->set_min_scaled_jacobian(grid.min_scaled_jacobian);
  out->set_crease_vertices(grid.crease_vertices);
}

}  // namespace splinegrid
