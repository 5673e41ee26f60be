#include "core/bspline/differential_geometry.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/util/check.h"

namespace splinegrid {
namespace {

Point3 Cross(const Point3& a, const Point3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

double Norm(const Point3& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

// The partial derivative of order `order` in direction d.
const Point3& Partial(const PartialDerivatives& ders, int d, int order) {
  return ders(d == 0 ? order : 0, d == 1 ? order : 0, d == 2 ? order : 0);
}

}  // namespace

absl::StatusOr<int> CurveDirection(const TensorSpline& spline) {
  const Extents n = spline.control_extents();
  if (spline.active_directions() != 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("a curve has one direction with more than one "
                     "control point; this spline has ",
                     n[0], " x ", n[1], " x ", n[2]));
  }
  return n[0] > 1 ? 0 : n[1] > 1 ? 1 : 2;
}

double CurveCurvature(const TensorSpline& spline, int direction, double u) {
  SG_CHECK(direction >= 0 && direction < 3);
  Point3 uvw = {0.0, 0.0, 0.0};
  uvw[direction] = u;
  const PartialDerivatives ders = EvaluateDerivatives(spline, uvw, 2);
  const Point3& d1 = Partial(ders, direction, 1);
  const Point3& d2 = Partial(ders, direction, 2);
  const double speed = Norm(d1);
  if (!(speed > 0.0)) return 0.0;
  const Point3 cross = Cross(d1, d2);
  const double numerator = spline.spatial_dim() == 2 ? cross[2] : Norm(cross);
  return numerator / (speed * speed * speed);
}

Point3 SurfaceNormal(const TensorSpline& spline, int d0, int d1, const Point3& uvw) {
  SG_CHECK(d0 >= 0 && d0 < d1 && d1 < 3);
  const PartialDerivatives ders = EvaluateDerivatives(spline, uvw, 1);
  Point3 n = Cross(Partial(ders, d0, 1), Partial(ders, d1, 1));
  const double length = Norm(n);
  if (!(length > 0.0)) return {0.0, 0.0, 0.0};
  for (double& c : n) c /= length;
  return n;
}

}  // namespace splinegrid
