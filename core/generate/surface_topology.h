// How the points of a multi-block surface grid belong together, for marching layers off it
// (surface_offset.h): which block points are one vertex, how each block is oriented, where the
// surface ends on a symmetry plane.
//
//  - Vertices: block points are joined into one vertex where the grid's connectivity matches
//    them (connectivity.h: shared edges, periodic seams; a corner of three blocks becomes one
//    vertex through its edges) and where a block edge collapses to one point (a pole). A marcher
//    that moves every vertex once keeps the blocks watertight.
//  - Orientation: block b's normal is side[b] (X_u x X_v); the sides are chosen so that blocks
//    sharing an edge agree (their parameter squares' counter-clockwise loops run along it in
//    opposite directions, as two faces of a polyhedron), starting from +1 at the first block of
//    each connected component. A surface whose blocks cannot agree (a Moebius strip) is refused.
//  - Symmetry planes: a block edge matched to nothing whose points all lie in a coordinate plane
//    x, y or z = c, with the whole surface on one side of that plane and leaving it steeply (the
//    surface normals along the edge within kSymmetryTiltDegrees of parallel to the plane), is a
//    symmetry plane: the root of a half wing. Its vertices keep that coordinate at c. A swept
//    wing's root meets its plane obliquely (the M6's normals lean up to 30 degrees out of it near
//    the leading edge), so the limit is loose; it only keeps a surface that touches a plane nearly
//    tangentially from being held in it.
//  - Vertex kinds, for smoothing the normals: a vertex shared by several block points (or on a
//    symmetry plane) is smoothed with the stencils of all its blocks together; a vertex on a free
//    edge only along that edge; free corners and poles keep their normal.
#ifndef SPLINEGRID_CORE_GENERATE_SURFACE_TOPOLOGY_H_
#define SPLINEGRID_CORE_GENERATE_SURFACE_TOPOLOGY_H_

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/grid/connectivity.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

// An edge whose points all lie this close (times the surface's size) to its first point is
// collapsed (a pole); a derivative this short (times the size) has vanished.
inline constexpr double kCollapsedFraction = 1e-9;

// At most this many symmetry planes (two per axis, the surface between them, is six).
inline constexpr size_t kMaxSymmetryPlanes = 8;

// The surface normals along a symmetry plane's edge lean at most this far out of the plane.
inline constexpr double kSymmetryTiltDegrees = 60.0;

enum class VertexKind : uint8_t {
  kShared,    // smoothed with every block's stencil (interior points too)
  kFreeEdge,  // smoothed along its block edge only
  kFixed,     // a free corner or a pole: not smoothed
};

// A coordinate plane x[axis] = value that the surface ends on.
struct SymmetryPlane {
  int axis = 0;
  double value = 0.0;
};

struct SurfaceTopology {
  int64_t num_vertices = 0;
  // vertex[b][q]: the vertex of block b's point q (i fastest).
  std::vector<std::vector<int64_t>> vertex;
  std::vector<VertexKind> kind;  // per vertex
  // Per vertex: bit p set when it lies on planes[p] (the corner of a quarter model on two).
  std::vector<uint8_t> plane;
  std::vector<SymmetryPlane> planes;
  std::vector<int> side;       // per block, +1 or -1 (file comment)
  std::vector<int> component;  // per block: its connected group of blocks, from 0
  int components = 0;
  // Largest distance between block points joined into one vertex (the matches' gap).
  double max_gap = 0.0;
  double scale = 0.0;  // the diagonal of the surface's bounding box
};

// The topology of `surface` (blocks ni x nj x 1, spatial_dim 3) with its `connectivity`
// (FindConnectivity of the same blocks); symmetry planes only if `find_symmetry_planes`.
// Errors: INVALID_ARGUMENT for a match outside the blocks (a connectivity of another grid), a
// surface whose matches have hanging nodes (step 2) or whose blocks cannot be oriented alike,
// naming the match or the blocks.
absl::StatusOr<SurfaceTopology> BuildSurfaceTopology(const MultiBlockGrid& surface,
                                                     const Connectivity& connectivity,
                                                     bool find_symmetry_planes);

// Flips the sides of every connected group of blocks whose normals point into the volume it
// bounds, so that they point away from it: outward when the area-weighted sum of
// side n . (x - c) over the group's points is positive, c the group's centroid (on a closed
// surface or one closed by symmetry planes, the flux of x - c through it is 3 times the enclosed
// volume). INVALID_ARGUMENT for a group whose sum does not tell (below 1e-3 of the sum of
// |n| |x - c|: a flat or saddle-shaped patch), naming its first block.
absl::Status OrientOutward(const MultiBlockGrid& surface, SurfaceTopology& topology);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GENERATE_SURFACE_TOPOLOGY_H_
