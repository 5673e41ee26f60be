// Evaluation of tensor-product B-splines: single points with derivatives, and whole grids of
// parameters by sum factorisation.
#ifndef SPLINEGRID_CORE_BSPLINE_EVALUATION_H_
#define SPLINEGRID_CORE_BSPLINE_EVALUATION_H_

#include <array>
#include <cstdint>
#include <vector>

#include "core/bspline/basis.h"
#include "core/bspline/tensor_spline.h"

namespace splinegrid {

// A point or vector of R^2 or R^3 (z = 0 in 2D).
using Point3 = std::array<double, 3>;

// X(u, v, w). Parameters outside [0, 1] are clamped. Cost O(k^3).
Point3 EvaluatePoint(const TensorSpline& spline, const Point3& uvw);

// Partial derivatives d^{a+b+c} X / du^a dv^b dw^c at one parameter point, for
// a, b, c <= max_order. (0, 0, 0) is the point itself.
class PartialDerivatives {
 public:
  PartialDerivatives(int max_order)
      : max_order_(max_order), d_((max_order + 1) * (max_order + 1) * (max_order + 1)) {}
  int max_order() const { return max_order_; }
  const Point3& operator()(int a, int b, int c) const { return d_[Index(a, b, c)]; }
  Point3& operator()(int a, int b, int c) { return d_[Index(a, b, c)]; }

 private:
  int Index(int a, int b, int c) const { return a + (max_order_ + 1) * (b + (max_order_ + 1) * c); }
  int max_order_;
  std::vector<Point3> d_;
};

// All partial derivatives up to `max_order` per direction (P&T A3.6 generalised to three
// directions). Cost O(k^3 (max_order + 1)^3).
PartialDerivatives EvaluateDerivatives(const TensorSpline& spline, const Point3& uvw,
                                       int max_order);

// Evaluates a spline on the tensor grid params[0] x params[1] x params[2] by sum
// factorisation (contract one direction at a time with precomputed basis values):
//   1. Y = contraction of the control net in u          (once, n_u' x n_v x n_w points)
//   2. per output plane k: Z_k = contraction of Y in w  (n_u' x n_v points)
//   3. per output line (j, k): contraction of Z_k in v, written straight to the output.
// Cost O(k * output points) plus O(k * n_u' n_v n_w) setup; memory O(n_u' n_v n_w), not
// O(output) (curves: O(1)). Lines (all i for one (j, k), index j + n_j' k) can be produced in any
// order and in pieces, which is how large results are streamed. Not thread-safe (caches the current
// plane); use one evaluator per thread.
class GridEvaluator {
 public:
  // params[d] are clamped into [0, 1]; a direction with one control point needs one parameter
  // (any value). With first_derivatives, EvaluateLines also writes dX/du, dX/dv, dX/dw.
  // Precondition: every params[d] is non-empty.
  GridEvaluator(const TensorSpline& spline, const std::array<std::vector<double>, 3>& params,
                bool first_derivatives);

  // Output point counts per direction.
  const Extents& extents() const { return extents_; }
  int spatial_dim() const { return spatial_dim_; }
  // Number of output lines, n_j' n_k'.
  int64_t num_lines() const { return int64_t{extents_[1]} * extents_[2]; }
  // Doubles per output line: spatial_dim * n_i'.
  int64_t line_size() const { return int64_t{spatial_dim_} * extents_[0]; }

  // Writes lines [begin, end) contiguously to `points` ((end - begin) * line_size() doubles)
  // and, when constructed with first_derivatives, the same layout to du, dv, dw (else they may
  // be null).
  void EvaluateLines(int64_t begin, int64_t end, double* points, double* du = nullptr,
                     double* dv = nullptr, double* dw = nullptr);

  // Points i_begin <= i < i_end of one line, for lines too long for one piece of a stream.
  void EvaluateLineRange(int64_t line, int i_begin, int i_end, double* points, double* du = nullptr,
                         double* dv = nullptr, double* dw = nullptr);

 private:
  void ComputePlane(int k);
  void EvaluateCurve(int i_begin, int i_end, double* points, double* du, double* dv,
                     double* dw) const;

  int spatial_dim_;
  bool derivatives_;
  Extents extents_;
  // Curves (one control point in v and w, one output line) skip the intermediate nets and
  // sample the basis in chunks, so memory stays O(chunk) for any number of output points.
  bool curve_ = false;
  KnotVector knots_u_;
  std::vector<double> params_u_, control_;
  int n_v_, n_w_;  // control counts in v and w
  SampledBasis basis_v_, basis_w_;
  std::vector<double> y_, y_du_;         // control net contracted in u (and du)
  int plane_ = -1;                       // output plane held in z_*
  std::vector<double> z_, z_du_, z_dw_;  // y contracted in w (n_u' x n_v)
};

// The whole grid params[0] x params[1] x params[2] as a block (points only).
StructuredBlock EvaluateGrid(const TensorSpline& spline,
                             const std::array<std::vector<double>, 3>& params);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_BSPLINE_EVALUATION_H_
