// Smooth, stretched, curvilinear test blocks for the benchmarks: a clustered and sheared
// mapping of the unit cube, like a boundary-layer block.
#ifndef SPLINEGRID_BENCH_GRID_SAMPLES_H_
#define SPLINEGRID_BENCH_GRID_SAMPLES_H_

#include <cmath>

#include "core/grid/structured_grid.h"

namespace splinegrid::bench {

inline StructuredBlock CurvilinearBlock(const Extents& n) {
  StructuredBlock block(n, 3);
  auto stretch = [](double s) { return std::expm1(3.0 * s) / std::expm1(3.0); };
  for (int k = 0; k < n[2]; ++k) {
    const double w = n[2] > 1 ? stretch(double(k) / (n[2] - 1)) : 0.0;
    for (int j = 0; j < n[1]; ++j) {
      const double v = n[1] > 1 ? stretch(double(j) / (n[1] - 1)) : 0.0;
      for (int i = 0; i < n[0]; ++i) {
        const double u = double(i) / (n[0] - 1);
        double* p = block.Point(i, j, k);
        const double r = 1.0 + 2.0 * v;
        p[0] = r * std::cos(2.5 * u) + 0.1 * w;
        p[1] = r * std::sin(2.5 * u) + 0.05 * std::sin(3.0 * w);
        p[2] = 4.0 * w + 0.2 * u * v;
      }
    }
  }
  return block;
}

}  // namespace splinegrid::bench

#endif  // SPLINEGRID_BENCH_GRID_SAMPLES_H_
