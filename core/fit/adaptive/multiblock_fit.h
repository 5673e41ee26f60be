// Watertight fit of a multi-block grid to tolerances by boundary kind, with valid cells.
//
//  1. Connectivity: which face ranges of the blocks coincide (connectivity.h).
//  2. Boundary kinds and per-point tolerances: wall, interface, outer, interior
//     (boundary_kinds.h; defaults are the QUADFLOW paper's 0.15e-3, 2e-3, 8e-3 in the grid's
//     unit, and 8e-3 inside).
//  3. A SegmentModel: matched segments share parameters and knots (segment_model.h).
//  4. Knot refinement until every point is within its tolerance; then every block is evaluated
//     at the original resolution and at refinement levels 1 and 2, and where a cell folds or
//     changes its size by more than `quality.max_size_ratio`, the tolerance around it is halved
//     and refinement resumes ("refine locally"); then unnecessary knots are removed
//     (adaptive_engine.h).
//  5. Watertightness: the boundary control points of every matched face range are made
//     bitwise identical in all blocks that share them (they are the same fit up to rounding).
//     Poles (edges collapsed to a point, faces collapsed to a line or point: poles.h) are no
//     match and no segment boundary; every line of controls along a pole's collapsed direction
//     is given one value (the constrained least-squares fit: multiblock_fit.cc), shared by all
//     blocks that meet there, so the pole stays exactly collapsed at every resolution.
#ifndef SPLINEGRID_CORE_FIT_ADAPTIVE_MULTIBLOCK_FIT_H_
#define SPLINEGRID_CORE_FIT_ADAPTIVE_MULTIBLOCK_FIT_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/fit/adaptive/refinement.h"
#include "core/fit/report/grid_quality.h"
#include "core/fit/report/wall_curvature.h"
#include "core/fit/solve/fairing.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/grid/boundary_kinds.h"
#include "core/grid/connectivity.h"
#include "core/grid/poles.h"

namespace splinegrid {

// Which grid lines give a direction its parameters. A tensor-product spline has one parameter
// per grid index of a direction, shared by all its lines; a wall fitted at parameters averaged
// over all lines wriggles between its points, because its own spacing differs from the average
// (on the NACA 0012 225 x 65 C-grid even an interpolating fit has 37 curvature extrema along the
// wall, where the wall's points have 5). Taking the parameters from the wall lines alone gives
// smooth walls (RAE 2822: 10 extrema instead of 28, the squared curvature differences 20x
// smaller), but on some grids the other lines then need many more knots and cells suffer.
enum class WallParametrization {
  kAverage,  // every line of the direction
  kWall,     // the lines holding at least three wall points, where the direction has any
  kAuto,     // both; keep the better fit: tolerances met, fewer bad cells, smoother walls
};

struct MultiBlockFitOptions {
  int order = 4;
  Parametrization parametrization = Parametrization::kChordLength;
  WallParametrization wall_parameters = WallParametrization::kAuto;
  BoundaryTolerances tolerances;
  // Explicit kinds of faces (else from the connectivity and the geometry).
  std::vector<FaceKindOverride> face_kinds;
  ConnectivityOptions connectivity;
  // Share knots and boundary controls across matches (watertight). False fits every block on
  // its own (boundaries are still classified by the connectivity).
  bool watertight = true;
  FeatureOptions features;
  // Most control points per direction; 0 means the point count.
  int max_controls_per_direction = 0;
  int max_iterations = 60;
  bool remove_unneeded_knots = true;
  // Refine locally where cells fold or change size at levels 0..quality.max_level; false: the
  // quality is only reported.
  bool check_quality = true;
  CellQualityOptions quality;
  // Fairing of the final fit (fairing.h): off, a fixed weight, or the largest weight that keeps
  // every tolerance and the cell quality.
  FairingOptions fairing;
  CancelCheck cancel;

  // INVALID_ARGUMENT naming the field and value.
  absl::Status Validate() const;
};

// Largest deviation per boundary kind (negative: the block has no point of that kind).
struct KindDeviation {
  double wall = -1.0;
  double interface = -1.0;
  double outer = -1.0;
  double interior = -1.0;
};

struct BlockFitReport {
  KindDeviation max_deviation;
  CellQuality quality;        // at levels 0..max_level
  bool tolerance_met = true;  // every point within its tolerance
  std::string unmet_reason;   // why not, naming the point and its kind
};

struct MultiBlockFit {
  std::vector<FittedBlock> blocks;
  std::vector<BlockFitReport> reports;
  Connectivity connectivity;
  // Block boundaries collapsed to a point or a line (poles.h); every line of controls along a
  // pole's collapsed direction holds one control point, bitwise, in every block.
  std::vector<Pole> poles;
  BoundaryKinds kinds;
  bool met = false;          // every point of every block within its tolerance
  bool quality_met = true;   // no folded or resized cell (when checked)
  std::string unmet_reason;  // the first block's reason when !met
  // Largest distance between coinciding boundary points of matched ranges, evaluated at the
  // original resolution and refinement levels 1 and 2 (0 up to rounding when watertight).
  double max_gap = 0.0;
  int iterations = 0;
  int knots_inserted = 0;
  int knots_removed = 0;
  int quality_rounds = 0;
  double fairing_weight = 0.0;  // lambda of the final fit (0: not faired)
  // Faired to tolerance: the same knots without fairing, to compare (else empty).
  std::vector<FittedBlock> unfaired;
  // Curvature along the walls at refinement level 2 (wall_curvature.h): of the result, and of
  // `unfaired` (zero when empty).
  CurvatureMetrics wall_curvature;
  CurvatureMetrics unfaired_wall_curvature;
  int64_t num_points = 0;
  int64_t num_control_points = 0;
  double seconds = 0.0;
};

// Largest distance of `fitted` from `block` at the data parameters, per kind of point (`kinds`:
// the block's BoundaryKinds::point_kinds).
absl::StatusOr<KindDeviation> DeviationByKind(const FittedBlock& fitted,
                                              const StructuredBlock& block,
                                              const std::vector<uint8_t>& kinds);

// Largest distance between the coinciding points of every match of `connectivity` in `blocks`,
// evaluated at refinement levels 0..max_level (hanging nodes: at the coarse side's points).
double MaxBoundaryGap(const Connectivity& connectivity, const std::vector<FittedBlock>& blocks,
                      int max_level);

// Fits `grid`. Not meeting a tolerance is reported, not an error. Errors: INVALID_ARGUMENT for
// bad options or data (naming the field, block and point), FAILED_PRECONDITION for blocks that
// touch inconsistently (naming the match), CANCELLED.
absl::StatusOr<MultiBlockFit> FitMultiBlock(const MultiBlockGrid& grid,
                                            const MultiBlockFitOptions& options);

// The same for a grid whose connectivity is known: `connectivity` is what
// FindConnectivity(grid, options.connectivity) gives (the service finds it once, at import),
// and options.connectivity is not used.
absl::StatusOr<MultiBlockFit> FitMultiBlock(const MultiBlockGrid& grid,
                                            const Connectivity& connectivity,
                                            const MultiBlockFitOptions& options);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_ADAPTIVE_MULTIBLOCK_FIT_H_
