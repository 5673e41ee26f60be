// Planar polylines given as interleaved coordinates x_0, y_0, x_1, y_1, ...: whether one is
// simple, i.e. does not cross or touch itself (an airfoil outline must go once around the
// profile, airfoil_fit.h).
//
// Segment i joins points i and i + 1. Two segments that are not neighbours meet when they cross
// properly (each one's end points lie strictly on opposite sides of the other's line) or when an
// end point of one lies on the other (its cross product is exactly 0 and it is inside the other's
// bounding box), which includes touching, collinear overlap and repeated points. Neighbours
// always share a point; they only meet when they fold back onto each other (exactly collinear
// and pointing in opposite directions). The predicates are evaluated in floating point without
// a tolerance: nearly degenerate configurations are decided by the sign of the rounded cross
// products.
//
// The search is a sweep over x: the segments, sorted by their smallest x, are compared only
// with those whose x-ranges overlap (about two per segment on an airfoil outline), so the cost
// is O(m log m) for m points on an outline and O(m^2) at worst (every x-range overlapping).
#ifndef SPLINEGRID_CORE_GRID_POLYLINE_H_
#define SPLINEGRID_CORE_GRID_POLYLINE_H_

#include <optional>
#include <span>

namespace splinegrid {

// Two segments of a polyline that meet: segment `first` (points first, first + 1) and segment
// `second` (points second, second + 1), first < second.
struct PolylineCrossing {
  int first = 0;
  int second = 0;
};

// A pair of segments where the polyline of `xy` (m = xy.size() / 2 points) crosses or touches
// itself (file comment), or nullopt when it is simple. The pair reported is the first one found:
// fold-backs of neighbours in point order, then the sweep's pairs; not necessarily the one of
// lowest indices. With `closed`, the last point is the first one again (a closed loop listed
// with its start repeated): the first and last segments are then neighbours that meet at that
// point, and their pair is not checked. Fewer than three points are always simple.
std::optional<PolylineCrossing> FindPolylineCrossing(std::span<const double> xy, bool closed);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GRID_POLYLINE_H_
