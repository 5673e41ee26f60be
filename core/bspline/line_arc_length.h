// Arc length along a parameter line of a tensor spline: the curve t -> X(.., t, ..) in one
// direction with the other parameters fixed, and its inverse, the parameter at a given length.
//
//   s(t) = integral from begin to t of |dX/dt| dt.
//
// The line is first reduced to a curve (its control points along the direction, k^2 products
// per control point), and dX/dt on every knot interval to its Taylor polynomial, so that a
// speed costs one Horner evaluation. The integrand is smooth inside a knot span, so every span is
// split into four pieces integrated by 8-point Gauss-Legendre quadrature (exact for speeds that are
// polynomials of degree 15, about 1e-13 relative on the grids' cubic splines); the inverse is a
// safeguarded Newton iteration (ds/dt = |dX/dt|) inside the piece that holds the length,
// started from a cubic Hermite interpolation of t(s) over the piece.
#ifndef SPLINEGRID_CORE_BSPLINE_LINE_ARC_LENGTH_H_
#define SPLINEGRID_CORE_BSPLINE_LINE_ARC_LENGTH_H_

#include <vector>

#include "core/bspline/evaluation.h"
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
  // |dX/dt| at t in knot interval `interval`.
  double Speed(int interval, double t) const;
  // The integral of the speed over [a, b] inside one piece (8-point Gauss).
  double PieceLength(int interval, double a, double b) const;
  // The same over a Newton step (3-point Gauss).
  double StepLength(int interval, double a, double b) const;

  int degree_ = 0;
  // Per knot interval: its knot and the Taylor coefficients of dX/dt about it (degree_ each).
  std::vector<double> centers_;
  std::vector<Point3> coefficients_;
  // Per piece (four per knot interval): its interval; per piece end, from begin to end: the
  // parameter, the length from begin and the speed.
  std::vector<int> piece_interval_;
  std::vector<double> breaks_;
  std::vector<double> cumulative_;
  std::vector<double> speeds_;
};

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_BSPLINE_LINE_ARC_LENGTH_H_
