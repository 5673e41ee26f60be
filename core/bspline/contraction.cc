#include "core/bspline/contraction.h"

#include "core/util/check.h"

namespace splinegrid {
namespace {

// Fixed-order kernel: the t loop unrolls and the c loop vectorises.
template <int K>
void WeightedRowSumFixed(const double* const* rows, const double* w, int64_t length,
                         double* __restrict out) {
  for (int64_t c = 0; c < length; ++c) {
    double sum = w[0] * rows[0][c];
    for (int t = 1; t < K; ++t) sum += w[t] * rows[t][c];
    out[c] = sum;
  }
}

}  // namespace

void WeightedRowSum(const double* const* rows, const double* w, int k, int64_t length,
                    double* out) {
  switch (k) {
    case 1:
      return WeightedRowSumFixed<1>(rows, w, length, out);
    case 2:
      return WeightedRowSumFixed<2>(rows, w, length, out);
    case 3:
      return WeightedRowSumFixed<3>(rows, w, length, out);
    case 4:
      return WeightedRowSumFixed<4>(rows, w, length, out);
    case 5:
      return WeightedRowSumFixed<5>(rows, w, length, out);
    case 6:
      return WeightedRowSumFixed<6>(rows, w, length, out);
    default:
      break;
  }
  for (int64_t c = 0; c < length; ++c) {
    double sum = 0.0;
    for (int t = 0; t < k; ++t) sum += w[t] * rows[t][c];
    out[c] = sum;
  }
}

namespace {

// Rows of A coordinates (the first direction of a control net): the whole point is one short
// row, so the sum is written out directly instead of calling the row kernel per point.
template <int A>
void ContractPoints(const double* in, int64_t b, const SampledBasis& basis, int derivative,
                    double* out) {
  const int k = basis.order;
  const int64_t n_in = basis.num_controls, n_out = basis.num_samples();
  for (int64_t e = 0; e < b; ++e) {
    const double* slab = in + A * n_in * e;
    double* out_slab = out + A * n_out * e;
    for (int64_t q = 0; q < n_out; ++q) {
      const double* w = basis.Row(q, derivative);
      const double* p = slab + A * basis.first[q];
      double sum[A] = {};
      for (int t = 0; t < k; ++t) {
        for (int c = 0; c < A; ++c) sum[c] += w[t] * p[A * t + c];
      }
      for (int c = 0; c < A; ++c) out_slab[A * q + c] = sum[c];
    }
  }
}

}  // namespace

void ContractDirection(const double* in, int64_t a, int64_t b, const SampledBasis& basis,
                       int derivative, double* out) {
  SG_CHECK(derivative >= 0 && derivative <= basis.max_derivative);
  if (a == 2) return ContractPoints<2>(in, b, basis, derivative, out);
  if (a == 3) return ContractPoints<3>(in, b, basis, derivative, out);
  const int k = basis.order;
  const int64_t n_in = basis.num_controls, n_out = basis.num_samples();
  const double* rows[kMaxOrder];
  for (int64_t e = 0; e < b; ++e) {
    const double* slab = in + a * n_in * e;
    double* out_slab = out + a * n_out * e;
    for (int64_t q = 0; q < n_out; ++q) {
      const double* first = slab + a * basis.first[q];
      for (int t = 0; t < k; ++t) rows[t] = first + a * t;
      WeightedRowSum(rows, basis.Row(q, derivative), k, a, out_slab + a * q);
    }
  }
}

}  // namespace splinegrid
