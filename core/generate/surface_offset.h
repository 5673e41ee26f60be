// Volume blocks by curvature-limited surface offsets: layers marched off a multi-block surface.
//
// The 3D analogue of offset_march.h. Each surface block (ni x nj) is fitted by a cubic B-spline
// X(u, v) (tensor_fit.h, faired with surface_fairing so that noise in the data does not tilt
// the normals), and layer after layer is offset along the spline's unit normals
//   N = side (X_u x X_v) / |X_u x X_v|,
// the step growing geometrically, h_k = first_height r^k with r = GeometricRatio
// (core/grid/sampling.h), so that the layers add up to `distance`. Every layer keeps the surface's
// parameters and knots: its spline is the previous one plus the spline of the displacement (fitted
// and faired, fairing.h), and the next layer's normals are taken from it. We fair the
// displacement, not the layer's points: the correction is then a small fraction of the step,
// whereas fairing the points moves them by a fraction of the layer's own size, which folds the
// thin cells near the wall and shrinks a sphere by far more than a step. A plane's displacement
// is constant and is reproduced exactly. Per layer:
//  - curvature limit: offsetting by h maps a grid edge from x_a to x_b, whose normals n_a, n_b
//    converge at the rate
//      kappa_e = -(n_b - n_a).(x_b - x_a) / |x_b - x_a|^2,
//    to one whose extent along itself is scaled by 1 - h kappa_e: it vanishes at h = 1 / kappa_e
//    (on a smooth surface kappa_e is the normal curvature along the edge, 1/R inside a sphere of
//    radius R). No point steps farther than max_curvature_step / kappa, kappa the largest
//    kappa_e of the edges at the point. So no layer reaches a centre of curvature: where the
//    limit holds on, the layers approach it geometrically, each keeping about
//    1 - max_curvature_step of the radius left. The rate is taken from the normals in use, so it
//    sees what smoothing and a distorted layer do to them; the principal curvatures of the
//    layer's spline are not used: where blocks meet at a convex corner (the M6's tip at the
//    trailing edge) the interpolated displacement through clustered parameters wriggles, and the
//    spline reported radii of 1e-4 on a convex tip, refusing the offset. The height a point is
//    denied is carried over to its next step (and limited again there), so where the curvature
//    relents later layers make it up. We carry the height rather than smoothing the normals
//    more: on a sphere no smoothing makes the normals converge less, only shorter steps help. As
//    soon as the height held back at some point exceeds max_shortfall * distance the offset is
//    refused (FAILED_PRECONDITION: the distance cannot be reached on the concave side); towards
//    a centre of curvature it is never given back, and marching on only distorts the layers
//    there. Below that it is reported as the shortfall.
//  - normal smoothing: Jacobi sweeps of the (1 2 1) x (1 2 1) average of neighbouring normals
//    (across block edges; along the edge only on free edges; free corners and poles keep
//    theirs), more the farther the layer: normal_smoothing times the fraction of the layers done,
//    and the fairing weight grows the same way, so the far field rounds out. A march to many
//    body lengths needs many sweeps: on the M6 to 5 (about 4 chords) the smallest scaled
//    Jacobian is 2e-4 with 10 sweeps at the last layer, 0.08 with 40, 0.31 with 80 (default);
//  - symmetry planes: a normal leaning towards a plane that the surface ends on has its lean
//    scaled by min(1, d / height) (d the distance to the plane, height the layer's above the
//    surface), so the layers meet the plane at right angles and no row overtakes another
//    towards it (a swept wing's trailing edge leans towards its root plane);
//  - folds: every new hexahedron must keep a positive Jacobian at its 8 corners (below); a layer
//    that does not is retried with the normals smoothed more (2 attempt more sweeps, the
//    curvature limit taken again), up to max_retries times, then FAILED_PRECONDITION. A faired
//    displacement that would fold a cell is replaced by the unfaired (interpolating) one.
// Blocks: a multi-block surface is marched as one. Block points that the connectivity matches
// (shared edges, corners, periodic seams) and the points of a collapsed edge are one vertex
// (surface_topology.h): it gets the normalised mean of its blocks' normals and one step, and
// it is smoothed with all its blocks' stencils together, so the volume
// blocks share their faces point for point (watertight) and a convex edge between blocks (a
// blunt trailing edge's corner) fans out along the mean normal. A concave crease between blocks
// (a wing-body junction, the inside of an L), or along a grid line across which one block kinks
// (its splines are then C0 there), is found on the surface and marched apart
// (concave_crease.h): its points go straight to their layer's height above both faces (along
// the bisector, by the miter), the faces' points near it move with it along their face and
// march along the face's normal, the normal smoothing does not cross it, and its edges do not
// limit the step. Where three concave creases meet (the inside corner of a box) the corner goes
// to its height above all three faces and the creases' points near it slide along their crease
// away from it. On block edges the spline's
// derivatives are one-sided (clamped knots), so no normal needs a neighbour outside its block.
// Where an edge collapses to one point (a pole: X_v = 0 along u = 0, say) the normal X_u x X_v
// vanishes; by l'Hopital X_v ~ u X_uv there, so the normal is that of X_u x X_uv (X_uv x X_v for
// X_u = 0), oriented like its regular neighbours; the pole is one vertex, its normal not
// smoothed. A free block edge on a symmetry plane (surface_topology.h: the root of a half wing on
// z = 0) keeps its points in the plane and its normals parallel to it.
// Orientation: each block keeps the surface's i and j, k = 0 the surface itself, and marches
// along side_b X_u x X_v, where side_b orients the blocks alike (surface_topology.h) times
// `side` (or outward). A corner Jacobian det[x_i, x_j, x_k] (the three cell edges leaving the
// corner in +i, +j, +k) has the sign of side_b: right-handed cells for +1, left-handed for -1.
// "Positive" below means side_b det > 0; corners on a collapsed edge (det = 0) are skipped.
// Only local folds are checked: a layer that meets a distant part of itself (a thin U-shaped
// surface offset inward) is not detected.
// Cost per layer O(k^2 ni nj) per block for the fit and the derivatives, plus the smoothing
// sweeps.
#ifndef SPLINEGRID_CORE_GENERATE_SURFACE_OFFSET_H_
#define SPLINEGRID_CORE_GENERATE_SURFACE_OFFSET_H_

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/generate/surface_topology.h"
#include "core/grid/connectivity.h"
#include "core/grid/structured_grid.h"
#include "core/util/cancellation.h"

