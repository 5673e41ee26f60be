#include "core/bspline/knot_vector.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/util/check.h"
#include "core/util/status_macros.h"

namespace splinegrid {

absl::StatusOr<KnotVector> KnotVector::Create(int order, std::vector<double> knots) {
  if (order < 1 || order > kMaxOrder) {
    return absl::InvalidArgumentError(
        absl::StrCat("order = ", order, " is outside [1, ", kMaxOrder, "]"));
  }
  const int size = static_cast<int>(knots.size());
  if (size < 2 * order) {
    return absl::InvalidArgumentError(absl::StrCat("knots: ", size, " knots for order ", order,
                                                   "; at least ", 2 * order, " are needed"));
  }
  for (int i = 0; i < size; ++i) {
    if (!std::isfinite(knots[i])) {
      return absl::InvalidArgumentError(
          absl::StrCat("knots[", i, "] = ", knots[i], " is not finite"));
    }
    if (i > 0 && knots[i] < knots[i - 1]) {
      return absl::InvalidArgumentError(absl::StrCat(
          "knots[", i, "] = ", knots[i], " is less than knots[", i - 1, "] = ", knots[i - 1]));
    }
  }
  for (int i = 1; i < order; ++i) {
    if (knots[i] != knots[0] || knots[size - 1 - i] != knots[size - 1]) {
      return absl::InvalidArgumentError(absl::StrCat("knots are not clamped: the first and last ",
                                                     order, " knots must be equal"));
    }
  }
  if (!(knots[order - 1] < knots[size - order])) {
    return absl::InvalidArgumentError(
        absl::StrCat("knots: empty domain [", knots[order - 1], ", ", knots[size - order], "]"));
  }
  for (int i = order; i < size - order;) {
    int j = i;
    while (j < size - order && knots[j] == knots[i]) ++j;
    if (j - i > order - 1) {
      return absl::InvalidArgumentError(absl::StrCat("knots: interior knot ", knots[i],
                                                     " has multiplicity ", j - i, "; at most ",
                                                     order - 1, " is allowed"));
    }
    i = j;
  }
  return KnotVector(order, std::move(knots));
}

KnotVector KnotVector::Uniform(int order, int num_controls) {
  SG_CHECK(order >= 1 && order <= kMaxOrder && num_controls >= order);
  SG_CHECK(order > 1 || num_controls == 1);
  std::vector<double> knots(num_controls + order);
  const int spans = num_controls - order + 1;
  for (int i = 0; i < static_cast<int>(knots.size()); ++i) {
    const int j = std::clamp(i - (order - 1), 0, spans);
    knots[i] = j == spans ? 1.0 : static_cast<double>(j) / spans;
  }
  return KnotVector(order, std::move(knots));
}

absl::StatusOr<KnotVector> KnotVector::Averaged(int order, int num_controls,
                                                std::span<const double> params) {
  const int m = static_cast<int>(params.size());
  if (order < 1 || order > kMaxOrder) {
    return absl::InvalidArgumentError(
        absl::StrCat("order = ", order, " is outside [1, ", kMaxOrder, "]"));
  }
  if (order == 1 && num_controls > 1) {
    return absl::InvalidArgumentError("order 1 admits a single control point per direction");
  }
  if (num_controls < order || num_controls > m) {
    return absl::InvalidArgumentError(absl::StrCat(
        "control count = ", num_controls, " is outside [order = ", order, ", points = ", m, "]"));
  }
  if (params.front() != 0.0 || params.back() != 1.0) {
    return absl::InvalidArgumentError("parameters must start at 0 and end at 1");
  }
  for (int i = 1; i < m; ++i) {
    if (!(params[i] > params[i - 1])) {
      return absl::InvalidArgumentError(absl::StrCat("parameters are not strictly increasing at ",
                                                     i, ": ", params[i - 1], ", ", params[i]));
    }
  }
  const int n = num_controls, k = order;
  std::vector<double> knots(n + k, 0.0);
  std::fill(knots.end() - k, knots.end(), 1.0);
  if (n == m) {
    // P&T eq. 9.8 (with p = k - 1): t_{j+p} = (u_j + ... + u_{j+p-1}) / p, j = 1 .. n - k.
    for (int j = 1; j <= n - k; ++j) {
      double sum = 0.0;
      for (int i = j; i < j + k - 1; ++i) sum += params[i];
      knots[j + k - 1] = sum / (k - 1);
    }
  } else {
    // P&T eq. 9.68-9.69 with m + 1 -> m data points and n + 1 -> n control points.
    const double d = static_cast<double>(m) / (n - k + 1);
    for (int j = 1; j <= n - k; ++j) {
      const int i = static_cast<int>(j * d);
      const double a = j * d - i;
      knots[k - 1 + j] = (1.0 - a) * params[i - 1] + a * params[i];
    }
  }
  return Create(order, std::move(knots));
}

std::vector<int> KnotVector::UsableBreaks(int order, int num_controls, int m,
                                          std::span<const int> candidates) {
  std::vector<int> kept;
  int previous = 0;
  for (int r : candidates) {
    const int pieces = static_cast<int>(kept.size()) + 2;
    // m_p >= k on both sides of r, and k controls for each piece: pieces * k <= n + breaks.
    if (r - previous >= order - 1 && (m - 1) - r >= order - 1 &&
        pieces * order <= num_controls + pieces - 1) {
      kept.push_back(r);
      previous = r;
    }
  }
  return kept;
}

absl::StatusOr<KnotVector> KnotVector::AveragedWithBreaks(int order, int num_controls,
                                                          std::span<const double> params,
                                                          std::span<const int> breaks) {
  if (breaks.empty()) return Averaged(order, num_controls, params);
  const int m = static_cast<int>(params.size());
  const int k = order;
  if (order < 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("breaks: order = ", order, " has no continuity to break; order >= 2 does"));
  }
  if (UsableBreaks(order, num_controls, m, breaks).size() != breaks.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("breaks: ", breaks.size(), " breaks at data indices from ", breaks.front(),
                     " to ", breaks.back(), " do not leave ", k, " of the ", m, " data and ", k,
                     " of the ", num_controls, " controls to every piece (order ", k, ")"));
  }
  // Piece bounds (data indices) and the controls of each piece.
  std::vector<int> bounds = {0};
  bounds.insert(bounds.end(), breaks.begin(), breaks.end());
  bounds.push_back(m - 1);
  const int pieces = static_cast<int>(bounds.size()) - 1;
  const int spare = num_controls + pieces - 1 - pieces * k;  // controls beyond k per piece
  const int surplus = m + pieces - 1 - pieces * k;           // sum of m_p - k
  std::vector<int> controls(pieces, k);
  std::vector<std::pair<double, int>> remainders;
  int given = 0;
  for (int p = 0; p < pieces; ++p) {
    const int extra_data = bounds[p + 1] - bounds[p] + 1 - k;
    const double share = surplus > 0 ? static_cast<double>(spare) * extra_data / surplus : 0.0;
    controls[p] += static_cast<int>(share);
    given += static_cast<int>(share);
    remainders.push_back({share - static_cast<int>(share), p});
  }
  std::stable_sort(remainders.begin(), remainders.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  for (int q = 0; given < spare; ++q, ++given) ++controls[remainders[q].second];

  std::vector<double> knots(k, params.front());
  for (int p = 0; p < pieces; ++p) {
    const double u0 = params[bounds[p]], u1 = params[bounds[p + 1]];
    std::vector<double> local(params.begin() + bounds[p], params.begin() + bounds[p + 1] + 1);
    for (double& u : local) u = (u - u0) / (u1 - u0);
    local.front() = 0.0;
    local.back() = 1.0;
    SG_ASSIGN_OR_RETURN(const KnotVector piece, Averaged(k, controls[p], local), "breaks: piece ",
                        p, ": ");
    for (int j = k; j < controls[p]; ++j) knots.push_back(u0 + piece.knot(j) * (u1 - u0));
    knots.insert(knots.end(), p + 1 < pieces ? k - 1 : k, u1);
  }
  return Create(order, std::move(knots));
}

int KnotVector::FindSpan(double u) const {
  const int n = num_controls();
  if (u >= knots_[n]) {
    // The last non-empty span (for clamped knots t_n = end of domain).
    int span = n - 1;
    while (span > order_ - 1 && knots_[span] == knots_[span + 1]) --span;
    return span;
  }
  if (u <= knots_[order_ - 1]) {
    int span = order_ - 1;
    while (span < n - 1 && knots_[span] == knots_[span + 1]) ++span;
    return span;
  }
  // upper_bound gives the first knot > u; the span starts one before it.
  const auto it = std::upper_bound(knots_.begin() + order_, knots_.begin() + n + 1, u);
  return static_cast<int>(it - knots_.begin()) - 1;
}

int KnotVector::Multiplicity(double u) const {
  const auto [lo, hi] = std::equal_range(knots_.begin(), knots_.end(), u);
  return static_cast<int>(hi - lo);
}

std::vector<double> KnotVector::InteriorBreaks() const {
  std::vector<double> breaks;
  for (int i = order_; i < num_controls(); ++i) {
    if (breaks.empty() || knots_[i] != breaks.back()) breaks.push_back(knots_[i]);
  }
  return breaks;
}

}  // namespace splinegrid
