// The wall of a grid around a profile: a closed loop of points distributed along it.
//
// A profile is a planar spline curve from the trailing edge around to the trailing edge
// (airfoil_fit.h): closed with a C0 corner when the trailing edge is sharp, open when it is
// blunt, in which case the loop is closed by the straight trailing-edge base, with a corner at
// either end of it. The loop's points follow the density
//   rho(s) = 1 + curvature_clustering sqrt(|kappa(s)| L / (2 pi)) + corner_clustering e^(-d /
//   delta),
// (L the loop's length, d the arc length to the nearest corner, delta = corner_width L) smoothed
// until neighbouring spacings differ by at most max_spacing_ratio, and are placed where the
// cumulative density reaches equal steps (equidistribution): dense at the leading edge, where
// the curvature is high (sqrt |kappa| keeps the turning per point from growing with it), and at
// the trailing edge corners; corners are always points of the loop.
#ifndef SPLINEGRID_CORE_GENERATE_WALL_LOOP_H_
#define SPLINEGRID_CORE_GENERATE_WALL_LOOP_H_

#include <array>
#include <vector>

#include "absl/status/statusor.h"
#include "core/bspline/tensor_spline.h"

namespace splinegrid {

// A planar profile: n x 1 x 1 curve with spatial_dim 2, parameters in [0, 1].
struct Profile {
  TensorSpline curve;
  // The ends coincide (within the curve's own rounding): a sharp trailing edge.
  bool closed = false;
  // Parameters of interior C0 corners (ascending, in (0, 1)).
  std::vector<double> corners;
};

struct WallOptions {
  int num_points = 257;  // points of the loop, the first repeated as the last
  double curvature_clustering = 1.0;
  double corner_clustering = 3.0;
  double corner_width = 0.02;
  double max_spacing_ratio = 1.15;  // of neighbouring spacings, >= 1
  int base_points = 9;              // points on a blunt trailing-edge base, >= 3

  absl::Status Validate() const;
};

struct WallLoop {
  std::vector<std::array<double, 2>> points;  // num_points, points.front() == points.back()
  std::vector<int> corners;                   // indices of corner points, ascending (0 first)
};

// The loop of the file comment. Errors: INVALID_ARGUMENT for bad options, a profile that is not
// a planar curve, or one with fewer points than its corners need.
absl::StatusOr<WallLoop> DistributeWall(const Profile& profile, const WallOptions& options);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GENERATE_WALL_LOOP_H_
