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

std::vector<BlockControlDisplacements> ParseControlMotion(const v1::ControlMotion& motion) {
  std::vector<BlockControlDisplacements> out;
  out.reserve(motion.blocks_size());
  for (const v1::ControlDisplacements& given : motion.blocks()) {
    out.push_back({given.block(),
                   std::vector<int64_t>(given.controls().begin(), given.controls().end()),
                   std::vector<double>(given.values().begin(), given.values().end())});
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

absl::StatusOr<DeformMotion> ParseDeformMotion(const v1::DeformGridRequest& request) {
  switch (request.motion_case()) {
    case v1::DeformGridRequest::kRigid: {
      SG_ASSIGN_OR_RETURN(RigidMotion rigid, ParseRigidMotion(request.rigid()));
      return rigid;
    }
    case v1::DeformGridRequest::kControls:
      return ParseControlMotion(request.controls());
    case v1::DeformGridRequest::kBoundaryPoints: {
      SG_ASSIGN_OR_RETURN(std::vector<BoundaryPoints> points,
                          ParseBoundaryPoints(request.boundary_points()));
      return points;
    }
    case v1::DeformGridRequest::MOTION_NOT_SET:
      break;
  }
  return absl::InvalidArgumentError("motion is unset: give rigid, controls or boundary_points");
}

void EncodeDeformationCheck(const DeformationCheck& check, v1::DeformReport* out) {
  out->set_check_level(check.level);
  out->set_cells_checked(check.cells_checked);
  if (check.cells_checked > 0) {
    out->set_min_jacobian_ratio(check.min_jacobian_ratio);
    out->set_max_jacobian_ratio(check.max_jacobian_ratio);
    out->set_worst_block(check.worst_block);
    EncodeExtents(check.worst_cell, out->mutable_worst_cell());
  }
  out->set_max_orthogonality_change_degrees(check.max_orthogonality_change_degrees);
}

}  // namespace splinegrid
