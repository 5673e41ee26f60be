#include "core/fit/adaptive/adaptive_fit.h"

#include <chrono>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/fit/adaptive/adaptive_engine.h"
#include "core/fit/adaptive/segment_model.h"
#include "core/util/status_macros.h"

namespace splinegrid {

absl::StatusOr<ToleranceFitResult> FitToTolerance(const StructuredBlock& block,
                                                  std::span<const double> tolerance,
                                                  const ToleranceFitOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (options.order < 2 || options.order > kMaxOrder) {
    return absl::InvalidArgumentError(
        absl::StrCat("order = ", options.order, " is outside [2, ", kMaxOrder, "]"));
  }
  SG_RETURN_IF_ERROR(ValidateParametrization(options.parametrization));
  SG_RETURN_IF_ERROR(options.features.Validate());
  SG_RETURN_IF_ERROR(ValidateControlCap(options.max_controls_per_direction, options.order));
  if (tolerance.size() != 1 && static_cast<int64_t>(tolerance.size()) != block.num_points()) {
    return absl::InvalidArgumentError(absl::StrCat("tolerance: ", tolerance.size(), " values for ",
                                                   block.num_points(),
                                                   " points; give one or one per point"));
  }
  for (size_t p = 0; p < tolerance.size(); ++p) {
    if (!(tolerance[p] > 0.0) || !std::isfinite(tolerance[p])) {
      return absl::InvalidArgumentError(
          absl::StrCat("tolerance", tolerance.size() == 1 ? "" : absl::StrCat("[", p, "]"), " = ",
                       tolerance[p], "; tolerances must be positive and finite"));
    }
  }
  SG_RETURN_IF_ERROR(ValidateFinite(block, "points"));

  const std::array<std::vector<double>, 3> params =
      ParametrizeBlock(block, options.parametrization);
  MultiBlockGrid grid;
  grid.blocks.push_back(block);
  std::vector<std::array<std::vector<int>, 3>> features(1);
  for (int d = 0; d < 3; ++d) features[0][d] = DetectFeatures(block, d, options.features);
  SG_ASSIGN_OR_RETURN(SegmentModel model,
                      SegmentModel::Build(grid, {params}, Connectivity(), features, options.order,
                                          options.max_controls_per_direction));
  std::vector<std::vector<double>> tolerances(1);
  tolerances[0].assign(tolerance.begin(), tolerance.end());
  if (tolerance.size() == 1) tolerances[0].assign(block.num_points(), tolerance[0]);
  internal::EngineOptions engine;
  engine.max_iterations = options.max_iterations;
  engine.remove_unneeded_knots = options.remove_unneeded_knots;
  engine.cancel = options.cancel;
  std::vector<std::vector<double>> no_edges(1);
  SG_ASSIGN_OR_RETURN(internal::EngineResult run,
                      internal::RunAdaptiveFit(grid, model, tolerances, no_edges, engine));

  ToleranceFitResult result;
  result.fitted = std::move(run.blocks[0]);
  result.met = run.met;
  result.worst_ratio = run.worst_ratio;
  result.worst_at = run.worst_at;
  result.iterations = run.iterations;
  result.knots_inserted = run.knots_inserted;
  result.knots_removed = run.knots_removed;
  for (int d = 0; d < 3; ++d) result.features[d] = model.splits(0, d);
  if (!result.met) {
    const Extents& at = run.worst_at;
    const Extents n = result.fitted.spline.control_extents();
    result.unmet_reason = absl::StrCat(
        "point (", at[0], ", ", at[1], ", ", at[2], ") deviates ", run.worst_ratio,
        " times its tolerance after ", run.iterations, " refinement rounds with ", n[0], " x ",
        n[1], " x ", n[2], " control points",
        options.max_controls_per_direction > 0
            ? absl::StrCat(" (cap ", options.max_controls_per_direction, " per direction)")
            : "");
  }
  result.fitted.summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace splinegrid
