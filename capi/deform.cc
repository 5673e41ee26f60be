// splinegrid.h: deformations by a rigid motion of a boundary or by new boundary points.
#include <cstdint>

#include "absl/strings/str_cat.h"
#include "capi/client_state.h"
#include "capi/splinegrid.h"
#include "client/client.h"
#include "core/util/status_macros.h"

namespace {

namespace client = splinegrid::client;
namespace v1 = splinegrid::v1;

// The request's stamp, checks and moved boundary from `options` (NULL: all zero).
absl::StatusOr<v1::DeformGridRequest> BaseRequest(const char* grid,
                                                  const sg_deform_options* options) {
  SG_RETURN_IF_ERROR(splinegrid::capi::RequireString(grid, "grid"));
  const sg_deform_options o = options == nullptr ? sg_deform_options{} : *options;
  v1::DeformGridRequest request;
  request.set_name(client::GridName(grid));
  request.set_reference_revision(o.reference_revision);
  request.set_base_revision(o.base_revision);
  request.set_time(o.time);
  request.set_step(o.step);
  request.set_check_level(o.check_level);
  request.set_max_boundary_error(o.max_boundary_error);  // the server names a bad one
  if (o.boundary_kind != 0) {
    if (!v1::BoundaryKind_IsValid(o.boundary_kind)) {
      return absl::InvalidArgumentError(absl::StrCat("options.boundary_kind: ", o.boundary_kind,
                                                     " (0 or 1 walls, 2 interfaces, 3 outer)"));
    }
    request.mutable_boundary()->add_kinds(static_cast<v1::BoundaryKind>(o.boundary_kind));
  }
  return request;
}

// Deforms and fills `result` (may be NULL).
absl::Status Deform(sg_client* c, const v1::DeformGridRequest& request, sg_deform_result* result) {
  SG_ASSIGN_OR_RETURN(client::Client * connected, c->state->Connected());
  SG_ASSIGN_OR_RETURN(const v1::DeformGridResponse moved, connected->Deform(request));
  if (result != nullptr) {
    const v1::DeformReport& r = moved.report();
    *result = sg_deform_result{moved.revision(),  r.min_jacobian_ratio(), r.max_jacobian_ratio(),
                               r.seconds(),       r.moved_controls(),     0,
                               r.boundary_error()};
  }
  return absl::OkStatus();
}

}  // namespace

extern "C" {

sg_status sg_deform_rigid(sg_client* c, const char* grid, const sg_deform_options* options,
                          double angle_degrees, const double center[3], const double translation[3],
                          sg_deform_result* result) {
  if (c == nullptr) return SG_INVALID_ARGUMENT;
  return splinegrid::capi::Guard(c->state.get(), [&]() -> absl::Status {
    SG_ASSIGN_OR_RETURN(v1::DeformGridRequest request, BaseRequest(grid, options));
    v1::RigidMotion* rigid = request.mutable_rigid();
    rigid->set_angle_degrees(angle_degrees);  // the server names a non-finite angle
    for (int d = 0; center != nullptr && d < 3; ++d) rigid->add_center(center[d]);
    for (int d = 0; translation != nullptr && d < 3; ++d) rigid->add_translation(translation[d]);
    return Deform(c, request, result);
  });
}

sg_status sg_deform_points(sg_client* c, const char* grid, const sg_deform_options* options,
                           int32_t block, int32_t face, const int32_t begin[3],
                           const int32_t end[3], int32_t level, const double* points, int64_t count,
                           int32_t displacements, sg_deform_result* result) {
  if (c == nullptr) return SG_INVALID_ARGUMENT;
  return splinegrid::capi::Guard(c->state.get(), [&]() -> absl::Status {
    SG_ASSIGN_OR_RETURN(v1::DeformGridRequest request, BaseRequest(grid, options));
    if (face < SG_FACE_I_MIN || face > SG_FACE_K_MAX) {
      return absl::InvalidArgumentError(absl::StrCat("face: ", face, " (SG_FACE_*: 1 to 6)"));
    }
    if (begin == nullptr || end == nullptr) {
      return absl::InvalidArgumentError(begin == nullptr ? "begin: NULL" : "end: NULL");
    }
    if (count < 0 || (count > 0 && points == nullptr)) {
      return absl::InvalidArgumentError(
          absl::StrCat("points: ", points == nullptr ? "NULL" : "given", " with count ", count));
    }
    v1::BoundaryPointMotion* motion = request.mutable_boundary_points()->add_ranges();
    v1::FaceRange* range = motion->mutable_range();
    range->set_block(block);
    range->set_face(static_cast<v1::BlockFace>(face));
    range->mutable_begin()->set_i(begin[0]);
    range->mutable_begin()->set_j(begin[1]);
    range->mutable_begin()->set_k(begin[2]);
    range->mutable_end()->set_i(end[0]);
    range->mutable_end()->set_j(end[1]);
    range->mutable_end()->set_k(end[2]);
    motion->set_refinement_level(level);
    motion->set_displacements(displacements != 0);
    // The server checks the count against the range's points ("7 values for 11").
    motion->mutable_coordinates()->Add(points, points + count);
    return Deform(c, request, result);
  });
}

}  // extern "C"
