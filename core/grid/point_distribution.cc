#include "core/grid/point_distribution.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/util/check.h"

namespace splinegrid {
namespace {

// Slopes of the index -> parameter map (unit-spaced index grid). Inside a piece, PCHIP's
// harmonic mean of the neighbouring secants x, y (Fritsch & Butland), 2xy / (x + y): it never
// exceeds 2 min(x, y), so the Hermite interpolant is monotone (Fritsch & Carlson's condition is
// slopes <= 3 secants), and on geometrically stretched spacing, h_{i+1} = r h_i as grid
// generators make it, refined sub-cells stay within 3% (r = 2) and 10% (r = 4) of the exact
// geometric continuation u_i + h_i (r^t - 1) / (r - 1).
//
// At the ends of a piece the sequence is continued geometrically, h_{-1} = h_0^2 / h_1, and the
// same mean taken: slope = 2 h_0^2 / (h_0 + h_1). PCHIP's three-point end formula,
// (3 h_0 - h_1) / 2, drops to 0 for h_1 >= 3 h_0 and so collapses the first sub-cell of a
// stretched wall layer (a level-2 sub-cell 0.3x its geometric size at r = 3); this one keeps it
// within the interior's error.
double HarmonicMean(double x, double y) { return 2.0 * x * y / (x + y); }

// Slopes of u on the index range [a, b]: slope[a..b]. Pieces between breaks are treated as
// separate curves: a break gets the one-sided end slope of each piece, stored for the piece on
// its right (the left piece's end slope is slope[b] of that piece).
void PieceSlopes(const std::vector<double>& u, int a, int b, std::vector<double>& slope) {
  if (b - a == 1) {
    slope[a] = slope[b] = u[b] - u[a];
    return;
  }
  for (int i = a + 1; i < b; ++i) slope[i] = HarmonicMean(u[i] - u[i - 1], u[i + 1] - u[i]);
  const double h0 = u[a + 1] - u[a], h1 = u[a + 2] - u[a + 1];
  slope[a] = HarmonicMean(h0 * h0 / h1, h0);
  const double g0 = u[b] - u[b - 1], g1 = u[b - 1] - u[b - 2];
  slope[b] = HarmonicMean(g0 * g0 / g1, g0);
}

}  // namespace

PointDistribution::PointDistribution() {
  for (int d = 0; d < 3; ++d) {
    params_[d] = {0.0};
    slopes_[d] = {0.0};
    left_slopes_[d] = {0.0};
  }
}

PointDistribution::PointDistribution(std::array<std::vector<double>, 3> params,
                                     std::array<std::vector<int>, 3> breaks)
    : params_(std::move(params)), breaks_(std::move(breaks)) {
  for (int d = 0; d < 3; ++d) {
    const std::vector<double>& u = params_[d];
    const int m = static_cast<int>(u.size());
    slopes_[d].assign(m, 0.0);
    if (m < 2) {
      left_slopes_[d] = slopes_[d];
      continue;
    }
    std::vector<int> bounds = {0};
    bounds.insert(bounds.end(), breaks_[d].begin(), breaks_[d].end());
    bounds.push_back(m - 1);
    // Each piece's slopes; at a break the right piece's start slope is kept in slopes_ and the
    // left piece's end slope in left_slopes_.
    left_slopes_[d].assign(m, 0.0);
    for (size_t p = 0; p + 1 < bounds.size(); ++p) {
      std::vector<double> piece(m, 0.0);
      PieceSlopes(u, bounds[p], bounds[p + 1], piece);
      for (int i = bounds[p]; i < bounds[p + 1]; ++i) slopes_[d][i] = piece[i];
      left_slopes_[d][bounds[p + 1]] = piece[bounds[p + 1]];
    }
    // Inside a piece both slopes are the same; the last point only has the left one.
    for (int i = 1; i + 1 < m; ++i) {
      if (!std::binary_search(breaks_[d].begin(), breaks_[d].end(), i)) {
        left_slopes_[d][i] = slopes_[d][i];
      }
    }
    slopes_[d][m - 1] = left_slopes_[d][m - 1];
  }
}

absl::StatusOr<PointDistribution> PointDistribution::Create(
    std::array<std::vector<double>, 3> params, std::array<std::vector<int>, 3> breaks) {
  for (int d = 0; d < 3; ++d) {
    const std::vector<double>& u = params[d];
    const std::string name = absl::StrCat("distribution direction ", d);
    if (u.empty()) return absl::InvalidArgumentError(absl::StrCat(name, ": no parameters"));
    if (u.size() == 1) {
      if (!(u[0] >= 0.0 && u[0] <= 1.0)) {
        return absl::InvalidArgumentError(
            absl::StrCat(name, ": parameter ", u[0], " is outside [0, 1]"));
      }
      continue;
    }
    if (u.front() != 0.0 || u.back() != 1.0) {
      return absl::InvalidArgumentError(absl::StrCat(name, ": parameters run from ", u.front(),
                                                     " to ", u.back(), "; must be 0 to 1"));
    }
    for (size_t i = 1; i < u.size(); ++i) {
      if (!(u[i] > u[i - 1])) {
        return absl::InvalidArgumentError(absl::StrCat(name, ": parameter ", i, " = ", u[i],
                                                       " does not exceed parameter ", i - 1, " = ",
                                                       u[i - 1]));
      }
    }
  }
  for (int d = 0; d < 3; ++d) {
    for (size_t i = 0; i < breaks[d].size(); ++i) {
      const int r = breaks[d][i];
      if (r <= 0 || r >= static_cast<int>(params[d].size()) - 1 ||
          (i > 0 && r <= breaks[d][i - 1])) {
        return absl::InvalidArgumentError(absl::StrCat("distribution direction ", d, ": break ", r,
                                                       " is not an increasing interior index"));
      }
    }
  }
  return PointDistribution(std::move(params), std::move(breaks));
}

double PointDistribution::ParameterAt(int d, double s) const {
  const std::vector<double>& u = params_[d];
  const int m = static_cast<int>(u.size());
  if (m == 1) return u[0];
  s = std::clamp(s, 0.0, static_cast<double>(m - 1));
  const int i = std::min(static_cast<int>(s), m - 2);
  const double t = s - i;
  if (t == 0.0) return u[i];
  if (t == 1.0) return u[i + 1];
  // Cubic Hermite basis on [i, i + 1].
  const double t2 = t * t, t3 = t2 * t;
  const double h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + t;
  const double h01 = -2 * t3 + 3 * t2, h11 = t3 - t2;
  const double value =
      h00 * u[i] + h10 * slopes_[d][i] + h01 * u[i + 1] + h11 * left_slopes_[d][i + 1];
  return std::clamp(value, u[i], u[i + 1]);
}

std::vector<double> PointDistribution::Refined(int d, int begin, int end, int level) const {
  SG_CHECK(begin >= 0 && begin <= end && end < num_points(d) && level >= 0 && level <= 20);
  const int64_t per_interval = int64_t{1} << level;
  std::vector<double> out;
  out.reserve((end - begin) * per_interval + 1);
  for (int i = begin; i < end; ++i) {
    for (int64_t q = 0; q < per_interval; ++q) {
      out.push_back(ParameterAt(d, i + static_cast<double>(q) / per_interval));
    }
  }
  out.push_back(params_[d][end]);
  return out;
}

std::vector<double> PointDistribution::Resampled(int d, double begin, double end, int count) const {
  SG_CHECK(count >= 1);
  std::vector<double> out(count);
  for (int q = 0; q < count; ++q) {
    const double s = count == 1 ? begin : begin + (end - begin) * q / (count - 1);
    out[q] = ParameterAt(d, s);
  }
  return out;
}

}  // namespace splinegrid
