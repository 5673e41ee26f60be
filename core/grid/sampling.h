// Where to evaluate a fitted block: resolution by refinement level or by point counts, over the
// whole block or an index sub-box, following the block's point distribution.
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

struct Resolution {
  enum class Kind {
    kLevel,   // 2^level - 1 new points in every original interval; level 0 = original points
    kCounts,  // counts[d] points per direction, evenly spaced in index space
  };
  Kind kind = Kind::kLevel;
  int level = 0;
  Extents counts = {1, 1, 1};
  std::optional<IndexBox> box;  // absent: the whole block
};

// Highest refinement level accepted (2^20 points per original interval is already absurd).
inline constexpr int kMaxRefinementLevel = 20;

// The point counts that `resolution` gives on a block with `distribution`, without building
// the parameters (for size checks). Errors, naming the field and value: INVALID_ARGUMENT for a
// negative level, counts below 1, a box outside the block or with end < begin, counts above 1
// in a direction with one original point; OUT_OF_RANGE for a level above kMaxRefinementLevel or
// more than 2^30 points in a direction.
absl::StatusOr<Extents> SampleExtents(const PointDistribution& distribution,
                                      const Resolution& resolution);

// The parameters per direction for `resolution` (see SampleExtents for the errors).
absl::StatusOr<std::array<std::vector<double>, 3>> SampleParameters(
    const PointDistribution& distribution, const Resolution& resolution);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GRID_SAMPLING_H_
