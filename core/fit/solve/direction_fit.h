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
// Interior controls can be pinned too: at a feature point (a knot of multiplicity order - 1 at
// params[r]) only one basis function is nonzero, and pinning its control to x_r makes the fit
// pass through the feature point exactly, each side fitted on its own.
#ifndef SPLINEGRID_CORE_FIT_SOLVE_DIRECTION_FIT_H_
#define SPLINEGRID_CORE_FIT_SOLVE_DIRECTION_FIT_H_

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "absl/status/statusor.h"
#include "core/bspline/knot_vector.h"
#include "core/fit/solve/banded_qr.h"
#include "core/util/cancellation.h"

namespace splinegrid {

enum class EndCondition { kFree, kInterpolate, kZero };

// An interior control value fixed to a data value: p_control = x_{data_row} (0 with kZero).
struct Pin {
  int control = 0;
  int data_row = 0;
};

// An extra least-squares row over control values: sum_t values[t] p_{first + t} ~ 0.
struct PenaltyRow {
  int first = 0;
  std::vector<double> values;
};

// Whether the data at `params` determine every control that is not pinned (the
// Schoenberg-Whitney condition: the free controls can be matched, in order, to distinct data
// points inside their supports). Then the least-squares problem has full rank. Cost O(n + m).
bool SchoenbergWhitneyHolds(const KnotVector& knots, std::span<const double> params,
                            std::span<const int> pinned_controls);

class DirectionFit {
 public:
  // Factors the fit of data at `params` (strictly increasing in the knots' domain; params[0] and
  // params[m-1] at the domain ends when ends == kInterpolate) with `knots`, plus `penalties`
  // (already weighted). Errors: INVALID_ARGUMENT for fewer points than controls without
  // penalties, FAILED_PRECONDITION when the data leave a control point undetermined.
  static absl::StatusOr<DirectionFit> Create(const KnotVector& knots,
                                             std::span<const double> params, EndCondition ends,
                                             std::span<const Pin> interior_pins = {},
                                             std::span<const PenaltyRow> penalties = {});

  int num_points() const { return num_points_; }
  int num_controls() const { return num_controls_; }

  // Fits every line of the tensor `in` of shape (a, m, b) along its middle direction, writing
  // the control values to `out` of shape (a, n, b) (layout as in contraction.h). Lines are
  // processed in blocks of columns; `cancel` is polled between blocks.
  absl::Status Apply(const double* in, int64_t a, int64_t b, double* out,
                     const CancelCheck& cancel = {}) const;

 private:
  // One row of the factored system: where its right-hand side comes from, and the pinned
  // controls it touches (their terms move to the right-hand side).
  struct RowSource {
    int data_row;      // row of the data, or -1 for a penalty row (zero right side)
    int pinned_begin;  // its pinned terms: pinned_terms_[pinned_begin .. pinned_end)
    int pinned_end;
  };
  struct PinnedTerm {
    int pin;  // index into pins_
    double coef;
  };

  DirectionFit() = default;

  // Steps of Create.
  // Pins the ends (unless kFree) and `interior_pins` into pins_; returns the pin index of every
  // control (-1: free). INVALID_ARGUMENT for a pin out of range or repeated.
  absl::StatusOr<std::vector<int>> PinControls(EndCondition ends,
                                               std::span<const Pin> interior_pins);
  // Fills free_columns_ from `pin_of`; returns the free index of every control (-1: pinned).
  std::vector<int> SetFreeColumns(const std::vector<int>& pin_of);
  // Adds the row `values` over controls first.. (right side: data row `data_row`, or -1 for a
  // penalty) to qr_ as its free part, its pinned terms to pinned_terms_; a row that constrains
  // nothing free is dropped. `free_values` is scratch of the bandwidth's size.
  void AddSplitRow(int first, std::span<const double> values, int data_row,
                   const std::vector<int>& pin_of, const std::vector<int>& free_index,
                   std::vector<double>& free_values);

  void ApplyBlock(const double* in, int64_t a, int64_t q0, int64_t q1, double* out,
                  std::vector<double>& scratch) const;

  int num_points_ = 0;
  int num_controls_ = 0;
  bool zero_pins_ = false;         // kZero: pinned controls are 0
  std::vector<Pin> pins_;          // ends first (if any), then interior pins
  std::vector<int> free_columns_;  // free index -> control index
  BandedQR qr_{0, 1};              // over the free controls
  std::vector<RowSource> rows_;    // in the order they were added to qr_
  std::vector<PinnedTerm> pinned_terms_;
};

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_SOLVE_DIRECTION_FIT_H_
