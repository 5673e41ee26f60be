// Fitting a whole multi-block grid: every block with the same options (control counts, with
// per-block overrides, or a tolerance).
#ifndef SPLINEGRID_CORE_FIT_GRID_FIT_H_
#define SPLINEGRID_CORE_FIT_GRID_FIT_H_

#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/fit/tensor_fit.h"
#include "core/grid/structured_grid.h"
#include "core/util/cancellation.h"

namespace splinegrid {

// What to fit; plain data, so a revision can keep it as provenance.
struct GridFitOptions {
  // Spline order (degree + 1).
  int order = 4;
  Parametrization parametrization = Parametrization::kChordLength;
  // With a tolerance: adaptive knots until every point is within it (in the grid's length
  // unit); without: control counts.
  std::optional<double> tolerance;
  // Control points per direction for every block; 0 = as many as points.
  Extents control_counts = {0, 0, 0};
  // Per-block overrides of control_counts: (block index, counts).
  std::vector<std::pair<int, Extents>> block_control_counts;
  // With a tolerance: the most control points per direction (0: the point count).
  int max_controls_per_direction = 0;

  // OK if the options suit `grid`; INVALID_ARGUMENT naming the field and value otherwise.
  absl::Status Validate(const MultiBlockGrid& grid) const;
};

// A block's fit and, for tolerance fits, whether the tolerance was met.
struct BlockFit {
  FittedBlock fitted;
  bool tolerance_met = true;
  std::string unmet_reason;
};

struct GridFit {
  std::vector<BlockFit> blocks;
  int64_t num_points = 0;
  int64_t num_control_points = 0;
  double max_deviation = 0.0;
  double seconds = 0.0;
};

// Fits every block of `grid`. Errors: INVALID_ARGUMENT (options, non-finite points; the message
// names the block), FAILED_PRECONDITION (data leave control points undetermined), CANCELLED.
absl::StatusOr<GridFit> FitGrid(const MultiBlockGrid& grid, const GridFitOptions& options,
                                const CancelCheck& cancel = {});

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_GRID_FIT_H_
