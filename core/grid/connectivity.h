// Connectivity of a multi-block structured grid: which parts of block boundaries coincide.
//
// A block's boundary consists of faces: for every direction d with more than one point, the
// face at index 0 and the face at index n_d - 1 (edges for surfaces and planar blocks, faces for
// volumes). A match is a rectangular range of one face whose points coincide one by one with a
// range of another face (of another block, or of the same block: the wake cut of a C-grid, the
// periodic seam of an O-grid), with an orientation: each tangential direction of the first face
// runs along some tangential direction of the second, forwards or backwards. Matches may cover
// part of a face (a T-junction, the wake part of a C-grid's wall face) and, on edges, may have
// hanging nodes: every point of the coarse edge coincides with every second point of the fine one.
// A range collapsed to a point or a line (a pole, poles.h) is never a match: its points coincide
// with each other in any order, so they say nothing about which points belong together.
#ifndef SPLINEGRID_CORE_GRID_CONNECTIVITY_H_
#define SPLINEGRID_CORE_GRID_CONNECTIVITY_H_

#include <array>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/grid/structured_grid.h"
#include "core/util/cancellation.h"

namespace splinegrid {

// A face of a block: the points with index `upper ? n - 1 : 0` in direction `normal`.
struct Face {
  int block = 0;
  int normal = 0;
  bool upper = false;

  friend bool operator==(const Face&, const Face&) = default;
};

// A rectangle of a face, inclusive at both ends (the normal direction has begin == end).
struct FaceRange {
  Face face;
  Extents begin = {0, 0, 0};
  Extents end = {0, 0, 0};

  friend bool operator==(const FaceRange&, const FaceRange&) = default;
};

// Two coinciding face ranges. Index x of range `a` (x[d] in [a.begin[d], a.end[d]]) coincides
// with the index y of range `b` where, for each tangential direction d of `a` (begin < end),
//   y[b_direction[d]] = b.begin[..] + step * (x[d] - a.begin[d])          (forwards), or
//   y[b_direction[d]] = b.end[..]   - step * (x[d] - a.begin[d])          (reversed),
// and y is on b's face in the normal direction. step is 1 (point-matched) or 2 (hanging nodes:
// `b` is the fine side; its odd points lie between a's points).
struct BoundaryMatch {
  FaceRange a, b;
  std::array<int, 3> b_direction = {-1, -1, -1};  // -1 for a's normal and unused directions
  std::array<bool, 3> reversed = {false, false, false};
  int step = 1;

  // The index of `b` that coincides with index `x` of `a` (x inside a's range).
  Extents MapToB(const Extents& x) const;
  // e.g. "block 0 j=0 i[0..32] ~ block 0 j=0 i[192..224] reversed".
  std::string Describe() const;

  friend bool operator==(const BoundaryMatch&, const BoundaryMatch&) = default;
};

struct ConnectivityOptions {
  // Points closer than this (in the grid's length unit) are candidates; <= 0 means 1e-7 times
  // the diagonal of the grid's bounding box.
  double absolute_tolerance = 0.0;
  // ... and must also be closer than this fraction of the local grid spacing at both points
  // (so that distinct points of a finely clustered boundary never match).
  double relative_tolerance = 1e-3;
  // Matches of fewer points are ignored (a shared corner point alone is not a match).
  int min_points = 2;

  // INVALID_ARGUMENT naming the field: tolerances must be finite, relative_tolerance > 0 and
  // min_points >= 2.
  absl::Status Validate() const;
};

struct Connectivity {
  std::vector<BoundaryMatch> matches;

  friend bool operator==(const Connectivity&, const Connectivity&) = default;
};

// Finds all matches between the boundaries of `grid`'s blocks. Cost about O(boundary points)
// (hashed), plus O(matched points) to grow the matches; `cancel` is polled once per 2^16 points.
// Errors: INVALID_ARGUMENT for bad options, blocks of different spatial dimensions or non-finite
// coordinates (naming the block and point), CANCELLED.
absl::StatusOr<Connectivity> FindConnectivity(const MultiBlockGrid& grid,
                                              const ConnectivityOptions& options = {},
                                              const CancelCheck& cancel = {});

// The faces of `block` (index b): two per direction with more than one point.
std::vector<Face> BlockFaces(const StructuredBlock& block, int b);

// "i=0", "j=max", ...
std::string FaceName(const Face& face);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GRID_CONNECTIVITY_H_
