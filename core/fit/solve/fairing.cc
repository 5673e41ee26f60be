#include "core/fit/solve/fairing.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/bspline/basis.h"

namespace splinegrid {
namespace {

// h_q^(k-1) (N^(k-1)(t_q+) - N^(k-1)(t_q-)) for the k + 1 controls q - k .. q of the simple knot
// at index q.
std::vector<double> JumpCoefficients(const KnotVector& knots, int q) {
  const int k = knots.order();
  const double t = knots.knot(q);
  std::vector<double> left(k * k), right(k * k);
  BasisDerivatives(knots, q - 1, t, k - 1, left.data());  // N_{q-k} .. N_{q-1}
  BasisDerivatives(knots, q, t, k - 1, right.data());     // N_{q-k+1} .. N_q
  const double h = 0.5 * (knots.knot(q + 1) - knots.knot(q - 1));
  const double scale = std::pow(h, k - 1);
  std::vector<double> jump(k + 1, 0.0);
  for (int s = 0; s < k; ++s) {
    jump[s] -= left[(k - 1) * k + s];
    jump[s + 1] += right[(k - 1) * k + s];
  }
  for (double& v : jump) v *= scale;
  return jump;
}

// Indices q of the simple interior knots.
std::vector<int> SimpleInteriorKnots(const KnotVector& knots) {
  std::vector<int> out;
  const int k = knots.order();
  const int n = knots.num_controls();
  for (int q = k; q < n; ++q) {
    const double t = knots.knot(q);
    if (knots.knot(q - 1) < t && t < knots.knot(q + 1)) out.push_back(q);
  }
  return out;
}

}  // namespace

absl::Status FairingOptions::Validate() const {
  if (mode == FairingMode::kOff) return absl::OkStatus();
  if (!(weight > 0.0) || !std::isfinite(weight)) {
    return absl::InvalidArgumentError(
        absl::StrCat("fairing weight = ", weight, " is not a positive finite number"));
  }
  return absl::OkStatus();
}

std::vector<PenaltyRow> JumpPenaltyRows(const KnotVector& knots, std::span<const double> params,
                                        double lambda) {
  std::vector<PenaltyRow> rows;
  if (!(lambda > 0.0) || knots.order() < 2) return rows;
  const int k = knots.order();
  for (int q : SimpleInteriorKnots(knots)) {
    // m_q: the mean number of data points in the two spans beside the knot (at least 1).
    const auto lo = std::lower_bound(params.begin(), params.end(), knots.knot(q - 1));
    const auto hi = std::upper_bound(params.begin(), params.end(), knots.knot(q + 1));
    const double m_q = std::max(1.0, 0.5 * static_cast<double>(hi - lo));
    PenaltyRow row{q - k, JumpCoefficients(knots, q)};
    const double weight = std::sqrt(lambda * m_q);
    for (double& v : row.values) v *= weight;
    rows.push_back(std::move(row));
  }
  return rows;
}

std::vector<double> ScaledDerivativeJumps(const KnotVector& knots,
                                          const std::vector<double>& controls) {
  std::vector<double> jumps;
  if (knots.order() < 2) return jumps;
  const int k = knots.order();
  for (int q : SimpleInteriorKnots(knots)) {
    const std::vector<double> c = JumpCoefficients(knots, q);
    double j = 0.0;
    for (int s = 0; s <= k; ++s) j += c[s] * controls[q - k + s];
    jumps.push_back(j);
  }
  return jumps;
}

}  // namespace splinegrid
