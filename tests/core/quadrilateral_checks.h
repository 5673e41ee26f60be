// An independent check of planar grids, shared by the tests of fits and generated grids (core,
// server): signed cell areas, and the sub-cells of a refinement that fold against the original.
#ifndef SPLINEGRID_TESTS_CORE_QUADRILATERAL_CHECKS_H_
#define SPLINEGRID_TESTS_CORE_QUADRILATERAL_CHECKS_H_

#include <cstdint>

#include "core/grid/structured_grid.h"

namespace splinegrid {

// Twice the signed area of cell (i, j) of a planar block, the cross product of its diagonals
// (positive counter-clockwise in (i, j)).
inline double CellArea(const StructuredBlock& g, int i, int j) {
  const double* a = g.Point(i, j, 0);
  const double* b = g.Point(i + 1, j, 0);
  const double* c = g.Point(i + 1, j + 1, 0);
  const double* d = g.Point(i, j + 1, 0);
  return (c[0] - a[0]) * (d[1] - b[1]) - (c[1] - a[1]) * (d[0] - b[0]);
}

// Sub-cells of `fine` (refinement level `level` of `original`: 2^level sub-cells per original
// cell and direction) whose signed area is not of the (nonzero) sign of the original cell they
// lie in; degenerate original cells are skipped.
inline int64_t FoldedSubCells(const StructuredBlock& original, const StructuredBlock& fine,
                              int level) {
  int64_t folded = 0;
  for (int J = 0; J + 1 < fine.extent(1); ++J) {
    for (int I = 0; I + 1 < fine.extent(0); ++I) {
      const double parent = CellArea(original, I >> level, J >> level);
      if (parent == 0.0) continue;
      if (CellArea(fine, I, J) * parent <= 0.0) ++folded;
    }
  }
  return folded;
}

}  // namespace splinegrid

#endif  // SPLINEGRID_TESTS_CORE_QUADRILATERAL_CHECKS_H_
