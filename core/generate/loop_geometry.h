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

// Outward unit normals by central differences (normal to the chord from the previous to the
// next point), `orientation` the sign of the loop's area. At a corner this is not the bisector
// unless both sides have the same length: see CornerBisector.
std::vector<Point2> LoopNormals(const std::vector<Point2>& p, double orientation);

// The outward unit bisector of the angle at point i: the normalised sum of its two sides' unit
// normals, whatever their lengths. A grid line leaving a thin wedge (kWedgeDegrees) must be it:
// the corner's two cells share the exterior angle 180 + turning degrees, and any other split of
// a thin wedge gives one of them a reflex angle. At a sharp trailing edge with sides of 2.8e-3
// and 3.0e-3 the central-difference normal is 33 degrees off the bisector, so the seam's first
// cell is non-convex (a 209 degree angle at the edge) and its refinements fold.
Point2 CornerBisector(const std::vector<Point2>& p, int i, double orientation);

// A corner turning by more than this many degrees is a thin wedge (a sharp trailing edge): its
// two cells share more than 300 degrees, so its line must be the bisector (CornerBisector).
// Blunter corners (a blunt base's, turning about 90 degrees) keep the central-difference
// normal: both cells stay convex with it, the transfinite fans were tuned to it, and the
// bisector there made one SC(2)-0714 grid fold (a fan's last line crossing its neighbour).
inline constexpr double kWedgeDegrees = 120.0;

// How far the loop turns at point i, in degrees (0 where it runs straight on).
double TurningDegrees(const std::vector<Point2>& p, int i);

// The loop's turning at point i in radians, signed: positive where it turns with `orientation`
// (the sign of the loop's area), that is where the loop is convex.
double SignedTurning(const std::vector<Point2>& p, int i, double orientation);

// The signed area of cell (i, j) of a planar grid (spatial_dim 2): half the cross product of its
// diagonals (equal to the shoelace area of the quadrilateral), positive where (i, j) is
// right-handed.
double SignedCellArea(const StructuredBlock& grid, int i, int j);

// `block` with its i direction reversed.
StructuredBlock ReversedI(const StructuredBlock& block);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GENERATE_LOOP_GEOMETRY_H_
