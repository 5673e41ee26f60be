// The least-squares operator of one direction of a tensor-product fit.
//
// For data parameters u_0 .. u_{m-1} and a knot vector with n control points, the collocation
// matrix A (m x n), A_rj = N_j(u_r), has `order` nonzeros per row. DirectionFit factors it once
// (BandedQR) and then fits every grid line of that direction: for each line x (m values of one
// coordinate) it computes the control values p minimising ||A p - x||, optionally with extra
// penalty rows ||lambda D p||. End conditions fix the first and last control value:
//   kInterpolate: p_0 = x_0 and p_{n-1} = x_{m-1} (the clamped spline interpolates the data
//                 end points; only the interior controls are fitted);
//   kZero:        p_0 = p_{n-1} = 0 (used to fit a correction with the boundary held).
#ifndef SPLINEGRID_CORE_FIT_DIRECTION_FIT_H_
#define SPLINEGRID_CORE_FIT_DIRECTION_FIT_H_

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "absl/status/statusor.h"
#include "core/bspline/knot_vector.h"
#include "core/fit/banded_qr.h"
#include "core/util/cancellation.h"

namespace splinegrid {

enum class EndCondition { kFree, kInterpolate, kZero };

// An extra least-squares row over control values: sum_t values[t] p_{first + t} ~ 0.
struct PenaltyRow {
  int first = 0;
  std::vector<double> values;
};

class DirectionFit {
 public:
  // Factors the fit of data at `params` (strictly increasing in the knots' domain; params[0] and
  // params[m-1] at the domain ends when ends == kInterpolate) with `knots`, plus `penalties`
  // (already weighted). Errors: INVALID_ARGUMENT for fewer points than controls without
  // penalties, FAILED_PRECONDITION when the data leave a control point undetermined.
  static absl::StatusOr<DirectionFit> Create(const KnotVector& knots,
                                             std::span<const double> params, EndCondition ends,
                                             std::span<const PenaltyRow> penalties = {});

  int num_points() const { return num_points_; }
  int num_controls() const { return num_controls_; }

  // Fits every line of the tensor `in` of shape (a, m, b) along its middle direction, writing
  // the control values to `out` of shape (a, n, b) (layout as in contraction.h). Lines are
  // processed in blocks of columns; `cancel` is polled between blocks.
  absl::Status Apply(const double* in, int64_t a, int64_t b, double* out,
                     const CancelCheck& cancel = {}) const;

 private:
  // One row of the factored system: where its right-hand side comes from and the coefficients
  // of the fixed end controls, which move to the right-hand side.
  struct RowSource {
    int data_row;             // row of the data, or -1 for a penalty row (zero right side)
    double first_coef = 0.0;  // coefficient of p_0 (fixed ends only)
    double last_coef = 0.0;   // coefficient of p_{n-1}
  };

  DirectionFit(int m, int n, EndCondition ends, BandedQR qr, std::vector<RowSource> rows)
      : num_points_(m), num_controls_(n), ends_(ends), qr_(std::move(qr)), rows_(std::move(rows)) {}

  void ApplyBlock(const double* in, int64_t a, int64_t q0, int64_t q1, double* out,
                  std::vector<double>& scratch) const;

  int num_points_;
  int num_controls_;
  EndCondition ends_;
  BandedQR qr_;                  // over the free controls
  std::vector<RowSource> rows_;  // in the order they were added to qr_
};

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_DIRECTION_FIT_H_
