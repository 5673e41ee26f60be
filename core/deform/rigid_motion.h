// A rigid motion of space: a rotation by `angle` about the axis through `center` along `axis`,
// followed by a translation, and the same motion carried out only in part, for blending.
//
//   M(x) = c + R(angle) (x - c) + t,
//   M_f(x) = c + R(f angle) (x - c) + f t           (0 <= f <= 1),
// with R the rotation of Rodrigues' formula, R(a) v = v cos a + (k x v) sin a + k (k . v)(1 - cos
// a) for the unit axis k. M_1 = M and M_0 is the identity. Blending rotations by their angle rather
// than by displacement keeps points at their distance from the axis: the linear blend
// (1 - f) x + f M(x) pulls points towards the centre by up to 1 - cos(angle / 2) (1.5% at 20
// degrees), which shrinks the cells of a blending zone.
//
// In 2D (z = 0) the axis is z and a positive angle turns counter-clockwise.
#ifndef SPLINEGRID_CORE_DEFORM_RIGID_MOTION_H_
#define SPLINEGRID_CORE_DEFORM_RIGID_MOTION_H_

#include "absl/status/status.h"
#include "core/bspline/evaluation.h"

namespace splinegrid {

struct RigidMotion {
  Point3 center = {0.0, 0.0, 0.0};
  Point3 axis = {0.0, 0.0, 1.0};  // need not be unit length; not zero
  double angle = 0.0;             // radians
  Point3 translation = {0.0, 0.0, 0.0};

  // INVALID_ARGUMENT naming the field for non-finite values or a zero axis.
  absl::Status Validate() const;
  // M_fraction(x) (file comment).
  Point3 Apply(const Point3& x, double fraction = 1.0) const;
};

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_DEFORM_RIGID_MOTION_H_
