// Conversions of DeformGrid: the request's boundary selection and propagation options, and its
// control and boundary-point motions, to the kernel's (core/deform/deformer.h).
#ifndef SPLINEGRID_PROTO_CONVERT_DEFORM_CONVERT_H_
#define SPLINEGRID_PROTO_CONVERT_DEFORM_CONVERT_H_

#include <vector>

#include "absl/status/statusor.h"
#include "core/deform/deform_motion.h"
#include "core/deform/deform_quality.h"
#include "core/deform/deformer.h"
#include "splinegrid/v1/splinegrid_service.pb.h"

namespace splinegrid {

// The deformer's options (moved boundary, propagation, radii, smoothing), validated by
// DeformOptions::Validate (INVALID_ARGUMENT naming the field).
absl::StatusOr<DeformOptions> ParseDeformOptions(const v1::DeformGridRequest& request);

// The displacements of a ControlMotion as given, block by block (checked against a deformer by
// DisplacementsInDeformerOrder, core/deform/deform_motion.h).
std::vector<BlockControlDisplacements> ParseControlMotion(const v1::ControlMotion& motion);

// The request's motion (rigid, controls or boundary_points); INVALID_ARGUMENT when it is unset
// or a part is malformed (naming the field).
absl::StatusOr<DeformMotion> ParseDeformMotion(const v1::DeformGridRequest& request);

// The ranges of a BoundaryPointsMotion (positions or displacements at a refinement level).
absl::StatusOr<std::vector<BoundaryPoints>> ParseBoundaryPoints(const v1::BoundaryPointsMotion& m);

// What the fold gate measured (check level, Jacobian ratios and the worst cell when cells were
// checked, orthogonality change) into the deform report.
void EncodeDeformationCheck(const DeformationCheck& check, v1::DeformReport* out);

}  // namespace splinegrid

#endif  // SPLINEGRID_PROTO_CONVERT_DEFORM_CONVERT_H_
