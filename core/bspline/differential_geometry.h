// Differential geometry of spline curves and surfaces: curvature and normals.
#ifndef SPLINEGRID_CORE_BSPLINE_DIFFERENTIAL_GEOMETRY_H_
#define SPLINEGRID_CORE_BSPLINE_DIFFERENTIAL_GEOMETRY_H_

#include "absl/status/statusor.h"
#include "core/bspline/evaluation.h"
#include "core/bspline/tensor_spline.h"

namespace splinegrid {

// The direction of a curve: the only direction with more than one control point.
// INVALID_ARGUMENT if the spline is not a curve.
absl::StatusOr<int> CurveDirection(const TensorSpline& spline);

// Curvature of a curve at parameter u:
//   2D: signed, kappa = (x' y'' - y' x'') / |C'|^3 (positive turning left);
//   3D: kappa = |C' x C''| / |C'|^3 >= 0.
// Zero where C' vanishes. Precondition: `direction` is the curve's direction.
double CurveCurvature(const TensorSpline& spline, int direction, double u);

// Unit normal (S_u x S_v) / |S_u x S_v| of a surface whose two directions are `d0` < `d1`,
// at the parameter point uvw; zero where the surface is singular. 3D splines only.
Point3 SurfaceNormal(const TensorSpline& spline, int d0, int d1, const Point3& uvw);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_BSPLINE_DIFFERENTIAL_GEOMETRY_H_
