// Fitting an airfoil profile from its coordinates: few control points, within a tolerance of
// the true distance, faired, with a kink kept only where the data have one.
//
// The data are an outline in Selig order (trailing edge, upper surface, leading edge, lower
// surface, trailing edge; io/airfoil.h). The result is one clamped B-spline curve C(u),
// u in [0, 1], from trailing edge to trailing edge that passes through both end points:
//  - sharp trailing edge (the end points are within the tolerance of each other): both ends are
//    moved to their midpoint, so the curve is closed with a C0 corner at the trailing edge;
//  - blunt trailing edge: the curve is open, from one end point to the other.
// The leading edge (the point farthest from the trailing-edge midpoint) is never a feature. Other
// feature points are the kinks among DetectFeatures' points (refinement.h) that turn by at least
// twice as much as both neighbours: a tangent discontinuity stands out, a tight smooth bend
// sampled coarsely does not (the NACA 0012 file turns by 29.6 degrees at its nose point and 24.8
// at its neighbours). The turning is measured over chords of length L = 8 tol / theta (theta the
// spike angle and its doublings up to 180 degrees), where noise within the tolerance cannot turn
// by more than theta / 2 (OutlineFeatures in airfoil_fit.cc); on outlines sampled coarser than L
// those are the neighbouring segments. A feature gets a knot of multiplicity order - 1 and a
// pinned control.
//
// Algorithm (each least-squares fit costs O(points); 500-1,500 fits in all, about as many for
// 3,000 points as for 20,000):
//  1. Parameters u_i: centripetal by default (E. T. Y. Lee, "Choosing nodes in parametric curve
//     interpolation", CAD 21(6), 1989), which spaces the nose well.
//  2. Every fit is least squares with interpolated ends (DirectionFit, banded QR) followed by
//     parameter correction: each u_i is replaced by the foot of the data point on the curve
//     (Newton on f(u) = C'(u).(C(u) - Q_i), P&T eq. 6.3) and the curve refitted, until a round
//     gains less than 1% of the squared distances (J. Hoschek, "Intrinsic parametrization for
//     approximation", CAGD 5(1), 1988). The residual is then the true distance, and far fewer
//     controls meet a tolerance (RAE 2822 at 1e-4: 16 controls instead of 21, before merges).
//  3. Knots: from no interior knots, the knot span with the worst distance is split at the
//     middle of its data, one span per round, until every distance is within the target.
//     When insertion runs out of spans or controls, it is redone with parameter correction
//     restricted to regular feet, |kappa| d <= 1/2 (profile_fitter.h, "Focal points"): on dense
//     outlines the feet on an early, too tightly bent fit crowd into one span and leave its
//     neighbour without data, where the curve loops.
//     Coarse to fine: an outline of 2,000 points or more first places its knots (steps 3-4) on
//     every 4th point with the anchors (itself coarse to fine), and starts from those knots with
//     the parameters carried over (linear in chord length between the coarse points). The knots
//     and parameters evolve together, so where greedy insertion ends depends on the data it
//     sees: on all 12,268 points of the 30P30N main element at 1e-4 chord it ended with 26
//     controls, while the 23 of every 4th point, with their parameters, also fit all points.
//  4. Knot removal: interior knots are tried in order of their scaled third-derivative jump
//     (fairing.h; a small jump means the neighbouring pieces are nearly one polynomial, T. Lyche
//     and K. Morken, "A data reduction strategy for splines", IMA J. Numer. Anal. 8, 1988) and a
//     removal is kept when the refit still meets the target. Then merges: two neighbouring
//     simple knots are replaced by one between them (midway, else at a third), then three by
//     two (at the midpoints of their pairs, else at the thirds of their span), when the refit
//     meets the target. Insertion is greedy and removal one knot at a time, so the count they
//     reach depends on the path; a merge is a removal and a move in one step, which neither can
//     make alone (NACA 0012 at 1e-4: 13 controls without merges, 10 with).
//     Knot vectors are screened with three correction rounds (parameters warm-started from the
//     previous fit) and converged only when they miss the target by less than 50%.
//  5. Fairing to tolerance: the largest lambda <= fairing.weight whose refit keeps every distance
//     within the tolerance, searched by decades, then bisected on a log scale. The jump rows
//     (fairing.h) are capped at the median jump (a row whose unfaired jump |J_q| exceeds the
//     median M is scaled by M / |J_q|): the nose needs jumps a hundred times the others and would
//     otherwise bind the tolerance before the surfaces are faired. A faired curve must also be
//     no less fair than the unfaired one: no larger sum of squared curvature differences and no
//     more spurious extrema; else the unfaired curve stays (lambda 0).
// With the knots placed for the full tolerance (fairing_headroom 1) the fit has little room
// left and fairing changes little; a smaller headroom buys room with controls.
//
// Curvature is judged per piece: the curve is cut at the feature points and at the nose (the
// sample of largest |kappa| within two data intervals of the leading-edge point), so a profile
// without features has an upper and a lower surface. Each piece is sampled at 2^curvature_level
// points per data interval; extrema are interior samples where kappa turns (wall_curvature.h,
// AccumulateCurvature). An extremum is spurious when the data do not ask for it: the reference is
// the fairest curve within the same tolerance that the kernel builds, a smoothing spline with a
// knot at every second data point faired to tolerance as in step 5 (C. H. Reinsch, "Smoothing by
// spline functions", Numer. Math. 10, 1967; P. Dierckx, "Curve and Surface Fitting with
// Splines", 1993, ch. 5), whose significant extrema are counted with a persistence of 10%: an
// extremum counts once the curvature has moved away from it by more than 10% of the larger
// magnitude (so the dense spline's ripples between knots do not count, and a swing through zero
// always does). Per piece, spurious = max(0, extrema - reference significant extrema).
// Any fit whose curvature exceeds twice the reference's largest has a cusp or a tiny loop that
// the distances cannot see (parameter correction can bunch parameters until |C'| nearly
// vanishes): knot placement splits the span there, and removal and fairing reject it.
#ifndef SPLINEGRID_CORE_FIT_AIRFOIL_AIRFOIL_FIT_H_
#define SPLINEGRID_CORE_FIT_AIRFOIL_AIRFOIL_FIT_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/bspline/parametrization.h"
#include "core/bspline/tensor_spline.h"
#include "core/fit/adaptive/refinement.h"
#include "core/fit/fit_defaults.h"
#include "core/fit/report/wall_curvature.h"
#include "core/fit/solve/fairing.h"
#include "core/grid/structured_grid.h"
#include "core/util/cancellation.h"

