// QR factorisation of a banded least-squares matrix by Givens rotations.
//
// Minimises ||A x - b|| for A (rows x n) whose row r has at most w consecutive nonzeros,
// starting at column first_r, with first_r non-decreasing (a B-spline collocation matrix has
// w = order). Rows are rotated into an upper-triangular R of bandwidth w one at a time
// (Cox 1981; Dierckx, "Curve and Surface Fitting with Splines", 1993, ch. 4; Golub & Van Loan
// 5.1.8), so A^T A is never formed and the cost is O(rows w^2) to factor, O(rows w) per
// right-hand side to apply Q^T and O(n w) to back-substitute. The rotations are recorded,
// which is what makes "factor once, solve many" cheap: a direction of a tensor grid is
// factored once and replayed on every grid line and coordinate.
#ifndef SPLINEGRID_CORE_FIT_SOLVE_BANDED_QR_H_
#define SPLINEGRID_CORE_FIT_SOLVE_BANDED_QR_H_

#include <cstdint>
#include <span>
#include <vector>

#include "absl/status/status.h"

namespace splinegrid {

class BandedQR {
 public:
  // An empty factorisation of a matrix with `num_cols` columns and bandwidth `bandwidth`;
  // `expected_rows` only reserves memory.
  BandedQR(int num_cols, int bandwidth, int expected_rows = 0);

  // Rotates the row with nonzeros `values` at columns first .. first + values.size() - 1 into R
  // and records the rotations. Preconditions: values.size() <= bandwidth, the row fits in
  // [0, num_cols), first >= the first of the previous row.
  void AddRow(int first, std::span<const double> values);

  // OK when every diagonal entry of R exceeds relative_tolerance * max |R_jj|; otherwise
  // FAILED_PRECONDITION naming the first rank-deficient column (no data constrains it).
  absl::Status CheckRank(double relative_tolerance = 1e-12) const;

  int num_cols() const { return num_cols_; }
  int bandwidth() const { return bandwidth_; }
  int num_rows() const { return static_cast<int>(row_begin_.size()); }
  // |R_jj|: the diagonal, for condition estimates.
  double Diagonal(int j) const { return r_[static_cast<size_t>(j) * bandwidth_]; }
  // Bytes held by R and the recorded rotations.
  int64_t MemoryBytes() const;

  // Applies the rotations of row `row` to a block of `width` right-hand sides: `v` is that
  // row's right-hand side and `acc` (num_cols rows of `width` values, row j at
  // acc + j * acc_stride) accumulates Q^T b (the residual part of v is dropped). Rows must be
  // replayed in the order they were added, starting from acc = 0. All rotations of a row are
  // applied in one sweep over the block.
  void ReduceRow(int row, const double* v, double* acc, int64_t width, int64_t acc_stride) const;

  // Solves R x = acc in place (acc laid out as in ReduceRow).
  void BackSubstitute(double* acc, int64_t width, int64_t acc_stride) const;

 private:
  // Row r was rotated against R rows row_first_[r] + t, t < row_count_[r], with
  // (c, s) = (cs_[2 (row_begin_[r] + t)], cs_[2 (row_begin_[r] + t) + 1]) (identity where the
  // entry was already zero, so that the columns stay consecutive).
  int num_cols_;
  int bandwidth_;
  int last_first_ = 0;
  std::vector<double> r_;  // R(j, t) = r_[j * bandwidth + t], column j + t
  std::vector<double> cs_;
  std::vector<int> row_first_, row_count_, row_begin_;
  std::vector<double> scratch_;
};

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_SOLVE_BANDED_QR_H_
