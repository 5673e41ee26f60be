// The knot refinement loop shared by single-block and multi-block tolerance fits (internal: its
// settings are built from GridFitOptions or ToleranceFitOptions by the fits that run it).
//
// Given a SegmentModel (which directions share knots) and a tolerance per data point:
//  1. Refine: fit every block (tensor least squares with the model's knots and pins); where some
//     point misses its tolerance, split the knot spans of every class whose members' own line
//     fits miss their share of the tolerance (refinement.h); when no class misses its share but
//     the tensor fit still does, shrink the shares. Repeat until every point is within tolerance.
//  2. Quality (optional): where cells fold or change size (grid_quality.h), halve the
//     tolerances at their vertices and refine again ("refine locally"). A round is kept only if
//     it improves the quality (fewer folded cells, then fewer bad cells); otherwise the best
//     state so far is restored and the rounds stop. More knots cure cells a coarse fit spoils,
//     but not the wiggles of a fit that already nearly interpolates a kink in the data, so the
//     guard is what keeps this step from making things worse.
//  2b. Repair (with a quality check): where cells still fold, bound the runs of knot spans
//     holding a single datum (a fit that nearly interpolates is nearly singular on them and
//     swings between its data; refinement.h SingleDatumRun), removing knots there and refining
//     again under that bound; kept only if every tolerance holds and the folds decrease.
//  3. Remove knots one at a time where the tolerances still hold and the quality is no worse.
//  3b. Repair what still folds (with a quality check), each kept only if every tolerance holds
//     and the folds decrease: (i) classes that reach a control per datum get averaged knots,
//     the well-posed interpolation; (ii) without a fairing of the caller's, a jump penalty of
//     weight 1e-12 .. 1e-6, which damps the swing the data leave free.
//  4. Fair (optional): a fixed weight for every fit, or, to tolerance, the largest weight that
//     keeps every tolerance and the quality no worse (a search over decades, then bisection on
//     a log scale). A fit that sits at its tolerance leaves fairing no room, so to fair to
//     tolerance, steps 1-3 place the knots for half the tolerances and the fairing may use the
//     other half; the unfaired fit with the same knots is returned too, to compare.
#ifndef SPLINEGRID_CORE_FIT_ADAPTIVE_ADAPTIVE_ENGINE_H_
#define SPLINEGRID_CORE_FIT_ADAPTIVE_ADAPTIVE_ENGINE_H_

#include <functional>
#include <vector>

#include "absl/status/statusor.h"
#include "core/fit/adaptive/segment_model.h"
#include "core/fit/fit_defaults.h"
#include "core/fit/report/grid_quality.h"
#include "core/fit/solve/fairing.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/util/cancellation.h"

namespace splinegrid::internal {

struct EngineOptions {
  // Refinement rounds before giving up.
  int max_iterations = kDefaultMaxRefinementRounds;
  // Try to drop every knot once the tolerances hold.
  bool remove_unneeded_knots = true;
  // The cell quality of block b's fit; unset: no quality check.
  std::function<absl::StatusOr<CellQuality>(int b, const FittedBlock& fitted)> quality;
  // Rounds of local tolerance tightening for quality before giving up.
  int max_quality_rounds = 10;
  FairingOptions fairing;
  CancelCheck cancel;
};

struct EngineResult {
  // summary.deviation: distances to the data; max_ratio/max_ratio_at are the largest ratio of
  // AssessErrors (point and edge tolerances).
  std::vector<FittedBlock> blocks;
  // Per block, when options.quality is set.
  std::vector<CellQuality> quality;
  bool met = false;         // every point within its tolerance
  bool quality_met = true;  // every block's cells acceptable (or no check)
  int worst_block = 0;      // where the largest deviation / tolerance is
  double worst_ratio = 0.0;
  Extents worst_at = {0, 0, 0};
  int iterations = 0;
  int knots_inserted = 0;
  int knots_removed = 0;
  int quality_rounds = 0;
  // Fold repairs kept (step 2b; the knots they removed are counted in knots_removed).
  int repair_rounds = 0;
  double fairing_weight = 0.0;  // lambda of the final fits
  // Fairing to tolerance: the same knots without fairing (else empty).
  std::vector<FittedBlock> unfaired;
};

// Runs the loop on `grid` with `model` (whose class knots it changes), per-block, per-point
// `tolerances` and relative `edge_tolerances` (AssessErrors in refinement.h; an empty vector
// for a block: no edge criterion), both of which quality rounds tighten. Errors: CANCELLED;
// fit errors of the kernel.
absl::StatusOr<EngineResult> RunAdaptiveFit(const MultiBlockGrid& grid, SegmentModel& model,
                                            std::vector<std::vector<double>>& tolerances,
                                            std::vector<std::vector<double>>& edge_tolerances,
                                            const EngineOptions& options);

}  // namespace splinegrid::internal

#endif  // SPLINEGRID_CORE_FIT_ADAPTIVE_ADAPTIVE_ENGINE_H_