namespace splinegrid {

struct AirfoilFitOptions {
  // Largest distance from a data point to the curve, in the data's length unit (chords for
  // normalised coordinates). Also the largest trailing-edge gap that counts as sharp.
  double tolerance = 1e-4;
  // Spline order (degree + 1), 3 .. kMaxOrder; curvature needs degree >= 2.
  int order = kDefaultOrder;
  // Most control points; 0: as many as data points.
  int max_control_points = 0;
  // Initial parameters (before correction).
  Parametrization parametrization = Parametrization::kCentripetal;
  // Most parameter-correction rounds per fit (step 2; rounds stop earlier once one gains less
  // than 1%); 0 keeps the initial parameters.
  int max_parameter_corrections = 30;
  // Whether knots are removed after the target is met (step 4).
  bool remove_knots = true;
  // kToTolerance (default), kWeight (a fixed lambda, not checked against the tolerance) or kOff.
  FairingOptions fairing = {.mode = FairingMode::kToTolerance};
  // With kToTolerance the knots are placed for fairing_headroom * tolerance, in (0, 1]: the
  // rest of the tolerance is left for the fairing to use.
  double fairing_headroom = 1.0;
  // Kinks other than the leading edge. features.detect = false: only the trailing edge.
  FeatureOptions features;
  // Curvature samples: 2^level per data interval, 0 .. 6.
  int curvature_level = 2;
  // Polled between fits; a fired check ends the fit with CANCELLED.
  CancelCheck cancel;

  // INVALID_ARGUMENT naming the field and its value when an option is out of range.
  absl::Status Validate() const;
};

// Curvature of a fitted profile, per piece (surfaces between the trailing edge, the nose and the
// feature points, in curve order) and over all of them (file comment).
struct ProfileCurvature {
  CurvatureMetrics total;                    // all pieces (total.lines = pieces)
  std::vector<int64_t> piece_extrema;        // interior curvature extrema of each piece
  std::vector<int64_t> significant_extrema;  // those with a swing > 10% (file comment)
  std::vector<int64_t> spurious_extrema;     // max(0, piece - reference significant extrema)
  int64_t spurious() const;                  // sum of spurious_extrema
};

struct AirfoilFit {
  TensorSpline curve;             // n x 1 x 1, spatial_dim 2
  std::vector<double> params;     // per data point: parameter of its closest curve point
  std::vector<double> distances;  // per data point: distance to the curve
  double max_deviation = 0.0;     // max of distances
  int worst_point = 0;            // data index of max_deviation
  int num_control_points = 0;
  bool sharp_trailing_edge = false;      // ends within the tolerance: closed, C0 corner
  int leading_edge = 0;                  // data index farthest from the trailing-edge midpoint
  std::vector<int> features;             // data indices kept as C0 knots (pinned), ascending
  double fairing_weight = 0.0;           // lambda of the final curve (0: not faired)
  ProfileCurvature curvature;            // of the final curve
  ProfileCurvature unfaired_curvature;   // of the least-squares curve with the same knots
  ProfileCurvature reference_curvature;  // of the reference; its spurious: its ripples
  int knots_inserted = 0;
  int knots_removed = 0;
  int fits = 0;              // least-squares solves, parameter corrections included
  bool met = false;          // max_deviation <= tolerance and no cusp
  std::string unmet_reason;  // names the worst point (or the cusp) and the stop when !met
};

// Fits the airfoil outline `points` (n x 1 x 1, spatial_dim 2, Selig order, n >= 5); see the
// file comment. Not meeting the tolerance (the control cap) is no error: met = false and the
// reason. Errors: INVALID_ARGUMENT naming the field and value for bad options, a non-curve or
// 3D block, fewer than 5 points, non-finite coordinates, repeated consecutive points, an outline
// that crosses itself, or max_control_points below what the feature points need; CANCELLED.
// Cost: O(points) per fit and 500-1,500 fits (19-54 ms for the shared files of 69-205 points;
// 0.4-0.9 s for 3,000-5,000 points and 1.4-3.3 s for 12,000-20,000, dense_profile_test).
absl::StatusOr<AirfoilFit> FitAirfoil(const StructuredBlock& points,
                                      const AirfoilFitOptions& options);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_AIRFOIL_AIRFOIL_FIT_H_
