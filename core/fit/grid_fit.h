// Fitting a whole multi-block grid, with a report: what the service's FitGrid runs.
//
// Two modes:
//  - control counts (per direction, with per-block overrides): a least-squares fit of every
//    block on its own (tensor_fit.h), only C0 at the kinks of its boundary lines (features),
//    optionally faired with a fixed weight;
//  - tolerances: a watertight multi-block fit to tolerances by boundary kind (multiblock_fit.h),
//    from one tolerance for every point or from per-kind tolerances, optionally faired.
// Either way the result reports, per block, the deviation per boundary kind and the cell
// quality at refinement levels 0..2 (grid_quality.h), and for the grid the connectivity, the
// gaps between matched boundaries and the curvature along the walls (wall_curvature.h).
#ifndef SPLINEGRID_CORE_FIT_GRID_FIT_H_
#define SPLINEGRID_CORE_FIT_GRID_FIT_H_

#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/fit/adaptive/refinement.h"
#include "core/fit/fit_defaults.h"
#include "core/fit/report/fit_deviation.h"
#include "core/fit/report/grid_quality.h"
#include "core/fit/report/wall_curvature.h"
#include "core/fit/solve/fairing.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/grid/boundary_kinds.h"
#include "core/grid/connectivity.h"
#include "core/grid/fittable_grid.h"
#include "core/grid/reference_length.h"
#include "core/grid/structured_grid.h"
#include "core/util/cancellation.h"

namespace splinegrid {

// Which grid lines give a direction its parameters (tolerance mode). A tensor-product spline has
// one parameter per grid index of a direction, shared by all its lines; a wall fitted at
// parameters averaged over all lines wriggles between its points, because its own spacing
// differs from the average (on the NACA 0012 225 x 65 C-grid even an interpolating fit has 47
// curvature extrema along the wall, where the wall's points have 5). Taking the parameters from
// the wall lines alone gives smooth walls (RAE 2822: 10 extrema instead of 28, the squared
// curvature differences 20x smaller), but on some grids the other lines then need many more
// knots and cells suffer.
enum class WallParametrization {
  kAverage,  // every line of the direction
  kWall,     // the lines holding at least three wall points, where the direction has any
  kAuto,     // both; keep the better fit: tolerances met, fewer bad cells, smoother walls
};

// What to fit: the one options struct of FitGrid, every default stated here (the shared ones in
// fit_defaults.h); the stages' own settings are built from it once, inside the fit. Plain data,
// so a revision can keep it as provenance (the service stores the fields a request can set; the
// tuning fields below `allow_folds` keep their defaults there).
struct GridFitOptions {
  // Spline order (degree + 1).
  int order = kDefaultOrder;
  Parametrization parametrization = kDefaultParametrization;
  // Tolerance mode: one tolerance for every point (in the grid's length unit, absolute), or
  // tolerances by boundary kind. At most one of the two; with neither, control counts.
  std::optional<double> tolerance;
  // By kind, each field is a fraction of the reference length for the kinds in relative_kinds,
  // else a length in the grid's unit. The defaults (BoundaryTolerances() with every kind
  // relative) are the QUADFLOW paper's tolerances in chords: 0.15e-3, 2e-3 and 8e-3 of the
  // reference length on walls, interfaces and outer boundaries, none inside; so a grid in
  // chords, millimetres or inches is fitted alike.
  std::optional<BoundaryTolerances> boundary_tolerances;
  // Bits (reference_length.h: kRelativeWall, ..., kRelativeInterior): the fields of
  // boundary_tolerances that are fractions of the reference length. ParseFitSpec marks the kinds
  // a request leaves unset (defaults) and clears the kinds it states (absolute).
  uint8_t relative_kinds = kAllKindsRelative;
  // The reference length of relative tolerances, in the grid's unit (positive, finite); unset:
  // detected from the walls (DetectReferenceLength). Only with boundary_tolerances.
  std::optional<double> reference_length;
  // Control points per direction for every block; 0 = as many as points.
  Extents control_counts = {0, 0, 0};
  // Per-block overrides of control_counts: (block index, counts), at most one per block. Counts
  // must suit every block they apply to (ValidateControlCounts); nothing is clamped.
  std::vector<std::pair<int, Extents>> block_control_counts;
  // Tolerance mode: the most control points per direction (0: the point count); at least the
  // order when given (a direction of fewer points than that is capped by its points).
  int max_controls_per_direction = 0;
  // kWeight in either mode; kToTolerance needs the tolerance mode.
  FairingOptions fairing;
  // Explicit kinds of faces (else from the connectivity and the geometry).
  std::vector<FaceKindOverride> face_kinds;
  // Tolerance mode: refine locally where cells fold or change size (the quality is reported in
  // either mode).
  bool check_quality = true;
  // Accept folds: a fit whose cells still fold at levels 0..2 after the repair (tolerance mode)
  // is returned with quality_met = false instead of failing with FAILED_PRECONDITION.
  bool allow_folds = false;

