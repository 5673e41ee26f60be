// Poles: block boundaries collapsed to a point or a line (polar axes, the centre of a polar disk,
// wing-tip caps, the apices of C-O and O-O topologies).
//
// A block boundary line along direction d (the points x with x[d] = 0 .. m_d - 1 and every other
// active index fixed at 0 or its maximum on the block's faces) is collapsed when all its points
// lie within `tolerance` of its first point. A pole is a box of data indices on one face of a
// block, full along d, in which every line along d is collapsed:
//  - on a surface or planar block: a whole edge (the centre of a polar disk, the tip of a cap);
//  - on a volume: a whole face collapsed along d (to a line: a polar axis; along both tangential
//    directions: to a point), or else a single boundary line of a face (a collapsed block edge).
//
// A pole is not a boundary that another block (or the block itself) meets: every point of a
// collapsed line coincides with every other, so a point-by-point "match" along d carries no
// correspondence (FindConnectivity drops such matches), and the segment model must not cut the
// parameter range at their ends. A fit keeps a pole collapsed by giving every control point of
// a collapsed line one value (multiblock_fit.cc explains why that is the constrained
// least-squares solution, not just a projection).
#ifndef SPLINEGRID_CORE_GRID_POLES_H_
#define SPLINEGRID_CORE_GRID_POLES_H_

#include <cstdint>
#include <string>
#include <vector>

#include "core/grid/structured_grid.h"

namespace splinegrid {

// Relative size of a collapsed line: its points lie within kPoleRelativeTolerance times the
// diagonal of the grid's bounding box of each other. Far below any fitting tolerance (the
// paper's smallest is 1.5e-4 chord) and far above rounding of coordinates written with 15
// digits, so printed poles are found and tiny real cells are not.
inline constexpr double kPoleRelativeTolerance = 1e-10;

// A box of data indices [lo, hi] of block `block` (lo[d] = 0, hi[d] = m_d - 1) in which every
// grid line along direction `d` is collapsed to one point. In every other direction the box is
// either the full range of the block or one end (0 or m - 1).
struct Pole {
  int block = 0;
  int d = 0;
  Extents lo = {0, 0, 0};
  Extents hi = {0, 0, 0};
  int normal = 0;     // the normal direction of the face it lies on
  int line_end = -1;  // a boundary line of that face: its fixed third direction; else -1

  // e.g. "block 0 j=0 collapsed along i".
  std::string Describe() const;
};

// The diagonal of the bounding box of all points of `grid` times kPoleRelativeTolerance (0 for
// an empty grid or one whose points are all equal).
double PoleTolerance(const MultiBlockGrid& grid);

// Whether every point x of `block` with x[d] in [lo[d], hi[d]] (the other indices of x fixed
// at `at`) lies within `tolerance` of the first one. Cost O(hi[d] - lo[d]).
bool LineCollapsed(const StructuredBlock& block, const Extents& at, int d, int lo, int hi,
                   double tolerance);

// Whether every line along d in the box [lo, hi] of `block` is collapsed. Cost O(box points).
bool BoxCollapsedAlong(const StructuredBlock& block, const Extents& lo, const Extents& hi, int d,
                       double tolerance);

// Whether the box [lo, hi] of `block` is collapsed along some direction d with lo[d] < hi[d]:
// every line along d in the box a single point. Cost O(box points).
bool BoxCollapsed(const StructuredBlock& block, const Extents& lo, const Extents& hi,
                  double tolerance);

// The poles of every block of `grid` (see the file comment): per face and tangential direction
// d, the whole face when all its lines along d are collapsed, else (volumes) each of the face's
// two boundary lines along d that is. A line may be listed more than once (it bounds two faces).
// Cost O(boundary points).
std::vector<Pole> FindPoles(const MultiBlockGrid& grid, double tolerance);

// Per block of `grid`, 1 at the points of `poles` and 0 elsewhere (empty for a block without
// one). Cost O(points of the blocks with poles).
std::vector<std::vector<uint8_t>> PointsOnPoles(const MultiBlockGrid& grid,
                                                const std::vector<Pole>& poles);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GRID_POLES_H_
