#include "core/deform/rigid_motion.h"

#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"

namespace splinegrid {

absl::Status RigidMotion::Validate() const {
  for (const auto& [field, vector] :
       {std::pair{"center", &center}, {"axis", &axis}, {"translation", &translation}}) {
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite((*vector)[c])) {
        return absl::InvalidArgumentError(
            absl::StrCat("motion: ", field, "[", c, "] = ", (*vector)[c], " is not finite"));
      }
    }
  }
  if (!std::isfinite(angle)) {
    return absl::InvalidArgumentError(absl::StrCat("motion: angle = ", angle, " is not finite"));
  }
  if (axis[0] == 0.0 && axis[1] == 0.0 && axis[2] == 0.0) {
    return absl::InvalidArgumentError("motion: axis = (0, 0, 0); a rotation needs a direction");
  }
  return absl::OkStatus();
}

Point3 RigidMotion::Apply(const Point3& x, double fraction) const {
  const double a = fraction * angle;
  if (a == 0.0) {  // a translation: exact, and the identity leaves x bitwise unchanged
    return {x[0] + fraction * translation[0], x[1] + fraction * translation[1],
            x[2] + fraction * translation[2]};
  }
  const double norm = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  const Point3 k = {axis[0] / norm, axis[1] / norm, axis[2] / norm};
  const Point3 v = {x[0] - center[0], x[1] - center[1], x[2] - center[2]};
  const double cos_a = std::cos(a), sin_a = std::sin(a);
  const double kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
  const Point3 kxv = {k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2],
                      k[0] * v[1] - k[1] * v[0]};
  Point3 out;
  for (int c = 0; c < 3; ++c) {
    out[c] = center[c] + v[c] * cos_a + kxv[c] * sin_a + k[c] * kv * (1.0 - cos_a) +
             fraction * translation[c];
  }
  return out;
}

}  // namespace splinegrid
