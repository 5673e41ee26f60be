#include "core/fit/grid_fit.h"

#include <chrono>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/fit/adaptive_fit.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

// The status with "block b: " in front of its message.
absl::Status InBlock(int b, const absl::Status& status) {
  return absl::Status(status.code(), absl::StrCat("block ", b, ": ", status.message()));
}

// The control-count fit options of block b: its override if it has one, else the grid-wide
// counts clamped to the block's points (so one request suits blocks of different sizes).
FitOptions BlockOptions(const GridFitOptions& options, const StructuredBlock& block, int b) {
  FitOptions fit_options;
  fit_options.order = options.order;
  fit_options.parametrization = options.parametrization;
  for (const auto& [index, counts] : options.block_control_counts) {
    if (index == b) {
      fit_options.control_counts = counts;
      return fit_options;
    }
  }
  for (int d = 0; d < 3; ++d) {
    fit_options.control_counts[d] =
        block.extent(d) == 1 ? 0 : std::min(options.control_counts[d], block.extent(d));
  }
  return fit_options;
}

}  // namespace

absl::Status GridFitOptions::Validate(const MultiBlockGrid& grid) const {
  if (grid.blocks.empty()) return absl::InvalidArgumentError("the grid has no blocks");
  if (order < 2 || order > kMaxOrder) {
    return absl::InvalidArgumentError(
        absl::StrCat("order = ", order, " is outside [2, ", kMaxOrder, "]"));
  }
  if (tolerance) {
    if (!(*tolerance > 0.0) || !std::isfinite(*tolerance)) {
      return absl::InvalidArgumentError(
          absl::StrCat("tolerance = ", *tolerance, "; must be positive and finite"));
    }
    if (max_controls_per_direction < 0) {
      return absl::InvalidArgumentError(absl::StrCat(
          "max_controls_per_direction = ", max_controls_per_direction, " is negative"));
    }
    if (!block_control_counts.empty()) {
      return absl::InvalidArgumentError("block_control_counts cannot be combined with a tolerance");
    }
    return absl::OkStatus();
  }
  const int num_blocks = static_cast<int>(grid.blocks.size());
  for (const auto& [block, counts] : block_control_counts) {
    if (block < 0 || block >= num_blocks) {
      return absl::InvalidArgumentError(absl::StrCat("block_control_counts: block ", block,
                                                     " is outside [0, ", num_blocks - 1, "]"));
    }
  }
  for (int d = 0; d < 3; ++d) {
    if (control_counts[d] < 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("control_counts[", d, "] = ", control_counts[d], " is negative"));
    }
  }
  for (int b = 0; b < num_blocks; ++b) {
    const FitOptions block_options = BlockOptions(*this, grid.blocks[b], b);
    if (absl::Status s = block_options.Validate(grid.blocks[b].extents()); !s.ok()) {
      return InBlock(b, s);
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<GridFit> FitGrid(const MultiBlockGrid& grid, const GridFitOptions& options,
                                const CancelCheck& cancel) {
  const auto start = std::chrono::steady_clock::now();
  SG_RETURN_IF_ERROR(options.Validate(grid));
  GridFit result;
  for (int b = 0; b < static_cast<int>(grid.blocks.size()); ++b) {
    const StructuredBlock& block = grid.blocks[b];
    BlockFit block_fit;
    if (options.tolerance) {
      ToleranceFitOptions tol_options;
      tol_options.order = options.order;
      tol_options.parametrization = options.parametrization;
      tol_options.max_controls_per_direction = options.max_controls_per_direction;
      tol_options.cancel = cancel;
      const double tolerance[] = {*options.tolerance};
      absl::StatusOr<ToleranceFitResult> fit = FitToTolerance(block, tolerance, tol_options);
      if (!fit.ok()) return InBlock(b, fit.status());
      block_fit.fitted = std::move(fit->fitted);
      block_fit.tolerance_met = fit->met;
      block_fit.unmet_reason = std::move(fit->unmet_reason);
    } else {
      FitOptions fit_options = BlockOptions(options, block, b);
      fit_options.cancel = cancel;
      absl::StatusOr<FittedBlock> fit = FitBlock(block, fit_options);
      if (!fit.ok()) return InBlock(b, fit.status());
      block_fit.fitted = *std::move(fit);
    }
    result.num_points += block_fit.fitted.summary.num_points;
    result.num_control_points += block_fit.fitted.summary.num_control_points;
    result.max_deviation = std::max(result.max_deviation, block_fit.fitted.summary.deviation.max);
    result.blocks.push_back(std::move(block_fit));
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace splinegrid
