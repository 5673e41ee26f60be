// Structured multi-block grids: the point data that splinegrid fits and writes.
//
// A block is an ni x nj x nk array of points with 2 or 3 coordinates each, stored
// contiguously with the coordinates interleaved and i fastest:
//   coords[s + spatial_dim * (i + ni * (j + nj * k))],  s < spatial_dim.
// Curves and surfaces are blocks whose unused directions have extent 1.
#ifndef SPLINEGRID_CORE_GRID_STRUCTURED_GRID_H_
#define SPLINEGRID_CORE_GRID_STRUCTURED_GRID_H_

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "absl/status/status.h"

namespace splinegrid {

// Point counts per index direction (i, j, k); an unused direction has extent 1.
using Extents = std::array<int, 3>;

// Total number of points of `extents`.
inline int64_t NumPoints(const Extents& extents) {
  return int64_t{extents[0]} * extents[1] * extents[2];
}

// Number of directions with more than one point: 0 (a point), 1 (curve), 2 (surface), 3 (volume).
int ActiveDirections(const Extents& extents);

class StructuredBlock {
 public:
  StructuredBlock() = default;
  // A zero-filled block of `extents` points with `spatial_dim` (2 or 3) coordinates each.
  // Precondition: every extent >= 1, spatial_dim in {2, 3}; see ValidateExtents for user input.
  StructuredBlock(const Extents& extents, int spatial_dim);

  const Extents& extents() const { return extents_; }
  int extent(int direction) const { return extents_[direction]; }
  int spatial_dim() const { return spatial_dim_; }
  int64_t num_points() const { return NumPoints(extents_); }

  // Interleaved coordinates, i fastest (see the file comment).
  std::span<double> coords() { return coords_; }
  std::span<const double> coords() const { return coords_; }

  // Linear index of point (i, j, k).
  int64_t Index(int i, int j, int k) const {
    return i + int64_t{extents_[0]} * (j + int64_t{extents_[1]} * k);
  }
  // Coordinates of point (i, j, k): spatial_dim() consecutive doubles.
  double* Point(int i, int j, int k) { return coords_.data() + spatial_dim_ * Index(i, j, k); }
  const double* Point(int i, int j, int k) const {
    return coords_.data() + spatial_dim_ * Index(i, j, k);
  }

  // Optional Plot3D iblank flags, one per point (empty when the source had none).
  std::vector<int>& iblank() { return iblank_; }
  const std::vector<int>& iblank() const { return iblank_; }

 private:
  Extents extents_ = {1, 1, 1};
  int spatial_dim_ = 3;
  std::vector<double> coords_ = std::vector<double>(3, 0.0);
  std::vector<int> iblank_;
};

// A multi-block structured grid, in the order the blocks were read or given.
struct MultiBlockGrid {
  std::vector<StructuredBlock> blocks;
};

// The largest |coordinate| of the grid's points (0 for a grid without points).
double LargestCoordinate(const MultiBlockGrid& grid);

// Lengths below this many units in the last place of a grid's largest coordinate round away:
// two points closer than that can have the same coordinates, and a deviation that small can be
// neither met nor measured.
inline constexpr double kResolvableUlps = 8.0;

// OK when every extent is in [1, max_extent] and the product is at most max_points;
// otherwise INVALID_ARGUMENT naming `what` (e.g. "block 3") and the offending value.
absl::Status ValidateExtents(const Extents& extents, const std::string& what,
                             int64_t max_points = int64_t{1} << 31, int max_extent = 1 << 24);

// Reverses `block`'s index direction `direction` (0, 1 or 2) in place: point x moves to
// n - 1 - x along it.
void ReverseDirection(StructuredBlock& block, int direction);

// OK when every coordinate of `block` is finite; otherwise INVALID_ARGUMENT naming
// `what`, the point index (i, j, k) and the value.
absl::Status ValidateFinite(const StructuredBlock& block, const std::string& what);

// OK when `block` can be fitted: finite coordinates, a volume (three directions with more than
// one point) only with spatial_dim 3, no active direction of zero length (every grid line of
// that direction a single repeated point), and cells that span as many dimensions as the block
// has active directions: the sum over cells and cell corners of |det| of the corner's edge
// vectors along the active directions (length, area, volume) exceeds 1e-12 L^D, L the diagonal
// of the bounding box, D the active directions. So a block whose points are all equal, lie on one
// line (a surface) or one plane (a volume) is refused; collapsed edges and faces (polar axes,
// wing-tip caps) leave other cells with a measure and pass. Otherwise INVALID_ARGUMENT naming
// `what` and what is degenerate. Cost O(points), one pass per direction and one over the cells.
absl::Status ValidateFittable(const StructuredBlock& block, const std::string& what);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GRID_STRUCTURED_GRID_H_
