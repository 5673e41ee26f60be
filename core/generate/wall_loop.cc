#include "core/generate/wall_loop.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/bspline/differential_geometry.h"
#include "core/bspline/evaluation.h"

namespace splinegrid {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Samples of the curve per loop point, for arc length and density.
constexpr int kSamplesPerPoint = 64;

// Dense samples of the curve: parameter, arc length, |curvature|.
struct Samples {
  std::vector<double> u, s, kappa;
};

Samples SampleCurve(const Profile& profile, int count) {
  Samples out;
  std::vector<double> u;
  for (int q = 0; q <= count; ++q) u.push_back(static_cast<double>(q) / count);
  u.insert(u.end(), profile.corners.begin(), profile.corners.end());
  std::sort(u.begin(), u.end());
  u.erase(std::unique(u.begin(), u.end()), u.end());
  Point3 prev{};
  double s = 0.0;
  for (size_t q = 0; q < u.size(); ++q) {
    const Point3 p = EvaluatePoint(profile.curve, {u[q], 0.0, 0.0});
    if (q > 0) s += std::hypot(p[0] - prev[0], p[1] - prev[1]);
    prev = p;
    const bool corner = std::binary_search(profile.corners.begin(), profile.corners.end(), u[q]);
    out.u.push_back(u[q]);
    out.s.push_back(s);
    out.kappa.push_back(corner ? 0.0 : std::abs(CurveCurvature(profile.curve, 0, u[q])));
  }
  return out;
}

// The largest ratio of neighbouring spacings of `s` (ascending).
double MaxSpacingRatio(const std::vector<double>& s) {
  double worst = 1.0;
  for (size_t i = 2; i < s.size(); ++i) {
    const double a = s[i - 1] - s[i - 2], b = s[i] - s[i - 1];
    worst = std::max(worst, std::max(a / b, b / a));
  }
  return worst;
}

// n arc lengths from 0 to samples.s.back() equidistributing `rho` (one value per sample), with
// `fixed` arc lengths (interior corners) hit exactly: each stretch between fixed points gets
// points in proportion to its share of the density.
std::vector<double> Equidistribute(const std::vector<double>& s, const std::vector<double>& rho,
                                   int n, const std::vector<double>& fixed) {
  std::vector<double> cumulative(s.size(), 0.0);
  for (size_t q = 1; q < s.size(); ++q) {
    cumulative[q] = cumulative[q - 1] + 0.5 * (rho[q] + rho[q - 1]) * (s[q] - s[q - 1]);
  }
  auto arc_at = [&](double phi) {  // inverse of the cumulative density
    const size_t q = std::min<size_t>(
        std::upper_bound(cumulative.begin(), cumulative.end(), phi) - cumulative.begin(),
        cumulative.size() - 1);
    if (q == 0) return s.front();
    const double t = (phi - cumulative[q - 1]) / (cumulative[q] - cumulative[q - 1]);
    return s[q - 1] + std::clamp(t, 0.0, 1.0) * (s[q] - s[q - 1]);
  };
  auto phi_at = [&](double arc) {
    const size_t q =
        std::min<size_t>(std::upper_bound(s.begin(), s.end(), arc) - s.begin(), s.size() - 1);
    if (q == 0) return 0.0;
    const double t = (arc - s[q - 1]) / (s[q] - s[q - 1]);
    return cumulative[q - 1] + std::clamp(t, 0.0, 1.0) * (cumulative[q] - cumulative[q - 1]);
  };
  std::vector<double> bounds = {0.0};
  for (double f : fixed) bounds.push_back(phi_at(f));
  bounds.push_back(cumulative.back());
  // Points per stretch, in proportion to its density, at least one interval each.
  const int intervals = n - 1;
  std::vector<int> per(bounds.size() - 1, 1);
  int given = static_cast<int>(per.size());
  for (size_t p = 0; p < per.size() && given < intervals; ++p) {
    const int share =
        static_cast<int>(std::lround((bounds[p + 1] - bounds[p]) / cumulative.back() * intervals));
    per[p] = std::max(1, share);
  }
  int total = 0;
  for (int x : per) total += x;
  per.back() += intervals - total;  // rounding goes to the last stretch
  std::vector<double> out;
  for (size_t p = 0; p < per.size(); ++p) {
    for (int q = 0; q < per[p]; ++q) {
      out.push_back(arc_at(bounds[p] + (bounds[p + 1] - bounds[p]) * q / per[p]));
    }
  }
  out.push_back(s.back());
  return out;
}

}  // namespace

absl::Status WallOptions::Validate() const {
  if (num_points < 9) {
    return absl::InvalidArgumentError(absl::StrCat("num_points = ", num_points, " is below 9"));
  }
  const std::pair<const char*, double> nonnegative[] = {
      {"curvature_clustering", curvature_clustering}, {"corner_clustering", corner_clustering}};
  for (const auto& [name, value] : nonnegative) {
    if (!(value >= 0.0) || !std::isfinite(value)) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, " = ", value, " is not a finite number >= 0"));
    }
  }
  if (!(corner_width > 0.0 && corner_width <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("corner_width = ", corner_width, " is outside (0, 1]"));
  }
  if (!(max_spacing_ratio >= 1.0) || !std::isfinite(max_spacing_ratio)) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_spacing_ratio = ", max_spacing_ratio, " is not a finite number >= 1"));
  }
  if (base_points < 3 || base_points > num_points / 3) {
    return absl::InvalidArgumentError(
        absl::StrCat("base_points = ", base_points, " is outside [3, num_points / 3]"));
  }
  return absl::OkStatus();
}

