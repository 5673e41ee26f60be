// Arc length along a parameter line of a tensor spline: the curve t -> X(.., t, ..) in one
// direction with the other parameters fixed, and its inverse, the parameter at a given length.
//
//   s(t) = integral from begin to t of |dX/dt| dt.
//
// The line is first reduced to a curve (its control points along the direction, k^2 products
// per control point). The integrand is smooth inside a knot span, so every span is split into
// four pieces integrated by 8-point Gauss-Legendre quadrature (exact for speeds that are
// polynomials of degree 15, about 1e-13 relative on the grids' cubic splines); the inverse is a
// safeguarded Newton iteration (ds/dt = |dX/dt|) inside the piece that holds the length.
#ifndef SPLINEGRID_CORE_BSPLINE_LINE_ARC_LENGTH_H_
#define SPLINEGRID_CORE_BSPLINE_LINE_ARC_LENGTH_H_

#include <vector>

#include "core/bspline/evaluation.h"
#include "core/bspline/knot_vector.h"
#include "core/bspline/tensor_spline.h"

namespace splinegrid {

class LineArcLength {
 public:
  // The line of `spline` in `direction` through the parameters `fixed` (its entry `direction`
  // is ignored; others are clamped into [0, 1]), measured over [begin, end] with
  // 0 <= begin <= end <= 1.
  LineArcLength(const TensorSpline& spline, int direction, const Point3& fixed, double begin,
                double end);

  double length() const { return cumulative_.back(); }
  // The parameter in [begin, end] where the length from `begin` is s (clamped into
  // [0, length()]). Exact at both ends; otherwise Length(ParameterAt(s)) = s to about 1e-13
  // of the piece's length. A line of zero length returns begin.
  double ParameterAt(double s) const;
  // The length from begin to t (t clamped into [begin, end]).
  double LengthAt(double t) const;

 private:
  // |dX/dt| of the reduced curve.
  double Speed(double t) const;
  // The integral of the speed over [a, b] inside one piece.
  double PieceLength(double a, double b) const;

  KnotVector knots_;
  int spatial_dim_;
  std::vector<double> control_;     // the curve's control points, spatial_dim_ each
  std::vector<double> breaks_;      // piece ends, begin .. end
  std::vector<double> cumulative_;  // length from begin to every break
};

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_BSPLINE_LINE_ARC_LENGTH_H_
