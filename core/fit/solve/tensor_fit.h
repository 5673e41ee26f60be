// Least-squares fit of structured grid blocks with tensor-product B-splines.
//
// For data X (m_u x m_v x m_w points) with parameters u, v, w per direction and collocation
// matrices A (m_u x n_u), B (m_v x n_v), C (m_w x n_w), the least-squares problem
//   min || (C (x) B (x) A) P - X ||
// separates: its solution is P = (C^+ (x) B^+ (x) A^+) X, one direction at a time. Each 1D
// operator is a banded QR factored once (DirectionFit) and applied to every grid line and
// coordinate; the Kronecker matrix and the normal equations are never formed. Cost
// O(k^2 m_u m_v m_w), linear in the points; memory O(points n_w / m_w) beyond the input.
//
// With interpolated ends (the default) every 1D operator fixes its first and last control to
// the line's end points. Then corners are reproduced exactly and every face and edge of the
// fitted block is the fit of that face's or edge's own data: two blocks that share boundary
// data, knots and parameters share the boundary curve, which is what watertight multi-block
// fits build on.
#ifndef SPLINEGRID_CORE_FIT_SOLVE_TENSOR_FIT_H_
#define SPLINEGRID_CORE_FIT_SOLVE_TENSOR_FIT_H_

#include <array>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/bspline/knot_vector.h"
#include "core/bspline/parametrization.h"
#include "core/bspline/tensor_spline.h"
#include "core/fit/fit_defaults.h"
#include "core/fit/solve/direction_fit.h"
#include "core/grid/point_distribution.h"
#include "core/grid/structured_grid.h"
#include "core/util/cancellation.h"

namespace splinegrid {

struct FitOptions {
  // Spline order k (degree k - 1), in [2, kMaxOrder]. The only exception, forced by the data: a
  // direction with m < k points interpolates them at order m (its SplineDirection says so);
  // asking for fewer than k controls where there are at least k points is an error.
  int order = kDefaultOrder;
  // Control points per direction (i, j, k); 0 means as many as data points (interpolation).
  // Directions with one data point always get one control point. Nothing is clamped: a count
  // above the points or below the order is refused (ValidateControlCounts).
  Extents control_counts = {0, 0, 0};
  Parametrization parametrization = kDefaultParametrization;
  KnotPlacement knot_placement = KnotPlacement::kAveraged;
  // Per direction, data indices (ascending) where every line of the direction is only C0: kinks
  // of the block's boundary lines (DetectFeatures). Knots of multiplicity order - 1 there
  // (KnotVector::AveragedWithBreaks), with the direction's control count unchanged; a break
  // that would leave fewer than `order` points or controls to a piece is not used
  // (KnotVector::UsableBreaks). Needs kAveraged placement.
  std::array<std::vector<int>, 3> breaks;
  // Fix the end controls of every direction to the data (corners exact, boundaries from the
  // boundary data alone); see the file comment.
  bool interpolate_ends = true;
  // Fairing weight lambda >= 0 (fairing.h); 0: plain least squares.
  double fairing = 0.0;
  // Polled between work units; a fired check ends the fit with CANCELLED.
  CancelCheck cancel;

  // OK if the options suit a block of `points`; INVALID_ARGUMENT naming the field otherwise.
  absl::Status Validate(const Extents& points) const;
};

// OK if `counts` (control points per direction, 0: as many as points) suit a block of `points`
// fitted at `order`: each nonzero count in [min(order, m), m] for a direction of m > 1 points,
// 0 or 1 for a direction of one point. Otherwise INVALID_ARGUMENT naming `field` and the
// direction ("control_counts[0] = 1000"), `block` (e.g. "block 3"), its points and the limit.
absl::Status ValidateControlCounts(const Extents& counts, int order, const Extents& points,
                                   const std::string& field, const std::string& block);

// How far a spline is from the data it was fitted to, at the data parameters.
struct Deviation {
  double max = 0.0;            // largest Euclidean distance, in the data's length unit
  double rms = 0.0;            // root mean square of the distances
  Extents max_at = {0, 0, 0};  // grid index (i, j, k) of the largest distance
  int64_t num_points = 0;
  // With per-point tolerances: the largest distance / tolerance and where it is (else 0).
  double max_ratio = 0.0;
  Extents max_ratio_at = {0, 0, 0};
};

struct FitSummary {
  Deviation deviation;
  int64_t num_points = 0;
  int64_t num_control_points = 0;
  double compression_ratio = 0.0;  // num_points / num_control_points
  double seconds = 0.0;            // wall time of the whole fit
};

// A fitted block: the mapping, its point distribution and how well it fits.
struct FittedBlock {
  TensorSpline spline;
  PointDistribution distribution;
  FitSummary summary;
};

// Fits `block` according to `options`: parametrisation, knot placement, tensor least squares
// and the deviation at the data. Errors: INVALID_ARGUMENT for bad options or non-finite
// points, FAILED_PRECONDITION if the data leave control points undetermined, CANCELLED.
absl::StatusOr<FittedBlock> FitBlock(const StructuredBlock& block, const FitOptions& options);

// Interior pins per direction (see DirectionFit): feature points the fit passes through.
using DirectionPins = std::array<std::vector<Pin>, 3>;

// The tensor least-squares solve with given parameters and knot vectors (one of each per
// direction; a direction with one point has params {0} and the default KnotVector). With
// `fairing` = lambda > 0 every direction's fit also penalises the jumps of the highest
// derivative at its simple knots (fairing.h).
absl::StatusOr<TensorSpline> FitTensor(const StructuredBlock& block,
                                       const std::array<std::vector<double>, 3>& params,
                                       const std::array<KnotVector, 3>& knots, EndCondition ends,
                                       const CancelCheck& cancel = {},
                                       const DirectionPins& pins = {}, double fairing = 0.0);

// Distances between `spline` evaluated at `params` and the points of `block` (same extents);
// with `tolerance` (one positive value per point, point order) also the largest ratio of
// distance to tolerance. Cost O(k points); memory O(a batch of grid lines).
absl::StatusOr<Deviation> MeasureDeviation(const TensorSpline& spline,
                                           const std::array<std::vector<double>, 3>& params,
                                           const StructuredBlock& block,
                                           const CancelCheck& cancel = {},
                                           std::span<const double> tolerance = {});

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_SOLVE_TENSOR_FIT_H_
