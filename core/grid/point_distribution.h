// The point distribution of a fitted block: per direction, the data parameters of its grid
// lines, i.e. a strictly increasing map from grid index to spline parameter.
//
// Evaluating a spline at these parameters reproduces the original grid's points (up to the fit
// deviation) and its clustering. Between grid indices the map is continued by monotone cubic
// Hermite interpolation (Fritsch & Carlson, SIAM J. Numer. Anal. 17, 1980; PCHIP slopes inside,
// geometric continuation at the ends), so refined and resampled grids follow the original
// clustering and stretching smoothly and never fold back.
//
// A direction may have breaks: grid indices where the map is split into pieces interpolated
// independently (one-sided slopes at the break). Blocks that share a boundary segment between
// breaks then refine it identically, whatever lies beyond the breaks (segment_model.h).
#ifndef SPLINEGRID_CORE_GRID_POINT_DISTRIBUTION_H_
#define SPLINEGRID_CORE_GRID_POINT_DISTRIBUTION_H_

#include <array>
#include <vector>

#include "absl/status/statusor.h"

namespace splinegrid {

class PointDistribution {
 public:
  // One point per direction at parameter 0.
  PointDistribution();

  // Validates: every direction has at least one parameter; with more than one they are finite,
  // strictly increasing, start at 0 and end at 1; a single parameter must lie in [0, 1]. Breaks
  // (per direction, optional) must be strictly increasing interior indices.
  static absl::StatusOr<PointDistribution> Create(std::array<std::vector<double>, 3> params,
                                                  std::array<std::vector<int>, 3> breaks = {});

  // Original parameters of direction d (one per grid index).
  const std::vector<double>& params(int d) const { return params_[d]; }
  // Interior grid indices where the interpolation of direction d is split.
  const std::vector<int>& breaks(int d) const { return breaks_[d]; }
  int num_points(int d) const { return static_cast<int>(params_[d].size()); }

  // The parameter at fractional grid index s in [0, m - 1] of direction d (clamped); exact at
  // integer s.
  double ParameterAt(int d, double s) const;

  // Refinement level `level` of the index range [begin, end] of direction d: every interval
  // gets 2^level - 1 new samples, (end - begin) 2^level + 1 parameters in all.
  // Precondition: 0 <= begin <= end < m, 0 <= level <= 20.
  std::vector<double> Refined(int d, int begin, int end, int level) const;

  // `count` parameters evenly spaced in grid-index space over [begin, end] (count >= 1; a single
  // sample sits at begin).
  std::vector<double> Resampled(int d, double begin, double end, int count) const;

 private:
  PointDistribution(std::array<std::vector<double>, 3> params,
                    std::array<std::vector<int>, 3> breaks);

  std::array<std::vector<double>, 3> params_;
  std::array<std::vector<int>, 3> breaks_;
  // d parameter / d index at every grid index, for the interval to its right (slopes_) and to
  // its left (left_slopes_); they differ only at breaks.
  std::array<std::vector<double>, 3> slopes_;
  std::array<std::vector<double>, 3> left_slopes_;
};

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GRID_POINT_DISTRIBUTION_H_
