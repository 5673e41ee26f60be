// Small geometry of closed planar point loops (the first point repeated as the last), shared by
// the grid generators.
#ifndef SPLINEGRID_CORE_GENERATE_LOOP_GEOMETRY_H_
#define SPLINEGRID_CORE_GENERATE_LOOP_GEOMETRY_H_

#include <array>
#include <vector>

#include "core/grid/structured_grid.h"

namespace splinegrid {

using Point2 = std::array<double, 2>;

inline double Cross(const Point2& a, const Point2& b) { return a[0] * b[1] - a[1] * b[0]; }

// x0, y0, x1, y1, ...
std::vector<double> Flat(const std::vector<Point2>& p);

// Twice the signed area of the loop (positive counter-clockwise).
double SignedArea2(const std::vector<Point2>& p);

// Outward unit normals by central differences, `orientation` the sign of the loop's area; a
// corner gets the bisector of its two sides.
std::vector<Point2> LoopNormals(const std::vector<Point2>& p, double orientation);

// How far the loop turns at point i, in degrees (0 where it runs straight on).
double TurningDegrees(const std::vector<Point2>& p, int i);

// `block` with its i direction reversed.
StructuredBlock ReversedI(const StructuredBlock& block);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GENERATE_LOOP_GEOMETRY_H_