absl::StatusOr<WallLoop> DistributeWall(const Profile& profile, const WallOptions& options) {
  if (absl::Status s = options.Validate(); !s.ok()) return s;
  const Extents n = profile.curve.control_extents();
  if (profile.curve.spatial_dim() != 2 || n[1] != 1 || n[2] != 1 || n[0] < 2) {
    return absl::InvalidArgumentError(
        "the profile must be a planar curve (n x 1 x 1 control points, 2 coordinates)");
  }
  for (size_t c = 0; c < profile.corners.size(); ++c) {
    const double u = profile.corners[c];
    if (!(u > 0.0 && u < 1.0) || (c > 0 && !(u > profile.corners[c - 1]))) {
      return absl::InvalidArgumentError(
          absl::StrCat("corners[", c, "] = ", u, " is not an ascending parameter in (0, 1)"));
    }
  }
  // The curve's share of the loop: all of it when closed; a blunt base takes base_points - 1
  // intervals of its own.
  const int curve_points =
      profile.closed ? options.num_points : options.num_points - options.base_points + 1;
  if (curve_points < 3 * static_cast<int>(profile.corners.size() + 1) + 1) {
    return absl::InvalidArgumentError(absl::StrCat("num_points = ", options.num_points,
                                                   " is too few for ", profile.corners.size(),
                                                   " corners"));
  }
  const Samples samples = SampleCurve(profile, kSamplesPerPoint * curve_points);
  const Point3 start = EvaluatePoint(profile.curve, {0.0, 0.0, 0.0});
  const Point3 end = EvaluatePoint(profile.curve, {1.0, 0.0, 0.0});
  const double base = profile.closed ? 0.0 : std::hypot(end[0] - start[0], end[1] - start[1]);
  const double length = samples.s.back() + base;
  // Corner arc lengths on the curve: its ends (trailing edge) and the interior corners.
  std::vector<double> corner_arcs = {0.0, samples.s.back()};
  std::vector<double> interior_arcs;
  for (double u : profile.corners) {
    const size_t q = std::lower_bound(samples.u.begin(), samples.u.end(), u) - samples.u.begin();
    corner_arcs.push_back(samples.s[q]);
    interior_arcs.push_back(samples.s[q]);
  }
  const double width = options.corner_width * length;
  std::vector<double> rho(samples.s.size());
  for (size_t q = 0; q < rho.size(); ++q) {
    double d = length;
    for (double c : corner_arcs) d = std::min(d, std::abs(samples.s[q] - c));
    rho[q] = 1.0 +
             options.curvature_clustering * std::sqrt(samples.kappa[q] * length / (2.0 * kPi)) +
             options.corner_clustering * std::exp(-d / width);
  }
  // Smooth the density until neighbouring spacings stay within the ratio.
  std::vector<double> arcs = Equidistribute(samples.s, rho, curve_points, interior_arcs);
  for (int pass = 0; pass < 400 && MaxSpacingRatio(arcs) > options.max_spacing_ratio; ++pass) {
    for (int sweep = 0; sweep < kSamplesPerPoint / 4; ++sweep) {
      std::vector<double> next = rho;
      for (size_t q = 1; q + 1 < rho.size(); ++q) {
        next[q] = 0.25 * rho[q - 1] + 0.5 * rho[q] + 0.25 * rho[q + 1];
      }
      rho = std::move(next);
    }
    arcs = Equidistribute(samples.s, rho, curve_points, interior_arcs);
  }
  WallLoop loop;
  for (double arc : arcs) {
    const size_t q = std::min<size_t>(
        std::lower_bound(samples.s.begin(), samples.s.end(), arc) - samples.s.begin(),
        samples.s.size() - 1);
    double u = samples.u[q];
    if (q > 0 && samples.s[q] > samples.s[q - 1]) {
      const double t = (arc - samples.s[q - 1]) / (samples.s[q] - samples.s[q - 1]);
      u = samples.u[q - 1] + std::clamp(t, 0.0, 1.0) * (samples.u[q] - samples.u[q - 1]);
    }
    const Point3 p = EvaluatePoint(profile.curve, {u, 0.0, 0.0});
    loop.points.push_back({p[0], p[1]});
  }
  loop.corners.push_back(0);
  for (double c : interior_arcs) {
    loop.corners.push_back(static_cast<int>(
        std::lower_bound(arcs.begin(), arcs.end(), c - 1e-12 * length) - arcs.begin()));
  }
  loop.corners.push_back(curve_points - 1);
  if (profile.closed) {
    loop.points.back() = loop.points.front();  // the trailing edge, bitwise once
  } else {
    for (int q = 1; q < options.base_points; ++q) {
      const double t = static_cast<double>(q) / (options.base_points - 1);
      loop.points.push_back({end[0] + t * (start[0] - end[0]), end[1] + t * (start[1] - end[1])});
    }
    loop.points.back() = loop.points.front();
    loop.corners.push_back(static_cast<int>(loop.points.size()) - 1);
  }
  return loop;
}

}  // namespace splinegrid
