// Where a fitted block is evaluated for a Resolution: a tensor grid of parameters, one vector
// per direction, except that a direction with a measured distribution (uniform arc length or
// geometric, sampling.h) gets its own parameters on every grid line, placed by that line's arc
// length (line_arc_length.h). The other directions keep one parameter per index, so each
// measured line is an iso-parameter line of the spline and its distribution is exact on it.
#ifndef SPLINEGRID_CORE_BSPLINE_BLOCK_SAMPLING_H_
#define SPLINEGRID_CORE_BSPLINE_BLOCK_SAMPLING_H_

#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/bspline/evaluation.h"
#include "core/bspline/tensor_spline.h"
#include "core/grid/point_distribution.h"
#include "core/grid/sampling.h"
#include "core/util/cancellation.h"

namespace splinegrid {

class BlockSampling {
 public:
  // The parameters of `resolution` on the block (`spline`, `distribution`). Errors: those of
  // SampleExtents, and INVALID_ARGUMENT when a geometric first spacing is not below the length
  // of a grid line (naming the line), or a distribution's spacings fall below what double
  // precision separates on a line. A line of negligible length (under 1e-12 of the largest
  // control coordinate: a collapsed edge) gets evenly spaced parameters: all its points
  // coincide whatever the distribution. A measured direction costs
  // about 0.1-0.2 us per point; `cancel` is polled once per grid line (CANCELLED).
  static absl::StatusOr<BlockSampling> Create(const TensorSpline& spline,
                                              const PointDistribution& distribution,
                                              const Resolution& resolution,
                                              const CancelCheck& cancel = {});

  // Bytes Create holds for a resolution with these output extents.
  static int64_t Bytes(const Resolution& resolution, const Extents& extents);

  // Output points per direction.
  const Extents& extents() const { return extents_; }
  // The direction whose parameters differ per grid line, or -1 (a tensor grid).
  int measured_direction() const { return measured_; }
  // Per direction, one parameter per output index; empty for the measured direction.
  const std::array<std::vector<double>, 3>& params() const { return params_; }
  // (u, v, w) of output point (a, b, c).
  Point3 ParametersAt(int a, int b, int c) const;

 private:
  Extents extents_ = {1, 1, 1};
  int measured_ = -1;
  std::array<std::vector<double>, 3> params_;
  // The measured direction d: line_params_[line * extents_[d] + index], lines numbered by the
  // other two output indices, the lower direction fastest.
  std::vector<double> line_params_;
};

// Output points [first, first + count) of `sampling` (i fastest), spatial_dim values each, to
// `points`, and with du (then dv and dw too) the first derivatives in the same layout. Cost
// O(k^dim) per point: the points are evaluated one by one, so a tensor sampling is faster with
// GridEvaluator.
void EvaluateSampledPoints(const TensorSpline& spline, const BlockSampling& sampling, int64_t first,
                           int64_t count, double* points, double* du = nullptr,
                           double* dv = nullptr, double* dw = nullptr);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_BSPLINE_BLOCK_SAMPLING_H_
