// The least-squares curve fits behind FitAirfoil (airfoil_fit.h): a planar clamped B-spline
// fitted to an outline's points, with parameter correction so that the residual is the true
// distance from each point to the curve. Internal to the airfoil fit, but a header of its own so
// the fitting machinery can be read and tested apart from the knot placement and fairing that
// drive it.
//
// One fit, for interior knots t and parameters u_i of the m data points Q_i:
//  - Least squares with interpolated ends (DirectionFit, one banded QR applied to x and y), with
//    the fairing rows of a Penalty (fairing.h, JumpPenaltyRows) when its lambda is positive. The
//    anchors (the end points and the feature points) keep their parameters: a feature gets a
//    knot of multiplicity order - 1 at its parameter u_r, where only N_{span - k + 1} is nonzero
//    (and 1), so pinning that control makes the curve pass through Q_r.
//  - Parameter correction: each u_i is replaced by the foot of Q_i on the curve, Newton on
//      f(u) = C'(u).(C(u) - Q_i),   f'(u) = |C'|^2 + C''.(C - Q_i)
//    (L. Piegl and W. Tiller, "The NURBS Book", 2nd ed., 1997, eq. 6.3), kept inside the point's
//    segment between anchors, and the curve refitted, until a round gains less than 1% of the
//    sum of squared distances (J. Hoschek, "Intrinsic parametrization for approximation", CAGD
//    5(1), 1988). Hoschek's iteration converges linearly: a few rounds take most of the gain,
//    then the parameters drift along the curve for little (0.2% over 100 rounds on RAE 2822).
//    Correction also ends, keeping the previous parameters, when the feet cannot be made
//    strictly increasing (restoring the old parameter of every point out of order) or no longer
//    determine every control (Schoenberg-Whitney).
// Focal points. The foot map of a point Q at signed distance h along the normal of C(u) has
// derivative du/ds = 1 / (|C'| (1 - kappa h)) with respect to arc length s along the data: on the
// convex side of a bend (kappa h < 0) the feet crowd together by 1 / (1 + |kappa h|), and beyond
// the centre of curvature (kappa h >= 1) they fold. An early fit with few controls bends much
// more tightly than the data at the nose, so Hoschek's correction then crowds hundreds of points
// of a dense outline into one knot span and leaves its neighbour without data; the least-squares
// piece there is undetermined by its own data and loops (a cusp the distances cannot see), and no
// split can help because the span has no data to split (the failure of 12,000-point outlines that
// a quarter of their points fitted). set_max_focal_ratio restricts the correction to regular feet,
// |kappa| d <= ratio; FitAirfoil uses it when the unrestricted placement fails (airfoil_fit.h).
// A solve costs O(m k^2) (banded QR); a projection O(k^2 + log n) per point and Newton step,
// 2-4 steps from the previous foot.
#ifndef SPLINEGRID_CORE_FIT_AIRFOIL_PROFILE_FITTER_H_
#define SPLINEGRID_CORE_FIT_AIRFOIL_PROFILE_FITTER_H_

#include <algorithm>
#include <limits>
#include <span>
#include <vector>

#include "absl/status/statusor.h"
#include "core/bspline/knot_vector.h"
#include "core/fit/solve/direction_fit.h"
#include "core/util/cancellation.h"

namespace splinegrid {

// A planar clamped B-spline curve: knots and controls (x, y interleaved).
struct Curve {
  KnotVector knots;
  std::vector<double> control;
};

// The fairing penalty of a fit: weight lambda and a factor per jump row (empty: all 1).
struct Penalty {
  double lambda = 0.0;
  std::vector<double> row_scale;
};

// Points and derivatives up to `max_derivative` of `curve` at `u`:
// out[(q (max_derivative + 1) + d) 2 + c] = d^d C_c / du^d (u_q).
void EvaluateJet(const Curve& curve, std::span<const double> u, int max_derivative,
                 std::vector<double>& out);

// Signed curvature (x' y'' - y' x'') / |C'|^3 from a jet entry {x, y, x', y', x'', y''}; 0 where
// the speed |C'| vanishes.
double JetCurvature(const double* x);

// The least-squares curve fits of one outline: data, anchors (end and feature points, whose
// parameters stay fixed) and the knots and pins that go with them (file comment).
class ProfileFitter {
 public:
  // `fit_data`: the points the curve is fitted to (a sharp trailing edge merged); `data`: the
  // points distances are measured to. Both m x 2, interleaved. `features`: data indices of the
  // feature points, ascending, strictly between 0 and m - 1. At most `max_corrections`
  // parameter-correction rounds per fit. `cancel` is polled before every solve and must outlive
  // the fitter.
  ProfileFitter(std::vector<double> fit_data, std::vector<double> data, int order,
                const std::vector<int>& features, int max_corrections, const CancelCheck& cancel);

