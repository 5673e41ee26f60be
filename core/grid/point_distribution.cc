#include "core/grid/point_distribution.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/util/check.h"

namespace splinegrid {
namespace {

// Fritsch-Carlson slopes on a unit-spaced index grid: the harmonic mean of the neighbouring
// secants inside, the shape-preserving three-point formula at the ends (as in PCHIP).
std::vector<double> MonotoneSlopes(const std::vector<double>& u) {
  const int m = static_cast<int>(u.size());
  std::vector<double> slope(m, 0.0);
  if (m < 2) return slope;
  if (m == 2) {
    slope[0] = slope[1] = u[1] - u[0];
    return slope;
  }
  for (int i = 1; i + 1 < m; ++i) {
    const double a = u[i] - u[i - 1], b = u[i + 1] - u[i];
    slope[i] = 2.0 * a * b / (a + b);
  }
  auto end_slope = [](double d0, double d1) {
    double d = 0.5 * (3.0 * d0 - d1);
    if (d <= 0.0) return 0.0;
    return std::min(d, 3.0 * d0);
  };
  slope[0] = end_slope(u[1] - u[0], u[2] - u[1]);
  slope[m - 1] = end_slope(u[m - 1] - u[m - 2], u[m - 2] - u[m - 3]);
  return slope;
}

}  // namespace

PointDistribution::PointDistribution() {
  for (int d = 0; d < 3; ++d) {
    params_[d] = {0.0};
    slopes_[d] = {0.0};
  }
}

PointDistribution::PointDistribution(std::array<std::vector<double>, 3> params)
    : params_(std::move(params)) {
  for (int d = 0; d < 3; ++d) slopes_[d] = MonotoneSlopes(params_[d]);
}

absl::StatusOr<PointDistribution> PointDistribution::Create(
    std::array<std::vector<double>, 3> params) {
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
  return PointDistribution(std::move(params));
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
  const double value = h00 * u[i] + h10 * slopes_[d][i] + h01 * u[i + 1] + h11 * slopes_[d][i + 1];
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
