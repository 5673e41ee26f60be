// Volume blocks by curvature-limited surface offsets: layers marched off a surface block.
//
// The 3D analogue of offset_march.h. The surface (an ni x nj block) is fitted by a cubic
// B-spline X(u, v) (tensor_fit.h, faired with surface_fairing so that noise in the data does
// not pose as curvature), and layer after layer is offset along the spline's unit normals
//   N = side (X_u x X_v) / |X_u x X_v|,
// the step growing geometrically, h_k = first_height r^k with r = GeometricRatio
// (core/grid/sampling.h), so that the layers add up to `distance`. Every layer keeps the surface's
// parameters and knots: its spline is the previous one plus the spline of the displacement (fitted
// and faired, fairing.h), and the next layer's normals and curvatures are taken from it. We fair
// the displacement, not the layer's points: the correction is then a small fraction of the step,
// whereas fairing the points moves them by a fraction of the layer's own size, which folds the
// thin cells near the wall and shrinks a sphere by far more than a step. A plane's displacement
// is constant and is reproduced exactly. Per layer:
//  - curvature limit: offsetting by h maps a principal direction of curvature kappa (taken
//    against N: kappa > 0 where the layer is concave towards the offset, e.g. 1/R inside a
//    sphere of radius R) to one scaled by 1 - h kappa, which vanishes at the centre of
//    curvature h = 1/kappa. With the largest principal curvature
//      kappa_max = H + sqrt(H^2 - K),  H = (E N' - 2 F M + G L) / (2 (E G - F^2)),
//                                      K = (L N' - M^2) / (E G - F^2)
//    (first fundamental form E, F, G of X_u, X_v; second L, M, N' = X_uu.N, X_uv.N, X_vv.N; do
//    Carmo, "Differential Geometry of Curves and Surfaces", sec. 3-3) no point steps farther
//    than max_curvature_step / kappa, kappa the larger of kappa_max and the convergence of the
//    normals actually used along the grid edges at the point,
//      kappa_e = -(n_b - n_a).(x_b - x_a) / |x_b - x_a|^2
//    (the discrete 1 - h kappa: the edge's extent along itself vanishes at h = 1 / kappa_e; it
//    sees what smoothing and a distorted layer do to the normals). So no layer reaches a centre
//    of curvature: where the limit holds on, the layers approach it geometrically, each keeping
//    about 1 - max_curvature_step of the radius left. The height a point is denied is carried
//    over to its next step (and limited again there), so where the curvature relents later
//    layers make it up. We carry the height rather than smoothing the normals more: on a
//    sphere no smoothing makes the normals converge less, only shorter steps help. As soon as
//    the height held back at some point exceeds max_shortfall * distance the offset is refused
//    (FAILED_PRECONDITION: the distance cannot be reached on the concave side); towards a
//    centre of curvature it is never given back, and marching on only distorts the layers
//    there. Below that it is reported as the shortfall.
//  - normal smoothing: Jacobi sweeps of the (1 2 1) x (1 2 1) average of neighbouring normals
//    (along the edge only on block edges; corners and collapsed edges keep theirs), more the
//    farther the layer: normal_smoothing times the fraction of the layers done, and the fairing
//    weight grows the same way, so the far field rounds out;
//  - folds: every new hexahedron must keep a positive Jacobian at its 8 corners (below); a layer
//    that does not is retried with the normals smoothed more (2 attempt more sweeps, the
//    curvature limit taken again), up to max_retries times, then FAILED_PRECONDITION. A faired
//    displacement that would fold a cell is replaced by the unfaired (interpolating) one.
// Edges and degenerate edges: on block edges and corners the spline's derivatives are
// one-sided (clamped knots), so the normal needs no neighbour outside the block. Where an edge
// collapses to one point (a pole: X_v = 0 along u = 0, say) the normal X_u x X_v vanishes; by
// l'Hopital X_v ~ u X_uv there, so the normal is that of X_u x X_uv (X_uv x X_v for X_u = 0),
// oriented like its regular neighbours. All points of a collapsed edge share the mean of their
// normals, their largest neighbouring curvature and one step, and are set to their mean after
// every layer, so the edge stays one point, moving along the pole's normal.
// Orientation: the block keeps the surface's i and j, k = 0 the surface itself, so a corner
// Jacobian det[x_i, x_j, x_k] (the three cell edges leaving the corner in +i, +j, +k) has the
// sign of `side`: right-handed cells for side = +1 (offset along X_u x X_v), left-handed for
// side = -1. "Positive" below means side det > 0; corners on a collapsed edge (det = 0) are
// skipped. Only local folds are checked: a layer that meets a distant part of itself (a thin
// U-shaped surface offset inward) is not detected. Each block is offset on its own: blocks
// that share an edge get the same edge offsets only where their one-sided normals agree.
// Cost per layer O(k^2 ni nj) for the fit and the derivatives, plus the smoothing sweeps.
#ifndef SPLINEGRID_CORE_GENERATE_SURFACE_OFFSET_H_
#define SPLINEGRID_CORE_GENERATE_SURFACE_OFFSET_H_

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/grid/structured_grid.h"
#include "core/util/cancellation.h"

