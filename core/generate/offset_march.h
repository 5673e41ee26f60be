// Grids by curvature-controlled offsets: layers marched outward from a wall loop.
//
// From the wall loop (wall_loop.h) layer after layer is offset along its normals, the step
// growing geometrically, h_k = first_height r^k, with r such that the layers add up to
// `distance` (sum h_k = distance). Each layer is a closed loop cut at its corners (the trailing
// edge and a blunt base's corners, carried outward); between corners it is refitted by a
// B-spline and faired (fairing.h), and its points redistributed along it. So the grid follows
// the spline's own geometry instead of solving a hyperbolic system (the QUADFLOW alternative
// to level sets), and:
//  - step and curvature: where neighbouring normals converge (a concave region, or a convex one
//    as seen from inside), the new segment shrinks by 1 + h kappa; a layer whose segments would
//    shrink below min_segment_ratio of their length, reverse, or cross another is retried with
//    the normals smoothed over their neighbours (which lowers the layer's effective curvature)
//    until it does not, so no layer intersects itself;
//  - curvature reduction: before the next step h' a layer's concave parts are smoothed until no
//    point turns by more than max_concave_turning over h' (h' kappa <= 0.1, concave_fill.h), so a
//    cove fills faster than the rest instead of focusing its normals on one point;
//  - normals are smoothed more the farther the layer (normal_smoothing sweeps times the
//    fraction of the layers done), and the fairing weight grows the same way, so the far field
//    rounds out; a corner stays a corner (its normal the bisector, CornerBisector, the refit split
//    there) while the layer turns there by 15 degrees or more, then it is smoothed like any point;
//  - points slide along each layer from the wall's distribution towards even spacing, layer k
//    by uniformity / (layers - k) of the way (so that the unevenness left is the fraction of
//    layers still to go), but no point by more than tan(a) times the step, the tilt a growing
//    with the layers: near the wall the grid lines leave it along its normals (orthogonal), and
//    the spacing evens out once the steps are comparable to the unevenness.
// The result is an O-grid: i runs along the loop (the first line repeated as the last: the
// seam leaves the trailing edge), clockwise so that (i, j) is right-handed and every cell's
// signed area positive, j through the layers, j = 0 the wall.
#ifndef SPLINEGRID_CORE_GENERATE_OFFSET_MARCH_H_
#define SPLINEGRID_CORE_GENERATE_OFFSET_MARCH_H_

#include <vector>

#include "absl/status/statusor.h"
#include "core/generate/wall_loop.h"
#include "core/grid/structured_grid.h"
#include "core/util/cancellation.h"

namespace splinegrid {

struct OffsetOptions {
  int layers = 128;
  double first_height = 1e-5;  // of the first layer above the wall, in the wall's unit
  double distance = 50.0;      // of the outermost layer from the wall
  // Far-field smoothing: normal smoothing sweeps and the fairing weight at the last layer.
  int normal_smoothing = 20;
  double fairing = 1e-3;
  double uniformity = 1.0;  // in [0, 1]
  // No point slides along a layer by more than tan(a) times the layer's step, a growing from
  // wall_tilt_degrees at the wall to far_tilt_degrees at the last layer: the grid lines leave
  // the wall within wall_tilt_degrees of its normal, and far out the points may slide enough
  // to even out the spacing.
  double wall_tilt_degrees = 2.5;
  double far_tilt_degrees = 30.0;
  double min_segment_ratio = 0.25;  // of a layer's segments against the previous layer's
  // The largest h' kappa left on a layer's concave parts before the next step h' (concave_fill.h),
  // in (0, 1): a concave part shrinks by 1 - h' kappa in that step.
  double max_concave_turning = 0.1;
  int max_retries = 60;  // normal smoothing rounds for one layer before giving up
  CancelCheck cancel;

  absl::Status Validate() const;
};

struct OffsetGrid {
  StructuredBlock block;      // wall points x (layers + 1), spatial_dim 2
  double growth_ratio = 1.0;  // r
  std::vector<double> steps;  // h_k
  int retries = 0;            // extra normal smoothing rounds over all layers
};

// Marches the layers (file comment). Errors: INVALID_ARGUMENT for bad options, a wall loop of
// fewer than 5 points, one that is not closed or crosses itself, or a distance below
// layers * first_height; FAILED_PRECONDITION when a layer cannot be kept from folding (the
// message names the layer); CANCELLED.
absl::StatusOr<OffsetGrid> MarchOffsets(const WallLoop& wall, const OffsetOptions& options);

// The most layers a stack may have.
inline constexpr int kMaxLayers = 100000;

// The largest growth ratio between consecutive marched layers: beyond it a layer is more than 10
// times the one below (and a far field of 1e300 overflowed the steps). The algebraic methods
// (transfinite, elliptic) take any stack.
inline constexpr double kMaxGrowthRatio = 10.0;

// OK for 1 .. kMaxLayers layers; INVALID_ARGUMENT naming `layers` otherwise.
absl::Status ValidateLayerCount(int layers);

// OK for a stack of 1 .. kMaxLayers layers growing from first_height to add up to distance (both
// positive, finite, distance >= layers * first_height); INVALID_ARGUMENT naming the field.
absl::Status ValidateLayerStack(int layers, double first_height, double distance);

// OK when a stack of `layers` from `first_height` reaching `distance` grows by at most
// kMaxGrowthRatio per layer (GeometricRatio); INVALID_ARGUMENT naming distance, the ratio and
// the way out otherwise. For the marched methods (MarchOffsets, OffsetSurfaceGrid).
absl::Status ValidateMarchedGrowth(int layers, double first_height, double distance);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GENERATE_OFFSET_MARCH_H_