namespace splinegrid {

// Bounds of the options below: a sweep costs about a microsecond per vertex, and more sweeps
// than this smooth a grid's normals flat; each retry smooths 2 * attempt sweeps more.
inline constexpr int kMaxNormalSmoothing = 1000;
inline constexpr int kMaxRetries = 100;

struct SurfaceOffsetOptions {
  int layers = 32;
  double first_height = 1e-3;  // of the first layer above the surface, in the surface's unit
  double distance = 0.5;       // of the last layer from the surface, same unit
  // +1: offset along the surface normal X_u x X_v of the first block of each connected group of
  // blocks (the others oriented alike); -1: against it. Ignored when `outward`.
  int side = +1;
  // Each connected group of blocks marches away from the volume it bounds (OrientOutward,
  // surface_topology.h); INVALID_ARGUMENT for a group that bounds none.
  bool outward = false;
  // Free block edges on a coordinate plane, the surface on one side of it, stay on it
  // (surface_topology.h: the root of a half wing). Turn off for a surface merely cut there.
  bool symmetry_planes = true;
  // Far-field smoothing: normal smoothing sweeps and the fairing weight at the last layer (both
  // grow linearly from the first layer's 1 / layers of them).
  int normal_smoothing = 80;
  double fairing = 1e-3;
  // Fairing weight lambda of the surface spline that the normals are taken from (not the points:
  // k = 0 is the surface as given). It keeps noise in the data from tilting the normals: the
  // shared M6 wing's trailing edge is noisy at 1e-8.
  double surface_fairing = 1e-3;
  // In (0, 1): no step is longer than this fraction of the local radius of curvature where the
  // layer is concave towards the offset (dimensionless).
  double max_curvature_step = 0.5;
  // In [0, 1]: the largest part of `distance` the curvature limit may hold back at a point
  // (after any layer); more is FAILED_PRECONDITION. Above ~0.1 the layers may distort as they
  // close in on a centre of curvature.
  double max_shortfall = 0.01;
  int max_retries = 20;  // extra normal smoothing rounds for one layer before giving up
  CancelCheck cancel;

  // OK, or INVALID_ARGUMENT naming the field and its value: a layer stack as offset_march.h's
  // ValidateLayerStack, one layer exactly first_height high, a growth ratio of at most
  // kMaxGrowthRatio (offset_march.h), options in range.
  absl::Status Validate() const;
};

struct SurfaceOffsetGrid {
  // Per surface block: ni x nj x (layers + 1), spatial_dim 3; k = 0 the surface (its points
  // matched to other blocks' moved to their common mean, see surface_gap).
  std::vector<StructuredBlock> blocks;
  std::vector<int> sides;  // per block: +1 right-handed cells, -1 left-handed (file comment)
  std::vector<SymmetryPlane> symmetry_planes;
  double surface_gap = 0.0;   // largest distance between matched surface points
  int components = 0;         // connected groups of blocks
  double growth_ratio = 1.0;  // r
  std::vector<double> steps;  // nominal h_k (sum = distance), before any curvature limit
  int retries = 0;            // extra normal smoothing rounds over all layers
  int refits_dropped = 0;     // layers whose faired displacement would have folded a cell
  int64_t limited_steps = 0;  // point steps shortened by the curvature limit, over all layers
  // Vertices of the surface on concave creases, between blocks or along a kinked grid line
  // inside one (concave_crease.h).
  int64_t crease_vertices = 0;
  // Largest height the curvature limit left unreached at a point of the last layer, in the
  // surface's unit (at most max_shortfall * distance).
  double shortfall = 0.0;
  // Smallest side det[x_i, x_j, x_k] / (|x_i| |x_j| |x_k|) over the cells' corners (collapsed
  // ones skipped): in (0, 1], 1 for an orthogonal cell.
  double min_scaled_jacobian = 1.0;
};

// Marches the layers (file comment). Every block of `surface` is ni x nj x 1 with spatial_dim 3,
// ni, nj >= 4; `connectivity` is FindConnectivity(surface) (the service keeps it with the grid).
// Errors: INVALID_ARGUMENT for bad options or a bad surface (too small, not a surface, not 3D,
// non-finite, collapsed to a point, hanging nodes, blocks that cannot be oriented alike;
// the message names the block); FAILED_PRECONDITION when a layer cannot be kept from folding
// (the message names the layer, block and cell) or the curvature limit holds back more than
// max_shortfall of the distance (the message names the block, point and layer); CANCELLED.
absl::StatusOr<SurfaceOffsetGrid> OffsetSurfaceGrid(const MultiBlockGrid& surface,
                                                    const Connectivity& connectivity,
                                                    const SurfaceOffsetOptions& options);

// One block: OffsetSurfaceGrid with the block's own connectivity (a periodic seam).
absl::StatusOr<SurfaceOffsetGrid> OffsetSurface(const StructuredBlock& surface,
                                                const SurfaceOffsetOptions& options);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GENERATE_SURFACE_OFFSET_H_
