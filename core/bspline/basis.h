// B-spline basis functions and their derivatives by the Cox-de Boor recursion.
//
// On knot span mu (t_mu <= u < t_{mu+1}) exactly k B-splines of order k are nonzero:
// N_{mu-k+1}, ..., N_mu. The functions here return those k values, lowest index first.
#ifndef SPLINEGRID_CORE_BSPLINE_BASIS_H_
#define SPLINEGRID_CORE_BSPLINE_BASIS_H_

#include <span>
#include <vector>

#include "core/bspline/knot_vector.h"

namespace splinegrid {

// values[t] = N_{span-k+1+t}(u), t < k: the triangular Cox-de Boor scheme, P&T A2.2.
// Cost O(k^2). Precondition: span == knots.FindSpan(u) (or u on the span's closure).
void BasisFunctions(const KnotVector& knots, int span, double u, double* values);

// ders[d * k + t] = d^d/du^d N_{span-k+1+t}(u) for d = 0 .. max_derivative: P&T A2.3.
// Derivatives above the degree are zero. Cost O(k^2 + max_derivative k^2).
void BasisDerivatives(const KnotVector& knots, int span, double u, int max_derivative,
                      double* ders);

// The nonzero basis functions (and derivatives) of one direction sampled at a list of
// parameters: the sparse collocation matrix B(q, j) = N_j^(d)(u_q), with k nonzeros per row
// starting at column first[q]. Shared by fitting (collocation) and evaluation.
struct SampledBasis {
  int order = 1;
  int num_controls = 1;
  int max_derivative = 0;
  std::vector<int> first;      // index of the first nonzero function at each sample
  std::vector<double> values;  // [(q * (max_derivative + 1) + d) * order + t]

  int num_samples() const { return static_cast<int>(first.size()); }
  // The k values of derivative d at sample q.
  const double* Row(int q, int d = 0) const {
    return values.data() + (static_cast<size_t>(q) * (max_derivative + 1) + d) * order;
  }
};

// Samples the basis of `knots` at `params` (clamped into the domain) with derivatives up to
// `max_derivative`. Cost O(samples k^2).
SampledBasis SampleBasis(const KnotVector& knots, std::span<const double> params,
                         int max_derivative = 0);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_BSPLINE_BASIS_H_