namespace splinegrid {

struct SurfaceOffsetOptions {
  int layers = 32;
  double first_height = 1e-3;  // of the first layer above the surface, in the surface's unit
  double distance = 0.5;       // of the last layer from the surface, same unit
  // +1: offset along the surface normal X_u x X_v of its (i, j); -1: against it.
  int side = +1;
  // Far-field smoothing: normal smoothing sweeps and the fairing weight at the last layer (both
  // grow linearly from the first layer's 1 / layers of them).
  int normal_smoothing = 10;
  double fairing = 1e-3;
  // Fairing weight lambda of the surface spline that the normals and curvatures are taken from
  // (not the points: k = 0 is the surface as given). It keeps noise in the data from posing as
  // curvature: the shared M6 wing's trailing edge, noisy at 1e-8, has spurious radii of
  // curvature of 0.1 in the interpolating spline.
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

  // OK, or INVALID_ARGUMENT naming the field and its value.
  absl::Status Validate() const;
};

struct SurfaceOffsetGrid {
  StructuredBlock block;      // ni x nj x (layers + 1), spatial_dim 3; k = 0 the surface
  double growth_ratio = 1.0;  // r
  std::vector<double> steps;  // nominal h_k (sum = distance), before any curvature limit
  int retries = 0;            // extra normal smoothing rounds over all layers
  int refits_dropped = 0;     // layers whose faired displacement would have folded a cell
  int64_t limited_steps = 0;  // point steps shortened by the curvature limit, over all layers
  // Largest height the curvature limit left unreached at a point of the last layer, in the
  // surface's unit (at most max_shortfall * distance).
  double shortfall = 0.0;
  // Smallest side det[x_i, x_j, x_k] / (|x_i| |x_j| |x_k|) over the cells' corners (collapsed
  // ones skipped): in (0, 1], 1 for an orthogonal cell.
  double min_scaled_jacobian = 1.0;
};

// Marches the layers (file comment). `surface` is an ni x nj x 1 block with spatial_dim 3,
// ni, nj >= 4. Errors: INVALID_ARGUMENT for bad options or a bad surface (too small, not a
// surface, not 3D, non-finite, collapsed to a point); FAILED_PRECONDITION when a layer cannot
// be kept from folding (the message names the layer and cell) or the curvature limit holds
// back more than max_shortfall of the distance (the message names the point and layer);
// CANCELLED.
absl::StatusOr<SurfaceOffsetGrid> OffsetSurface(const StructuredBlock& surface,
                                                const SurfaceOffsetOptions& options);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GENERATE_SURFACE_OFFSET_H_
