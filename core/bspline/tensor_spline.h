// Tensor-product B-spline mappings: curves, surfaces and volumes.
//
//   X(u, v, w) = sum_{a,b,c} N_a(u) M_b(v) L_c(w) P_{abc},  (u, v, w) in [0, 1]^3,
//
// with one clamped knot vector per direction and control points P of 2 or 3 coordinates.
// Every spline has three directions; a direction that is not used has a single control point
// and the constant basis (order 1, knots {0, 1}), so a curve is n x 1 x 1 and a surface
// n x m x 1. Control points are stored like grid points (structured_grid.h): coordinates
// interleaved, first direction fastest.
#ifndef SPLINEGRID_CORE_BSPLINE_TENSOR_SPLINE_H_
#define SPLINEGRID_CORE_BSPLINE_TENSOR_SPLINE_H_

#include <array>
#include <span>
#include <vector>

#include "absl/status/statusor.h"
#include "core/bspline/knot_vector.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

class TensorSpline {
 public:
  // A single control point at the origin of R^3.
  TensorSpline() = default;

  // Validates and builds: spatial_dim 2 or 3, control.size() == spatial_dim * n_u n_v n_w
  // with n_d = knots[d].num_controls(), every control coordinate finite.
  static absl::StatusOr<TensorSpline> Create(std::array<KnotVector, 3> knots, int spatial_dim,
                                             std::vector<double> control);

  const KnotVector& knots(int direction) const { return knots_[direction]; }
  const std::array<KnotVector, 3>& all_knots() const { return knots_; }
  int spatial_dim() const { return spatial_dim_; }
  // Control points per direction.
  Extents control_extents() const;
  int64_t num_control_points() const { return NumPoints(control_extents()); }
  // Number of directions with more than one control point.
  int active_directions() const { return ActiveDirections(control_extents()); }

  std::span<const double> control() const { return control_; }
  std::span<double> mutable_control() { return control_; }
  // Coordinates of control point (a, b, c).
  const double* ControlPoint(int a, int b, int c) const {
    const Extents n = control_extents();
    return control_.data() + spatial_dim_ * (a + int64_t{n[0]} * (b + int64_t{n[1]} * c));
  }

 private:
  TensorSpline(std::array<KnotVector, 3> knots, int spatial_dim, std::vector<double> control)
      : knots_(std::move(knots)), spatial_dim_(spatial_dim), control_(std::move(control)) {}

  std::array<KnotVector, 3> knots_;
  int spatial_dim_ = 3;
  std::vector<double> control_ = std::vector<double>(3, 0.0);
};

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_BSPLINE_TENSOR_SPLINE_H_
