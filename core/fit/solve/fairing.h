// Fairing: the penalty that keeps a least-squares spline from wriggling between its data.
//
// A spline of order k is a polynomial of degree k - 1 on every knot span, so its (k - 1)-th
// derivative is piecewise constant and only jumps at the knots. At a simple interior knot t_q
// the jump
//   J_q(P) = s^(k-1)(t_q+) - s^(k-1)(t_q-) = sum_j (N_j^(k-1)(t_q+) - N_j^(k-1)(t_q-)) P_j
// involves the k + 1 controls P_{q-k} .. P_q. For cubics (k = 4) it is the jump of the third
// derivative; on uniform knots of width h, h^3 J_q = P_{q-4} - 4 P_{q-3} + 6 P_{q-2} - 4 P_{q-1}
// + P_q, a fourth difference of neighbouring control points. A spline whose jumps vanish is a
// single polynomial, so penalising them pulls the fit towards the smoothest shape the data
// allow. The fit minimises
//   sum_r |s(u_r) - x_r|^2 + lambda sum_q m_q (h_q^(k-1) J_q)^2,
// with h_q the mean width of the two spans beside t_q and m_q the mean number of data points in
// them. The factor h_q^(k-1) makes each term a length, independent of how the parameter is
// scaled, and m_q makes lambda the ratio of the penalty to the squared residuals it competes
// with, so one lambda means the same on coarse and dense data. Both are local, so a segment
// shared by two blocks (same parameters and knots there) gets the same rows in both. This is the
// smoothing criterion of Dierckx's FITPACK (P. Dierckx, "Curve and Surface Fitting with Splines",
// Oxford 1993, ch. 5) and the third-derivative fairing of the QUADFLOW B-spline grids; here lambda
// is given or searched for, not tied to a smoothing factor. The penalty rows join the data rows in
// the same banded QR (bandwidth k + 1 instead of k), so a faired fit still costs O(points).
//
// Knots of multiplicity > 1 (feature points, the splits of a multi-block model) are not
// penalised: their kink is deliberate.
#ifndef SPLINEGRID_CORE_FIT_SOLVE_FAIRING_H_
#define SPLINEGRID_CORE_FIT_SOLVE_FAIRING_H_

#include <span>
#include <vector>

#include "absl/status/status.h"
#include "core/bspline/knot_vector.h"
#include "core/fit/solve/direction_fit.h"

namespace splinegrid {

// How a tolerance fit is faired.
enum class FairingMode {
  kOff,          // plain least squares
  kWeight,       // every fit uses lambda = weight
  kToTolerance,  // the largest lambda <= weight that keeps every point within its tolerance
};

struct FairingOptions {
  FairingMode mode = FairingMode::kOff;
  // lambda for kWeight; the upper end of the search for kToTolerance.
  double weight = 1e4;

  // INVALID_ARGUMENT naming the field unless weight is positive and finite (mode kOff: any).
  absl::Status Validate() const;
};

// The weighted jump rows of `knots` for a fit of data at `params` (ascending) with weight
// `lambda` (>= 0; 0 or a spline without simple interior knots gives no rows).
std::vector<PenaltyRow> JumpPenaltyRows(const KnotVector& knots, std::span<const double> params,
                                        double lambda);

// The unweighted jumps J_q of the (k - 1)-th derivative of the 1D spline with `knots` and
// scalar `controls`, at every simple interior knot, times h_q^(k-1) (as penalised above).
std::vector<double> ScaledDerivativeJumps(const KnotVector& knots,
                                          const std::vector<double>& controls);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_SOLVE_FAIRING_H_
