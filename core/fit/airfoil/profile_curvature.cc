// The curvature judgement of a fitted profile (profile_curvature.h).
#include "core/fit/airfoil/profile_curvature.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace splinegrid {
namespace {

// A piece of the profile ending at a feature knot is sampled this far (in u) inside, so its
// last sample has the piece's own one-sided derivatives.
constexpr double kOneSidedOffset = 1e-12;
// The nose (the leading-edge split) is looked for within this many data intervals of the
// leading-edge data point.
constexpr int kNoseWindow = 2;
// Relative swing of the curvature that makes an extremum significant (SignificantExtrema).
constexpr double kSignificantSwing = 0.1;

}  // namespace

std::vector<double> PieceSamples(std::span<const double> params, int level, bool one_sided_end) {
  const int per = 1 << level;
  std::vector<double> u;
  u.reserve((params.size() - 1) * per + 1);
  for (size_t r = 0; r + 1 < params.size(); ++r) {
    for (int j = 0; j < per; ++j) u.push_back(params[r] + (params[r + 1] - params[r]) * j / per);
  }
  u.push_back(params.back() - (one_sided_end ? kOneSidedOffset : 0.0));
  return u;
}

std::vector<CurvatureSample> SampleCurvature(const Curve& curve, std::span<const double> u) {
  std::vector<double> jet;
  EvaluateJet(curve, u, 2, jet);
  std::vector<CurvatureSample> samples(u.size());
  for (size_t q = 0; q < u.size(); ++q) {
    const double* x = jet.data() + 6 * q;
    CurvatureSample& s = samples[q];
    s.point = {x[0], x[1], 0.0};
    s.curvature = JetCurvature(x);
    if (q > 0) {
      const Point3& p = samples[q - 1].point;
      s.arc_length = samples[q - 1].arc_length + std::hypot(x[0] - p[0], x[1] - p[1]);
    }
  }
  return samples;
}

std::pair<double, double> CurvaturePeak(const Fitted& fitted, const std::vector<int>& anchors,
                                        int level) {
  std::pair<double, double> peak = {0.0, 0.0};
  for (size_t a = 0; a + 1 < anchors.size(); ++a) {
    const std::span<const double> params(fitted.params);
    const std::vector<double> u = PieceSamples(
        params.subspan(anchors[a], anchors[a + 1] - anchors[a] + 1), level, a + 2 < anchors.size());
    const std::vector<CurvatureSample> samples = SampleCurvature(fitted.curve, u);
    for (size_t q = 0; q < u.size(); ++q) {
      if (std::abs(samples[q].curvature) > peak.first)
        peak = {std::abs(samples[q].curvature), u[q]};
    }
  }
  return peak;
}

int64_t SignificantExtrema(std::span<const CurvatureSample> samples) {
  auto swing = [](double from, double to) {
    return std::abs(to - from) > kSignificantSwing * std::max(std::abs(from), std::abs(to));
  };
  int64_t count = 0;
  int direction = 0;  // +1 rising, -1 falling, 0 not yet known
  double low = samples[0].curvature, high = low, extremum = low;
  for (const CurvatureSample& s : samples) {
    const double v = s.curvature;
    if (direction == 0) {
      low = std::min(low, v), high = std::max(high, v);
      if (v > low && swing(low, v)) direction = 1, extremum = v;
      if (v < high && swing(high, v)) direction = -1, extremum = v;
    } else if (direction * (v - extremum) > 0.0) {
      extremum = v;
    } else if (swing(extremum, v)) {
      ++count;
      direction = -direction;
      extremum = v;
    }
  }
  return count;
}

ProfileCurvature MeasureCurvature(const Fitted& fitted, const std::vector<int>& anchors,
                                  int leading_edge, int level) {
  ProfileCurvature out;
  auto add = [&](std::span<const CurvatureSample> piece) {
    CurvatureMetrics metrics;
    AccumulateCurvature(piece, metrics);
    out.piece_extrema.push_back(metrics.extrema);
    out.significant_extrema.push_back(SignificantExtrema(piece));
    AccumulateCurvature(piece, out.total);
  };
  const std::span<const double> params(fitted.params);
  for (size_t a = 0; a + 1 < anchors.size(); ++a) {
    const int r0 = anchors[a], r1 = anchors[a + 1];
    const std::vector<CurvatureSample> samples = SampleCurvature(
        fitted.curve, PieceSamples(params.subspan(r0, r1 - r0 + 1), level, a + 2 < anchors.size()));
    if (leading_edge <= r0 || leading_edge >= r1) {
      add(samples);
      continue;
    }
    const size_t per = size_t{1} << level;
    const size_t lo = (std::max(leading_edge - kNoseWindow, r0) - r0) * per;
    const size_t hi = (std::min(leading_edge + kNoseWindow, r1) - r0) * per;
    size_t nose = lo;
    for (size_t q = lo; q <= hi; ++q) {
      if (std::abs(samples[q].curvature) > std::abs(samples[nose].curvature)) nose = q;
    }
    const std::span<const CurvatureSample> all(samples);
    add(all.first(nose + 1));
    add(all.subspan(nose));
  }
  return out;
}

void CountSpurious(const ProfileCurvature& reference, ProfileCurvature& c) {
  c.spurious_extrema.assign(c.piece_extrema.size(), 0);
  for (size_t p = 0; p < c.piece_extrema.size(); ++p) {
    const bool known = p < reference.significant_extrema.size();
    c.spurious_extrema[p] =
        std::max<int64_t>(0, c.piece_extrema[p] - (known ? reference.significant_extrema[p] : 0));
  }
}

}  // namespace splinegrid