  // 0, the features, m - 1.
  const std::vector<int>& anchors() const { return anchors_; }
  // Least-squares solves so far, parameter corrections included.
  int fits() const { return fits_; }
  // Controls of the curve with the given interior knots.
  int NumControls(const std::vector<double>& interior) const {
    return order_ + static_cast<int>(interior.size());
  }

  // The clamped knot vector with the given interior knots (feature knots repeated).
  absl::StatusOr<KnotVector> Knots(const std::vector<double>& interior) const;

  // Pins of the feature controls: at a knot of multiplicity order - 1 at u_r only
  // N_{span - k + 1} is nonzero (and 1), so that control is the curve point.
  std::vector<Pin> FeaturePins(const KnotVector& knots, std::span<const double> params) const;

  // Whether the data at `params` determine every control of `knots` (Schoenberg-Whitney).
  bool WellPosed(const KnotVector& knots, std::span<const double> params) const;
  bool WellPosed(const std::vector<double>& interior, std::span<const double> params) const;

  // Restricts parameter correction to regular feet: a point Q at distance d from its foot C(u),
  // where the curve's curvature is kappa, moves to u only when |kappa| d <= ratio; else it keeps
  // its parameter. Infinity (the default): every foot is taken. Why (file comment, "Focal
  // points"): near a bend of the curve tighter than the data's, the foot map Q -> u contracts
  // parameter spacing by 1 / (1 + |kappa| d) on the convex side and folds beyond the centre of
  // curvature (|kappa| d >= 1) on the concave side.
  void set_max_focal_ratio(double ratio) { max_focal_ratio_ = ratio; }

  // Least squares with `penalty` and parameter correction (file comment): fit, move every
  // parameter to its foot on the curve, refit, ... for at most max_rounds rounds (and
  // max_corrections), until a round gains less than 1% (kSettledGain). On return `params` are
  // the feet on the returned curve, strictly increasing (or, with no correction, as given).
  // Errors: those of the knots and the solve; CANCELLED.
  absl::StatusOr<Curve> Fit(const std::vector<double>& interior, const Penalty& penalty,
                            std::vector<double>& params, int max_rounds);

  // Moves every parameter but the anchors' to the foot of its data point on `curve` and writes
  // the distances (when `distance` is not null): Newton on f(u) = C'(u).(C(u) - Q),
  // f'(u) = |C'|^2 + C''.(C - Q) (P&T eq. 6.3), from the current parameter, kept inside the
  // point's segment between anchors, until the step is below kFootTolerance (1e-13) or after
  // kMaxNewtonSteps (12); the closest iterate wins.
  void Project(const Curve& curve, std::vector<double>& u, std::vector<double>* distance) const;

 private:
  // Makes the corrected parameters `next` strictly increasing by restoring the old value of
  // every point that is out of order; false if that is not enough.
  bool KeepOrder(const std::vector<double>& old, std::vector<double>& next) const;
  // Restores the old parameter of every point whose foot is not regular (set_max_focal_ratio).
  void KeepRegularFeet(const Curve& curve, const std::vector<double>& old,
                       const std::vector<double>& distance, std::vector<double>& next) const;

  std::vector<double> fit_data_, data_;
  int m_;
  int order_;
  int max_corrections_;
  const CancelCheck& cancel_;
  std::vector<int> anchors_;  // 0, features, m - 1
  std::vector<int> segment_;  // per point: index a of the anchors' interval [a, a + 1] it is in
  double max_focal_ratio_ = std::numeric_limits<double>::infinity();
  int fits_ = 0;
};

// A fitted curve, the (strictly increasing) parameters it was fitted at, and the feet of the
// data points on it with their distances.
struct Fitted {
  Curve curve;
  std::vector<double> params, feet, distances;
  double lambda = 0.0;

  double max() const { return *std::max_element(distances.begin(), distances.end()); }
};

// Fit and distances at knots `interior`, starting from `params` (ProfileFitter::Fit, then
// ProfileFitter::Project from the fitted parameters).
absl::StatusOr<Fitted> FitAndMeasure(ProfileFitter& fitter, const std::vector<double>& interior,
                                     const Penalty& penalty, std::vector<double> params,
                                     int max_rounds = std::numeric_limits<int>::max());

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_AIRFOIL_PROFILE_FITTER_H_
