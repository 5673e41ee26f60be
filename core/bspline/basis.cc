#include "core/bspline/basis.h"

#include <algorithm>

#include "core/util/check.h"

namespace splinegrid {

void BasisFunctions(const KnotVector& knots, int span, double u, double* values) {
  const int k = knots.order();
  const std::span<const double> t = knots.knots();
  double left[kMaxOrder], right[kMaxOrder];
  values[0] = 1.0;
  for (int j = 1; j < k; ++j) {
    left[j] = u - t[span + 1 - j];
    right[j] = t[span + j] - u;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      // The weights right / (right + left) and left / (right + left) are divided out separately
      // so that a zero left (u at a knot of multiplicity k - 1, or a clamped end) gives a
      // weight of exactly 1: the one nonzero basis function there is exactly 1.
      const double den = right[r + 1] + left[j - r];
      const double v = values[r];
      values[r] = saved + (right[r + 1] / den) * v;
      saved = (left[j - r] / den) * v;
    }
    values[j] = saved;
  }
}

void BasisDerivatives(const KnotVector& knots, int span, double u, int max_derivative,
                      double* ders) {
  const int k = knots.order();
  const int p = k - 1;
  const std::span<const double> t = knots.knots();
  // ndu: basis functions (upper triangle incl. diagonal) and knot differences (lower).
  double ndu[kMaxOrder][kMaxOrder], a[2][kMaxOrder], left[kMaxOrder], right[kMaxOrder];
  ndu[0][0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = u - t[span + 1 - j];
    right[j] = t[span + j] - u;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      ndu[j][r] = right[r + 1] + left[j - r];
      const double v = ndu[r][j - 1];
      ndu[r][j] = saved + (right[r + 1] / ndu[j][r]) * v;
      saved = (left[j - r] / ndu[j][r]) * v;
    }
    ndu[j][j] = saved;
  }
  for (int j = 0; j <= p; ++j) ders[j] = ndu[j][p];
  const int n = std::min(max_derivative, p);
  for (int r = 0; r <= p; ++r) {
    int s1 = 0, s2 = 1;
    a[0][0] = 1.0;
    for (int d = 1; d <= n; ++d) {
      double der = 0.0;
      const int rk = r - d, pk = p - d;
      if (r >= d) {
        a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
        der = a[s2][0] * ndu[rk][pk];
      }
      const int j1 = rk >= -1 ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? d - 1 : p - r;
      for (int j = j1; j <= j2; ++j) {
        a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
        der += a[s2][j] * ndu[rk + j][pk];
      }
      if (r <= pk) {
        a[s2][d] = -a[s1][d - 1] / ndu[pk + 1][r];
        der += a[s2][d] * ndu[r][pk];
      }
      ders[d * k + r] = der;
      std::swap(s1, s2);
    }
  }
  // Multiply by p! / (p - d)!.
  double factor = p;
  for (int d = 1; d <= n; ++d) {
    for (int j = 0; j <= p; ++j) ders[d * k + j] *= factor;
    factor *= p - d;
  }
  for (int d = n + 1; d <= max_derivative; ++d) {
    for (int j = 0; j <= p; ++j) ders[d * k + j] = 0.0;
  }
}

SampledBasis SampleBasis(const KnotVector& knots, std::span<const double> params,
                         int max_derivative) {
  SG_CHECK(max_derivative >= 0);
  SampledBasis basis;
  basis.order = knots.order();
  basis.num_controls = knots.num_controls();
  basis.max_derivative = max_derivative;
  const int k = basis.order;
  const size_t stride = static_cast<size_t>(max_derivative + 1) * k;
  basis.first.resize(params.size());
  basis.values.resize(params.size() * stride);
  const double lo = knots.domain_begin(), hi = knots.domain_end();
  const std::span<const double> t = knots.knots();
  int span = -1;
  for (size_t q = 0; q < params.size(); ++q) {
    const double u = std::clamp(params[q], lo, hi);
    // Sorted parameters (the usual case) walk the spans forward; others search.
    if (span >= 0 && u >= t[span] && u < t[span + 1]) {
      // same span as the previous sample
    } else if (span >= 0 && span + 2 < basis.num_controls + 1 && u >= t[span + 1] &&
               u < t[span + 2]) {
      ++span;
    } else {
      span = knots.FindSpan(u);
    }
    basis.first[q] = span - k + 1;
    double* row = basis.values.data() + q * stride;
    if (max_derivative == 0) {
      BasisFunctions(knots, span, u, row);
    } else {
      BasisDerivatives(knots, span, u, max_derivative, row);
    }
  }
  return basis;
}

}  // namespace splinegrid
