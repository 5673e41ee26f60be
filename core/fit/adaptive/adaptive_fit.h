// Least-squares fit of one block to a tolerance with adaptively placed knots.
//
// Starts from a single polynomial piece per direction and inserts knots where the fit is not
// good enough, until every point is within its own tolerance (or a control-point cap stops it),
// then removes knots that turn out unnecessary (adaptive_engine.h).
//
// Which direction needs knots: the tensor fit's error splits by direction,
//   I - P_w P_v P_u = (I - P_u) + P_u (I - P_v) + P_u P_v (I - P_w),
// where P_d fits the grid lines of direction d with that direction's knots. So the residual of
// fitting only direction d's lines, e_d = |(I - P_d) X|, tells where direction d lacks knots.
// Every knot span of d whose data have e_d / tolerance above d's share of the budget (1 / active
// directions at first) is split at the middle of its data; when no direction is over its share
// but the combined fit still is, the shares shrink. The worst grid line thus drives the knots of
// each direction (a span is refined if any line through it needs it).
//
// Feature points (kinks such as a C-grid's trailing edge on its wake cut, see refinement.h) get
// a knot of multiplicity order - 1 and a pinned control, so the fit passes through them exactly
// and each side is smooth on its own.
#ifndef SPLINEGRID_CORE_FIT_ADAPTIVE_ADAPTIVE_FIT_H_
#define SPLINEGRID_CORE_FIT_ADAPTIVE_ADAPTIVE_FIT_H_

#include <array>
#include <span>
#include <string>

#include "absl/status/statusor.h"
#include "core/fit/adaptive/refinement.h"
#include "core/fit/fit_defaults.h"
#include "core/fit/solve/tensor_fit.h"

namespace splinegrid {

struct ToleranceFitOptions {
  // Spline order (degree + 1) of every direction with enough points.
  int order = kDefaultOrder;
  Parametrization parametrization = kDefaultParametrization;
  // Most control points per direction; 0 means the direction's point count (interpolation).
  int max_controls_per_direction = 0;
  // Knot insertion rounds before giving up (each round splits every span that needs it).
  int max_iterations = kDefaultMaxRefinementRounds;
  // After the tolerance is met, try to drop knots one by one and keep each removal that still
  // meets it (cost: one tensor fit per knot).
  bool remove_unneeded_knots = true;
  // Kink detection (refinement.h); features.detect = false treats every line as smooth.
  FeatureOptions features;
  CancelCheck cancel;
};

struct ToleranceFitResult {
  FittedBlock fitted;
  bool met = false;          // every point within its tolerance
  std::string unmet_reason;  // why not, when !met
  double worst_ratio = 0.0;  // max over points of deviation / tolerance
  Extents worst_at = {0, 0, 0};
  int iterations = 0;
  int knots_inserted = 0;
  int knots_removed = 0;
  std::array<std::vector<int>, 3> features;  // grid indices of the feature points per direction
};

// Fits `block` so that every point p is within tolerance[p] (one positive value per point in
// point order, or a single value for all). Not meeting the tolerance is not an error: the
// result says so (met = false, with the reason and the worst point). Errors: INVALID_ARGUMENT
// for bad options, tolerances <= 0 or NaN, non-finite points; CANCELLED.
absl::StatusOr<ToleranceFitResult> FitToTolerance(const StructuredBlock& block,
                                                  std::span<const double> tolerance,
                                                  const ToleranceFitOptions& options);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_ADAPTIVE_ADAPTIVE_FIT_H_
