#include "core/fit/report/wall_curvature.h"

#include <algorithm>
#include <cmath>

#include "core/bspline/basis.h"
#include "core/util/check.h"

namespace splinegrid {
namespace {

// The control points of the iso-parametric curve of `spline` along direction d through the
// parameters uvw of the other directions: sum over their nonzero basis functions of N(v) M(w) P.
// n_d points of spatial_dim coordinates.
std::vector<double> IsoCurveControls(const TensorSpline& spline, int d, const Point3& uvw) {
  const Extents n = spline.control_extents();
  const int s = spline.spatial_dim();
  // Per direction: the first control and the weights of the nonzero basis functions.
  std::array<int, 3> first{};
  std::array<std::vector<double>, 3> weight;
  for (int e = 0; e < 3; ++e) {
    if (e == d) continue;
    const KnotVector& knots = spline.knots(e);
    const int k = knots.order();
    const int span = knots.FindSpan(uvw[e]);
    weight[e].resize(k);
    BasisFunctions(knots, span, uvw[e], weight[e].data());
    first[e] = span - k + 1;
  }
  const int e1 = d == 0 ? 1 : 0;
  const int e2 = d == 2 ? 1 : 2;
  std::vector<double> out(static_cast<size_t>(s) * n[d], 0.0);
  for (int a = 0; a < n[d]; ++a) {
    for (size_t q1 = 0; q1 < weight[e1].size(); ++q1) {
      for (size_t q2 = 0; q2 < weight[e2].size(); ++q2) {
        Extents c{};
        c[d] = a;
        c[e1] = first[e1] + static_cast<int>(q1);
        c[e2] = first[e2] + static_cast<int>(q2);
        const double w = weight[e1][q1] * weight[e2][q2];
        const double* p = spline.ControlPoint(c[0], c[1], c[2]);
        for (int x = 0; x < s; ++x) out[s * a + x] += w * p[x];
      }
    }
  }
  return out;
}

}  // namespace

std::vector<WallLine> FindWallLines(const std::vector<FittedBlock>& blocks,
                                    const BoundaryKinds& kinds) {
  std::vector<WallLine> lines;
  const auto wall = static_cast<uint8_t>(BoundaryKind::kWall);
  for (size_t b = 0; b < blocks.size(); ++b) {
    const PointDistribution& dist = blocks[b].distribution;
    const Extents m = {dist.num_points(0), dist.num_points(1), dist.num_points(2)};
    const std::vector<uint8_t>& kind = kinds.point_kinds[b];
    for (int d = 0; d < 3; ++d) {
      if (m[d] < 3) continue;
      const std::vector<int>& breaks = dist.breaks(d);
      const int e1 = d == 0 ? 1 : 0;
      const int e2 = d == 2 ? 1 : 2;
      for (int y = 0; y < m[e2]; ++y) {
        for (int x = 0; x < m[e1]; ++x) {
          Extents at{};
          at[e1] = x;
          at[e2] = y;
          auto is_wall = [&](int t) {
            Extents p = at;
            p[d] = t;
            return (kind[p[0] + int64_t{m[0]} * (p[1] + int64_t{m[1]} * p[2])] & wall) != 0;
          };
          auto emit = [&](int begin, int end) {  // points begin..end inclusive
            if (end - begin + 1 < 3) return;
            WallLine line{static_cast<int>(b), d, at, end - begin + 1};
            line.start[d] = begin;
            lines.push_back(line);
          };
          int begin = -1;
          for (int t = 0; t < m[d]; ++t) {
            if (!is_wall(t)) {
              if (begin >= 0) emit(begin, t - 1);
              begin = -1;
              continue;
            }
            if (begin < 0) begin = t;
            if (std::binary_search(breaks.begin(), breaks.end(), t) && t > begin) {
              emit(begin, t);
              begin = t;
            }
          }
          if (begin >= 0) emit(begin, m[d] - 1);
        }
      }
    }
  }
  return lines;
}

std::vector<CurvatureSample> SampleWallCurvature(const FittedBlock& fitted, const WallLine& line,
                                                 int level) {
  const int d = line.direction;
  const PointDistribution& dist = fitted.distribution;
  Point3 uvw{};
  for (int e = 0; e < 3; ++e) uvw[e] = dist.params(e)[line.start[e]];
  const std::vector<double> params =
      dist.Refined(d, line.start[d], line.start[d] + line.length - 1, level);
  const std::vector<double> control = IsoCurveControls(fitted.spline, d, uvw);
  const KnotVector& knots = fitted.spline.knots(d);
  const SampledBasis basis = SampleBasis(knots, params, 2);
  const int s = fitted.spline.spatial_dim();
  const int k = knots.order();
  std::vector<CurvatureSample> out(params.size());
  for (int q = 0; q < basis.num_samples(); ++q) {
    Point3 x{}, d1{}, d2{};
    for (int t = 0; t < k; ++t) {
      const double* p = control.data() + static_cast<size_t>(s) * (basis.first[q] + t);
      for (int c = 0; c < s; ++c) {
        x[c] += basis.Row(q, 0)[t] * p[c];
        d1[c] += basis.Row(q, 1)[t] * p[c];
        d2[c] += basis.Row(q, 2)[t] * p[c];
      }
    }
    const Point3 cross = {d1[1] * d2[2] - d1[2] * d2[1], d1[2] * d2[0] - d1[0] * d2[2],
                          d1[0] * d2[1] - d1[1] * d2[0]};
    const double speed = std::sqrt(d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2]);
    const double numerator =
        s == 2 ? cross[2]
               : std::sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
    CurvatureSample& sample = out[q];
    sample.point = x;
    sample.curvature = speed > 0.0 ? numerator / (speed * speed * speed) : 0.0;
    if (q > 0) {
      const Point3& prev = out[q - 1].point;
      sample.arc_length =
          out[q - 1].arc_length + std::hypot(x[0] - prev[0], x[1] - prev[1], x[2] - prev[2]);
    }
  }
  return out;
}

void AccumulateCurvature(std::span<const CurvatureSample> samples, CurvatureMetrics& metrics) {
  ++metrics.lines;
  metrics.samples += static_cast<int64_t>(samples.size());
  double largest = 0.0;
  for (const CurvatureSample& s : samples) largest = std::max(largest, std::abs(s.curvature));
  metrics.max_abs_curvature = std::max(metrics.max_abs_curvature, largest);
  const double flat = 1e-9 * largest;
  int direction = 0;  // +1 rising, -1 falling, 0 not yet known
  for (size_t q = 1; q < samples.size(); ++q) {
    const double change = samples[q].curvature - samples[q - 1].curvature;
    metrics.sum_squared_differences += change * change;
    if (std::abs(change) <= flat) continue;
    const int now = change > 0.0 ? 1 : -1;
    if (direction != 0 && now != direction) ++metrics.extrema;
    direction = now;
  }
}

CurvatureMetrics WallCurvatureMetrics(const std::vector<FittedBlock>& blocks,
                                      const BoundaryKinds& kinds, int level) {
  CurvatureMetrics metrics;
  for (const WallLine& line : FindWallLines(blocks, kinds)) {
    AccumulateCurvature(SampleWallCurvature(blocks[line.block], line, level), metrics);
  }
  return metrics;
}

}  // namespace splinegrid
