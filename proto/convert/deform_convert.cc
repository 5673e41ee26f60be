#include "proto/convert/deform_convert.h"

#include <map>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"

namespace splinegrid {

absl::StatusOr<DeformOptions> ParseDeformOptions(const v1::DeformGridRequest& request) {
  DeformOptions options;
  SG_ASSIGN_OR_RETURN(options.moved, ParseBoundarySelection(request.boundary()));
  switch (request.propagation()) {
    case v1::PROPAGATION_UNSPECIFIED:
    case v1::PROPAGATION_BLEND:
      options.propagation = Propagation::kBlend;
      break;
    case v1::PROPAGATION_TRANSFINITE:
      options.propagation = Propagation::kTransfinite;
      break;
    default:
      return absl::InvalidArgumentError(absl::StrCat(
          "propagation = ", static_cast<int>(request.propagation()), " is not a known value"));
  }
  options.rigid_radius = request.rigid_radius();
  options.decay_radius = request.decay_radius();
  options.smoothing_iterations = request.smoothing_iterations();
  SG_RETURN_IF_ERROR(options.Validate());
  return options;
}

absl::StatusOr<std::vector<double>> ParseControlDisplacements(const Deformer& deformer,
                                                              const v1::ControlMotion& motion) {
  const int s = deformer.reference().front().spline.spatial_dim();
  std::map<std::pair<int, int64_t>, size_t> index;
  for (size_t q = 0; q < deformer.moved_controls().size(); ++q) {
    index[deformer.moved_controls()[q]] = q;
  }
  std::vector<double> out(deformer.moved_controls().size() * s, 0.0);
  const int num_blocks = static_cast<int>(deformer.reference().size());
  for (int e = 0; e < motion.blocks_size(); ++e) {
    const v1::ControlDisplacements& given = motion.blocks(e);
    const std::string field = absl::StrCat("controls.blocks[", e, "]");
    if (given.block() < 0 || given.block() >= num_blocks) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".block = ", given.block(), " is outside [0, ", num_blocks - 1, "]"));
    }
    if (given.values_size() != s * given.controls_size()) {
      return absl::InvalidArgumentError(absl::StrCat(field, ": ", given.values_size(),
                                                     " values for ", given.controls_size(),
                                                     " controls of ", s, " coordinates"));
    }
    for (int q = 0; q < given.controls_size(); ++q) {
      const auto it = index.find({given.block(), given.controls(q)});
      if (it == index.end()) {
        return absl::InvalidArgumentError(absl::StrCat(
            field, ".controls[", q, "] = ", given.controls(q),
            " does not carry the moved boundary (or is no control of block ", given.block(), ")"));
      }
      for (int c = 0; c < s; ++c) out[s * it->second + c] = given.values(s * q + c);
    }
  }
  return out;
}

absl::StatusOr<std::vector<BoundaryPoints>> ParseBoundaryPoints(const v1::BoundaryPointsMotion& m) {
  std::vector<BoundaryPoints> out;
  for (int q = 0; q < m.ranges_size(); ++q) {
    const v1::BoundaryPointMotion& given = m.ranges(q);
    BoundaryPoints points;
    SG_ASSIGN_OR_RETURN(
        points.range,
        ParseFaceRange(given.range(), absl::StrCat("boundary_points.ranges[", q, "].range")));
    points.level = given.refinement_level();
    points.coordinates.assign(given.coordinates().begin(), given.coordinates().end());
    points.displacements = given.displacements();
    out.push_back(std::move(points));
  }
  return out;
}

}  // namespace splinegrid
