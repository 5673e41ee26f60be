#include "core/bspline/knot_insertion.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid {

absl::StatusOr<TensorSpline> InsertKnot(const TensorSpline& spline, int direction, double u,
                                        int times) {
  if (direction < 0 || direction > 2) {
    return absl::InvalidArgumentError(absl::StrCat("direction = ", direction, "; must be 0..2"));
  }
  const KnotVector& kv = spline.knots(direction);
  if (!std::isfinite(u) || !(u > kv.domain_begin() && u < kv.domain_end())) {
    return absl::InvalidArgumentError(absl::StrCat("knot u = ", u, " is not inside the domain (",
                                                   kv.domain_begin(), ", ", kv.domain_end(), ")"));
  }
  const int p = kv.degree();
  const int s = kv.Multiplicity(u);
  if (times < 1 || s + times > p) {
    return absl::InvalidArgumentError(absl::StrCat("inserting u = ", u, " ", times,
                                                   " time(s) next to multiplicity ", s,
                                                   " exceeds the maximum of order - 1 = ", p));
  }
  const int r = times;
  const int k = kv.FindSpan(u);
  const int n = kv.num_controls();
  const std::span<const double> U = kv.knots();

  std::vector<double> knots(U.begin(), U.begin() + k + 1);
  knots.insert(knots.end(), r, u);
  knots.insert(knots.end(), U.begin() + k + 1, U.end());
  SG_ASSIGN_OR_RETURN(KnotVector refined, KnotVector::Create(kv.order(), std::move(knots)));

  // View the control net as (a, n, b): a = coordinates and faster directions, b = slower.
  const Extents ext = spline.control_extents();
  int64_t a = spline.spatial_dim(), b = 1;
  for (int d = 0; d < direction; ++d) a *= ext[d];
  for (int d = direction + 1; d < 3; ++d) b *= ext[d];
  const int n_new = n + r;
  std::vector<double> out(a * n_new * b);
  std::vector<double> rw(a * (p + 1));
  const double* in = spline.control().data();
  for (int64_t e = 0; e < b; ++e) {
    const double* P = in + a * n * e;
    double* Q = out.data() + a * n_new * e;
    auto row_p = [&](int i) { return P + a * i; };
    auto row_q = [&](int i) { return Q + a * i; };
    auto row_r = [&](int i) { return rw.data() + a * i; };
    for (int i = 0; i <= k - p; ++i) std::copy_n(row_p(i), a, row_q(i));
    for (int i = k - s; i < n; ++i) std::copy_n(row_p(i), a, row_q(i + r));
    for (int i = 0; i <= p - s; ++i) std::copy_n(row_p(k - p + i), a, row_r(i));
    int L = k - p;
    for (int j = 1; j <= r; ++j) {
      L = k - p + j;
      for (int i = 0; i <= p - j - s; ++i) {
        const double alpha = (u - U[L + i]) / (U[i + k + 1] - U[L + i]);
        double* ri = row_r(i);
        const double* rn = row_r(i + 1);
        for (int64_t c = 0; c < a; ++c) ri[c] = alpha * rn[c] + (1.0 - alpha) * ri[c];
      }
      std::copy_n(row_r(0), a, row_q(L));
      std::copy_n(row_r(p - j - s), a, row_q(k + r - j - s));
    }
    for (int i = L + 1; i < k - s; ++i) std::copy_n(row_r(i - L), a, row_q(i));
  }
  std::array<KnotVector, 3> all = spline.all_knots();
  all[direction] = std::move(refined);
  return TensorSpline::Create(std::move(all), spline.spatial_dim(), std::move(out));
}

}  // namespace splinegrid
