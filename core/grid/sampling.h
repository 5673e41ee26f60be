// Where to evaluate a fitted block: resolution by refinement level or by point counts, over the
// whole block or an index sub-box, following the block's point distribution or another
// distribution per direction.
#ifndef SPLINEGRID_CORE_GRID_SAMPLING_H_
#define SPLINEGRID_CORE_GRID_SAMPLING_H_

#include <array>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "core/grid/point_distribution.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

// An index box in original grid indices, inclusive at both ends.
struct IndexBox {
  Extents begin = {0, 0, 0};
  Extents end = {0, 0, 0};
};

// How the points of one direction are spread between the box's first and last index. The count
// comes from the resolution; the ends are always the original end points.
struct Distribution {
  enum class Kind {
    kOriginal,          // the original clustering (point_distribution.h)
    kUniformParameter,  // evenly spaced in the spline parameter
    // Measured along every grid line of the spline (block_sampling.h):
    kUniformArcLength,  // evenly spaced in arc length
    kGeometric,         // first interval of arc length first_spacing, the next ones growing
                        // (or shrinking) by a constant ratio to the line's end
  };
  Kind kind = Kind::kOriginal;
  double first_spacing = 0.0;  // kGeometric: in the grid's length unit, > 0
  bool from_end = false;       // kGeometric: the first interval at the last index instead

  friend bool operator==(const Distribution&, const Distribution&) = default;
};

// Arc length and geometric distributions place every grid line's points on that line.
inline bool IsMeasured(Distribution::Kind kind) {
  return kind == Distribution::Kind::kUniformArcLength || kind == Distribution::Kind::kGeometric;
}

struct Resolution {
  enum class Kind {
    kLevel,   // 2^level - 1 new points in every original interval; level 0 = original points
    kCounts,  // counts[d] points per direction, evenly spaced in index space
  };
  Kind kind = Kind::kLevel;
  int level = 0;
  Extents counts = {1, 1, 1};
  std::optional<IndexBox> box;  // absent: the whole block
  // Per direction i, j, k. At most one direction may be measured (IsMeasured): the others
  // stay one parameter per index, so every measured line is an iso-parameter line.
  std::array<Distribution, 3> distributions;
};

// The direction of `resolution` with a measured distribution, or -1 (SampleExtents refuses
// more than one).
int MeasuredDirection(const Resolution& resolution);

// Highest refinement level accepted (2^20 points per original interval is already absurd).
inline constexpr int kMaxRefinementLevel = 20;

// The point counts that `resolution` gives on a block with `distribution`, without building
// the parameters (for size checks). Errors, naming the field and value: INVALID_ARGUMENT for a
// negative level, counts below 1, a box outside the block or with end < begin, counts above 1
// in a direction with one original point; OUT_OF_RANGE for a level above kMaxRefinementLevel,
// more than 2^30 points in a direction or 2^40 in all; INVALID_ARGUMENT for a distribution that
// cannot be followed (two measured directions, a geometric one with fewer than 3 points or a first
// spacing that is not positive and finite, a first_spacing or from_end on another kind).
absl::StatusOr<Extents> SampleExtents(const PointDistribution& distribution,
                                      const Resolution& resolution);

// The parameters per direction for `resolution` (see SampleExtents for the errors). A measured
// distribution needs the spline: INVALID_ARGUMENT here, use BlockSampling.
absl::StatusOr<std::array<std::vector<double>, 3>> SampleParameters(
    const PointDistribution& distribution, const Resolution& resolution);

// `count` parameters evenly spaced from `begin` to `end`, both ends exact (count >= 1; a single
// one is `begin`).
std::vector<double> UniformParameters(double begin, double end, int count);

// The ratio r of a geometric sequence of `intervals` (>= 1) steps starting at `first` (> 0) that
// add up to `total` (> first): first (r^intervals - 1) / (r - 1) = total, by bisection (the sum
// increases with r). Exactly 1 when total is intervals x first to 1e-12; below 1 when total is
// less. Wall spacings (geometric distributions) and layer growth (the grid generators) use it.
double GeometricRatio(double first, double total, int intervals);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GRID_SAMPLING_H_
