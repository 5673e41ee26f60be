// An independent check of volume grids, shared by the tests of the generated volumes (server,
// end to end): the scaled Jacobian at the lower corner of every hexahedron.
#ifndef SPLINEGRID_TESTS_CORE_HEXAHEDRON_CHECKS_H_
#define SPLINEGRID_TESTS_CORE_HEXAHEDRON_CHECKS_H_

#include <cmath>

#include "core/grid/structured_grid.h"

namespace splinegrid {

// The smallest det[x_i, x_j, x_k] / (|x_i| |x_j| |x_k|) at the lower corner of every hexahedron
// (x_i, x_j, x_k its three edges from that corner); -inf where it is not a number (a collapsed
// edge, a NaN point), so that > 0 means every corner right-handed.
inline double MinCornerJacobian(const StructuredBlock& b) {
  double worst = HUGE_VAL;
  for (int k = 0; k + 1 < b.extent(2); ++k) {
    for (int j = 0; j + 1 < b.extent(1); ++j) {
      for (int i = 0; i + 1 < b.extent(0); ++i) {
        const double* o = b.Point(i, j, k);
        const double* pi = b.Point(i + 1, j, k);
        const double* pj = b.Point(i, j + 1, k);
        const double* pk = b.Point(i, j, k + 1);
        double e[3][3];
        for (int c = 0; c < 3; ++c) {
          e[0][c] = pi[c] - o[c];
          e[1][c] = pj[c] - o[c];
          e[2][c] = pk[c] - o[c];
        }
        const double det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                           e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                           e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
        double lengths = 1.0;
        for (const auto& v : e) lengths *= std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        const double scaled = det / lengths;
        if (std::isnan(scaled)) return -HUGE_VAL;
        if (scaled < worst) worst = scaled;
      }
    }
  }
  return worst;
}

}  // namespace splinegrid

#endif  // SPLINEGRID_TESTS_CORE_HEXAHEDRON_CHECKS_H_
