// Sum-factorisation kernels: contracting one tensor direction with sampled basis values.
//
// A tensor T of shape (a, n, b), element (c, r, e) at T[c + a * (r + n * e)], contracted in
// its middle direction with a sampled basis B (q < samples, k nonzeros from first[q]):
//   U(c, q, e) = sum_t B(q, t) T(c, first[q] + t, e).
// Every output row U(., q, e) is a weighted sum of k contiguous input rows of length a, so
// the inner loop is a unit-stride multiply-add that the compiler vectorises.
#ifndef SPLINEGRID_CORE_BSPLINE_CONTRACTION_H_
#define SPLINEGRID_CORE_BSPLINE_CONTRACTION_H_

#include <cstdint>

#include "core/bspline/basis.h"

namespace splinegrid {

// out[c] = sum_{t < k} w[t] * rows[t][c] for c < length.
void WeightedRowSum(const double* const* rows, const double* w, int k, int64_t length, double* out);

// U = T contracted with derivative `derivative` of `basis` (see the file comment).
// T has shape (a, basis.num_controls, b); U has shape (a, basis.num_samples(), b).
void ContractDirection(const double* in, int64_t a, int64_t b, const SampledBasis& basis,
                       int derivative, double* out);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_BSPLINE_CONTRACTION_H_