  // Tuning of the tolerance mode (adaptive_engine.h describes the steps):
  WallParametrization wall_parameters = WallParametrization::kAuto;
  // Share knots and boundary controls across matches (watertight). False fits every block on its
  // own (boundaries are still classified by the connectivity).
  bool watertight = true;
  // Kink detection, either mode: feature points where every line of a direction becomes C0
  // (refinement.h).
  FeatureOptions features;
  // Knot refinement rounds before giving up.
  int max_iterations = kDefaultMaxRefinementRounds;
  // Try to drop every knot once the tolerances hold.
  bool remove_unneeded_knots = true;
  // Either mode: the cell check and its report (levels 0..quality.max_level, the accepted size
  // change); its cancel is FitGrid's.
  CellQualityOptions quality;
  // FitGrid without a known connectivity: how it is found (connectivity.h).
  ConnectivityOptions connectivity;

  bool tolerance_mode() const { return tolerance.has_value() || boundary_tolerances.has_value(); }
  // The per-kind tolerances of the tolerance mode in the grid's unit (one tolerance: every kind,
  // inside too), the relative kinds scaled by `reference_length`.
  BoundaryTolerances Tolerances(double reference_length) const;

  // OK if the options suit `grid`; INVALID_ARGUMENT naming the field and value otherwise
  // (FitGrid checks this first; the stages do not check again).
  absl::Status Validate(const MultiBlockGrid& grid) const;
};

// A block's fit and what the report says about it.
struct BlockFit {
  FittedBlock fitted;
  bool tolerance_met = false;  // tolerance mode: every point within its tolerance (measured)
  std::string unmet_reason;
  KindDeviation deviation_by_kind;
  CellQuality quality;  // levels 0..2
};

// What a fit achieved, for the whole grid.
struct GridFitReport {
  int64_t num_points = 0;
  int64_t num_control_points = 0;
  double max_deviation = 0.0;
  // True only when measured: tolerance mode, every block's points within their tolerances.
  // A fit to control counts has no tolerance: false, and unmet_reason says so.
  bool tolerance_met = false;
  std::string unmet_reason;  // the first block's reason
  // True only when measured: no folded or resized cell in any block, and no block with cells
  // whose every cell was skipped as collapsed (CellQuality::measured()).
  bool quality_met = false;
  int num_matches = 0;  // of the connectivity
  // Largest distance between coinciding points of matched boundaries at levels
  // 0..quality.max_level (0 up to rounding when watertight: the tolerance mode by default).
  double max_gap = 0.0;
  double fairing_weight = 0.0;
  CurvatureMetrics wall_curvature;           // at refinement level 2
  CurvatureMetrics unfaired_wall_curvature;  // faired to tolerance: the same knots unfaired
  // Tolerance mode, filled by the adaptive engine (adaptive_engine.h): refinement rounds, knots
  // inserted and removed, quality rounds.
  int iterations = 0;
  int knots_inserted = 0;
  int knots_removed = 0;
  int quality_rounds = 0;
  double seconds = 0.0;
  // The reference length (reference_length.h): given, or detected from the walls, in every
  // mode (the default tolerances by kind are fractions of it).
  ReferenceLength reference;
  // Tolerance mode: the tolerance of each kind the fit was held to, in the grid's unit.
  std::optional<BoundaryTolerances> tolerances;
  // Where the fit differs from the options, one sentence each: a direction with more than one
  // but fewer points than the order is fitted through its points at a lower order (the only
  // fit there is). Empty: as asked.
  std::vector<std::string> adjustments;
};

struct GridFit {
  std::vector<BlockFit> blocks;
  Connectivity connectivity;
  BoundaryKinds kinds;
  GridFitReport report;
};

// Fits every block of `grid`, as asked: no count, order or tolerance is changed silently (the
// one exception, forced by the data, is a direction with fewer points than the order: it
// interpolates them at a lower order, see FitOptions::order). Errors: INVALID_ARGUMENT
// (options, naming the field, value, block and limit), FAILED_PRECONDITION (a block that cannot
// be fitted: non-finite points, all points equal, a direction of zero length, cells of zero
// measure, see ValidateFittable; data that leave control points undetermined; blocks that touch
// inconsistently), CANCELLED.
absl::StatusOr<GridFit> FitGrid(const MultiBlockGrid& grid, const GridFitOptions& options,
                                const CancelCheck& cancel = {});

// The same for a grid checked once beforehand (FittableGrid::Check): the blocks are not checked
// again and the grid's connectivity is used (options.connectivity is not).
absl::StatusOr<GridFit> FitGrid(const FittableGrid& grid, const GridFitOptions& options,
                                const CancelCheck& cancel = {});

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_GRID_FIT_H_
