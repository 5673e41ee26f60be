// The reference length of a grid: the length the default tolerances by boundary kind are
// fractions of, so that the same grid in chords, millimetres or inches is fitted alike.
//
// The QUADFLOW paper states its tolerances in chords (0.15e-3 on the wing, 2e-3 on block
// interfaces, 8e-3 on outer boundaries). A grid's chord is found from its wall points
// (boundary_kinds.h):
//  - the wall points are joined into walls: two wall points belong to the same wall when they
//    are neighbours along an index direction of a block, or when they coincide (within 1e-9 of
//    the grid's bounding-box diagonal) across blocks or across a cut;
//  - a wall's extent is its diameter, the largest distance between two of its points: for an
//    airfoil (2D, a closed or open wall curve) the distance from the trailing to the leading
//    edge, the chord; for a wing surface (3D) the distance from the root's leading edge to the
//    tip's trailing edge;
//  - the reference length is the largest extent over the walls (the main element of a
//    multi-element airfoil, the largest body of a configuration).
// A grid without a wall point has the diagonal of its bounding box as reference length.
//
// The diameter is exact up to kExactDiameterPoints points of a wall (O(m^2) distances); beyond,
// it is the longest of the farthest-point sweeps started from the wall's extreme points along
// every coordinate (O(m) each): a lower bound that is exact for convex-ish bodies (every shared
// surface), stated in the description.
#ifndef SPLINEGRID_CORE_GRID_REFERENCE_LENGTH_H_
#define SPLINEGRID_CORE_GRID_REFERENCE_LENGTH_H_

#include <cstdint>
#include <string>

#include "core/grid/boundary_kinds.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

// Where a reference length came from.
enum class ReferenceLengthSource : uint8_t {
  kGiven = 1,        // by the caller (GridFitOptions::reference_length)
  kWall = 2,         // the largest extent of a wall
  kBoundingBox = 3,  // no wall: the diagonal of the grid's bounding box
};

// "given", "wall", "bounding box".
std::string_view ReferenceLengthSourceName(ReferenceLengthSource source);

// A reference length and how it was found.
struct ReferenceLength {
  double length = 1.0;  // in the grid's unit
  ReferenceLengthSource source = ReferenceLengthSource::kGiven;
  // One sentence, e.g. "the largest extent of 1 wall: 129 points in block 0, from (1, 0) to
  // (0, 0)".
  std::string description;
};

// Walls of more points than this get the sweep estimate of their diameter.
inline constexpr int64_t kExactDiameterPoints = 6000;

// The reference length of `grid` from its wall points (`kinds`, as ClassifyBoundaries made
// them for `grid`), see the file comment. Cost O(wall points) plus the diameters. Precondition:
// `kinds` belongs to `grid` (one entry per point of every block).
ReferenceLength DetectReferenceLength(const MultiBlockGrid& grid, const BoundaryKinds& kinds);

// Bits of GridFitOptions::relative_kinds: which tolerances by kind are fractions of the
// reference length. The first three are the BoundaryKind bits.
inline constexpr uint8_t kRelativeWall = static_cast<uint8_t>(BoundaryKind::kWall);
inline constexpr uint8_t kRelativeInterface = static_cast<uint8_t>(BoundaryKind::kInterface);
inline constexpr uint8_t kRelativeOuter = static_cast<uint8_t>(BoundaryKind::kOuter);
inline constexpr uint8_t kRelativeInterior = 8;
inline constexpr uint8_t kAllKindsRelative =
    kRelativeWall | kRelativeInterface | kRelativeOuter | kRelativeInterior;

// `tolerances` with the fields of the kinds in `relative_kinds` multiplied by `reference_length`
// (edge is relative to each edge's length and stays as it is; infinity stays infinity).
BoundaryTolerances ScaleTolerances(const BoundaryTolerances& tolerances, uint8_t relative_kinds,
                                   double reference_length);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GRID_REFERENCE_LENGTH_H_
