// Test surfaces shared by the kernel's and the service's crease tests: two 33 x 33 unit squares
// meeting along the y axis at an opening angle between them, as two blocks or as one.
#ifndef SPLINEGRID_TESTS_CORE_WEDGE_SURFACE_H_
#define SPLINEGRID_TESTS_CORE_WEDGE_SURFACE_H_

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/grid/structured_grid.h"

namespace splinegrid {

// The wedge of opening `degrees` (in x-z, y along the edge): z = 0 for x in [0, 1], and the face
// rotated by the angle about the y axis, its i running towards the edge. Its X_i x X_j normals
// point into the wedge.
inline MultiBlockGrid Wedge(double degrees) {
  const double a = degrees * std::numbers::pi / 180.0;
  MultiBlockGrid grid;
  for (int b = 0; b < 2; ++b) {
    StructuredBlock block({33, 33, 1}, 3);
    for (int j = 0; j < 33; ++j) {
      for (int i = 0; i < 33; ++i) {
        const double u = i / 32.0, v = j / 32.0;
        double* x = block.Point(i, j, 0);
        x[0] = b == 0 ? u : (1.0 - u) * std::cos(a);
        x[1] = v;
        x[2] = b == 0 ? 0.0 : (1.0 - u) * std::sin(a);
      }
    }
    grid.blocks.push_back(std::move(block));
  }
  return grid;
}

// The same two faces as one 65 x 33 block, kinked along its grid line i = 32 (the edge): i = 0
// .. 32 are Wedge's block 1, i = 32 .. 64 its block 0, so X_i x X_j points into the wedge too.
inline MultiBlockGrid FoldedWedge(double degrees) {
  const MultiBlockGrid faces = Wedge(degrees);
  StructuredBlock block({65, 33, 1}, 3);
  for (int j = 0; j < 33; ++j) {
    for (int i = 0; i < 65; ++i) {
      const double* x =
          i <= 32 ? faces.blocks[1].Point(i, j, 0) : faces.blocks[0].Point(i - 32, j, 0);
      std::copy(x, x + 3, block.Point(i, j, 0));
    }
  }
  MultiBlockGrid grid;
  grid.blocks.push_back(std::move(block));
  return grid;
}

}  // namespace splinegrid

#endif  // SPLINEGRID_TESTS_CORE_WEDGE_SURFACE_H_
