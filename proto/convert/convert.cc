#include "proto/convert/convert.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid {

void EncodeExtents(const Extents& extents, v1::Extents* out) {
  out->set_i(extents[0]);
  out->set_j(extents[1]);
  out->set_k(extents[2]);
}

Extents ParseExtents(const v1::Extents& extents) { return {extents.i(), extents.j(), extents.k()}; }

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
  return options;
}

void EncodeFitSpec(const GridFitOptions& options, v1::FitSpec* out) {
  out->set_order(options.order);
  out->set_parametrization(EncodeParametrization(options.parametrization));
  if (options.tolerance) {
    out->set_tolerance(*options.tolerance);
  } else {
    EncodeExtents(options.control_counts, out->mutable_control_counts());
  }
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
  for (int d = 0; d < 3; ++d) {
    const v1::SplineDirection& direction = block.directions(d);
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
  SG_ASSIGN_OR_RETURN(PointDistribution distribution, PointDistribution::Create(std::move(params)));
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
  return resolution;
}

}  // namespace splinegrid
