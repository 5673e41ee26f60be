#include "core/fit/report/fit_deviation.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/bspline/evaluation.h"
#include "core/grid/boundary_kinds.h"

namespace splinegrid {

absl::StatusOr<KindDeviation> DeviationByKind(const FittedBlock& fitted,
                                              const StructuredBlock& block,
                                              const std::vector<uint8_t>& kinds,
                                              std::span<const uint8_t> on_pole, double collapsed) {
  std::array<std::vector<double>, 3> params;
  for (int d = 0; d < 3; ++d) params[d] = fitted.distribution.params(d);
  const StructuredBlock eval = EvaluateGrid(fitted.spline, params);
  KindDeviation dev;
  const int s = block.spatial_dim();
  for (int64_t p = 0; p < block.num_points(); ++p) {
    double d2 = 0.0;
    for (int c = 0; c < s; ++c) {
      const double diff = eval.coords()[s * p + c] - block.coords()[s * p + c];
      d2 += diff * diff;
    }
    const double d = std::sqrt(d2);
    const uint8_t k = kinds[p];
    if (k == 0) dev.interior = std::max(dev.interior, d);
    if (k & static_cast<uint8_t>(BoundaryKind::kWall)) dev.wall = std::max(dev.wall, d);
    if (k & static_cast<uint8_t>(BoundaryKind::kInterface))
      dev.interface = std::max(dev.interface, d);
    if (k & static_cast<uint8_t>(BoundaryKind::kOuter)) dev.outer = std::max(dev.outer, d);
  }
  // First-layer heights. A collapsed edge has no height to keep (relative to it any error
  // would be unbounded), and an edge from a pole is not held by the fit.
  const double collapsed2 = collapsed * collapsed;
  ForEachHeldFirstLayerEdge(block, kinds, on_pole, [&](int64_t p, int64_t q) {
    double data = 0.0, fit = 0.0;
    for (int c = 0; c < s; ++c) {
      const double a = block.coords()[s * q + c] - block.coords()[s * p + c];
      const double b = eval.coords()[s * q + c] - eval.coords()[s * p + c];
      data += a * a;
      fit += b * b;
    }
    if (!(data > collapsed2)) return;  // also exactly 0 when `collapsed` is
    const double height = std::sqrt(data);
    const double change = std::abs(std::sqrt(fit) - height) / height;
    if (change > dev.first_layer) {
      dev.first_layer = change;
      const int64_t ni = block.extent(0), nj = block.extent(1);
      dev.first_layer_at = {static_cast<int>(p % ni), static_cast<int>((p / ni) % nj),
                            static_cast<int>(p / (ni * nj))};
    }
  });
  return dev;
}

double MaxBoundaryGap(const Connectivity& connectivity, const std::vector<FittedBlock>& blocks,
                      int max_level) {
  double gap = 0.0;
  for (const BoundaryMatch& m : connectivity.matches) {
    const FittedBlock& fa = blocks[m.a.face.block];
    const FittedBlock& fb = blocks[m.b.face.block];
    for (int level = 0; level <= (m.step == 1 ? max_level : 0); ++level) {
      std::array<std::vector<double>, 3> pa, pb;
      for (int d = 0; d < 3; ++d) {
        pa[d] = fa.distribution.Refined(d, m.a.begin[d], m.a.end[d], level);
      }
      for (int e = 0; e < 3; ++e) {
        pb[e] = fb.distribution.Refined(e, m.b.begin[e], m.b.end[e], m.step == 1 ? level : 0);
        if (m.step == 2) {
          std::vector<double> even;
          for (size_t q = 0; q < pb[e].size(); q += (pb[e].size() > 1 ? 2 : 1))
            even.push_back(pb[e][q]);
          if (m.b.end[e] > m.b.begin[e]) pb[e] = even;
        }
      }
      const StructuredBlock ea = EvaluateGrid(fa.spline, pa);
      const StructuredBlock eb = EvaluateGrid(fb.spline, pb);
      const int s = ea.spatial_dim();
      for (int k = 0; k < ea.extent(2); ++k) {
        for (int j = 0; j < ea.extent(1); ++j) {
          for (int i = 0; i < ea.extent(0); ++i) {
            // The index in b's evaluated range of a's evaluated point (i, j, k).
            const Extents x = {i, j, k};
            Extents y = {0, 0, 0};
            for (int d = 0; d < 3; ++d) {
              const int e = m.b_direction[d];
              if (e < 0) continue;
              y[e] = m.reversed[d] ? eb.extent(e) - 1 - x[d] : x[d];
            }
            double d2 = 0.0;
            for (int c = 0; c < s; ++c) {
              const double diff = ea.Point(i, j, k)[c] - eb.Point(y[0], y[1], y[2])[c];
              d2 += diff * diff;
            }
            gap = std::max(gap, std::sqrt(d2));
          }
        }
      }
    }
  }
  return gap;
}

}  // namespace splinegrid
