#include "core/fit/solve/banded_qr.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/util/check.h"

namespace splinegrid {

BandedQR::BandedQR(int num_cols, int bandwidth, int expected_rows)
    : num_cols_(num_cols),
      bandwidth_(bandwidth),
      r_(static_cast<size_t>(num_cols) * bandwidth, 0.0),
      scratch_(bandwidth) {
  SG_CHECK(num_cols >= 0 && bandwidth >= 1 && expected_rows >= 0);
  cs_.reserve(2 * static_cast<size_t>(expected_rows) * bandwidth);
  row_first_.reserve(expected_rows);
  row_count_.reserve(expected_rows);
  row_begin_.reserve(expected_rows);
}

void BandedQR::AddRow(int first, std::span<const double> values) {
  const int w = bandwidth_;
  SG_CHECK(static_cast<int>(values.size()) <= w);
  SG_CHECK(first >= last_first_ && first + static_cast<int>(values.size()) <= num_cols_);
  last_first_ = first;
  row_first_.push_back(first);
  row_begin_.push_back(static_cast<int>(cs_.size() / 2));
  double* h = scratch_.data();
  std::fill(h, h + w, 0.0);
  std::copy(values.begin(), values.end(), h);
  // Rotate until the row is annihilated. Rotating against R row j can fill the row in up to
  // column j + w - 1 (R rows reach that far when an earlier row with the same first column was
  // wider), so the count of rotations is not the row's own length: trailing zeros are trimmed
  // after every rotation instead.
  auto last_nonzero = [&] {
    int last = w;
    while (last > 0 && h[last - 1] == 0.0) --last;
    return last;
  };
  int count = 0;
  for (int j = first; j < num_cols_ && last_nonzero() > 0; ++j, ++count) {
    // Invariant: h[t] is the entry of the row in column j + t.
    double c = 1.0, s = 0.0;
    double* rj = r_.data() + static_cast<size_t>(j) * w;
    if (h[0] != 0.0) {
      // hypot, not sqrt(a^2 + b^2): the squares of tiny entries (rounding residues can reach
      // 1e-160 and below) underflow to 0, which made norm = 0 and c = 0 / 0 = NaN.
      const double norm = std::hypot(rj[0], h[0]);
      c = rj[0] / norm;
      s = h[0] / norm;
      rj[0] = norm;
    }
    for (int t = 1; t < w; ++t) {
      const double rt = rj[t];
      rj[t] = c * rt + s * h[t];
      h[t - 1] = -s * rt + c * h[t];
    }
    h[w - 1] = 0.0;
    cs_.push_back(c);
    cs_.push_back(s);
  }
  row_count_.push_back(count);
}

int64_t BandedQR::MemoryBytes() const {
  return static_cast<int64_t>((r_.size() + cs_.size()) * sizeof(double) +
                              3 * row_first_.size() * sizeof(int));
}

absl::Status BandedQR::CheckRank(double relative_tolerance) const {
  double largest = 0.0;
  for (int j = 0; j < num_cols_; ++j) largest = std::max(largest, std::abs(Diagonal(j)));
  for (int j = 0; j < num_cols_; ++j) {
    if (!(std::abs(Diagonal(j)) > relative_tolerance * largest)) {
      return absl::FailedPreconditionError(absl::StrCat(
          "least-squares matrix is rank deficient at column ", j, " of ", num_cols_,
          ": no data constrains that control point (too many control points for the data)"));
    }
  }
  return absl::OkStatus();
}

namespace {

// Applies T consecutive rotations to acc rows acc[0], acc[width], ... in one sweep: the
// right-hand side value stays in a register while it passes through the T rows.
template <int T>
void RotateInto(const double* __restrict cs, const double* __restrict v, double* __restrict acc,
                int64_t width, int64_t stride) {
  for (int64_t x = 0; x < width; ++x) {
    double vx = v[x];
    for (int t = 0; t < T; ++t) {
      double* __restrict a = acc + t * stride;
      const double ax = a[x];
      a[x] = cs[2 * t] * ax + cs[2 * t + 1] * vx;
      vx = cs[2 * t] * vx - cs[2 * t + 1] * ax;
    }
  }
}

}  // namespace

void BandedQR::ReduceRow(int row, const double* v, double* acc, int64_t width,
                         int64_t acc_stride) const {
  const double* cs = cs_.data() + 2 * static_cast<size_t>(row_begin_[row]);
  double* a = acc + row_first_[row] * acc_stride;
  switch (row_count_[row]) {
    case 0:
      return;
    case 1:
      return RotateInto<1>(cs, v, a, width, acc_stride);
    case 2:
      return RotateInto<2>(cs, v, a, width, acc_stride);
    case 3:
      return RotateInto<3>(cs, v, a, width, acc_stride);
    case 4:
      return RotateInto<4>(cs, v, a, width, acc_stride);
    case 5:
      return RotateInto<5>(cs, v, a, width, acc_stride);
    case 6:
      return RotateInto<6>(cs, v, a, width, acc_stride);
    default:
      break;
  }
  // High orders: the same sweep with a run-time rotation count.
  const int count = row_count_[row];
  for (int64_t x = 0; x < width; ++x) {
    double vx = v[x];
    for (int t = 0; t < count; ++t) {
      double* ar = a + t * acc_stride;
      const double ax = ar[x];
      ar[x] = cs[2 * t] * ax + cs[2 * t + 1] * vx;
      vx = cs[2 * t] * vx - cs[2 * t + 1] * ax;
    }
  }
}

void BandedQR::BackSubstitute(double* acc, int64_t width, int64_t acc_stride) const {
  const int w = bandwidth_;
  for (int j = num_cols_ - 1; j >= 0; --j) {
    const double* rj = r_.data() + static_cast<size_t>(j) * w;
    double* __restrict xj = acc + j * acc_stride;
    for (int t = 1; t < w && j + t < num_cols_; ++t) {
      const double* __restrict xt = acc + (j + t) * acc_stride;
      const double coef = rj[t];
      for (int64_t x = 0; x < width; ++x) xj[x] -= coef * xt[x];
    }
    const double inv = 1.0 / rj[0];
    for (int64_t x = 0; x < width; ++x) xj[x] *= inv;
  }
}

}  // namespace splinegrid
