#include "core/fit/report/fit_report.h"

#include <algorithm>
#include <array>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/fit/report/fit_deviation.h"
#include "core/fit/report/wall_curvature.h"
#include "core/grid/poles.h"
#include "core/util/status_macros.h"

namespace splinegrid::internal {
namespace {

// Refinement level of the wall curvature samples: three samples between grid points.
constexpr int kCurvatureLevel = 2;

std::string KindNames(uint8_t mask) {
  if (mask == 0) return "interior";
  std::string names;
  for (BoundaryKind k : {BoundaryKind::kWall, BoundaryKind::kInterface, BoundaryKind::kOuter}) {
    if (mask & static_cast<uint8_t>(k)) {
      absl::StrAppend(&names, names.empty() ? "" : "/", std::string(BoundaryKindName(k)));
    }
  }
  return names;
}

// Block b's deviation re-measured against `tolerances` (into its summary, with the point and
// control counts), and whether every point is within its tolerance.
absl::Status MeasureAgainstTolerances(const MultiBlockGrid& grid,
                                      const BoundaryTolerances& tolerances,
                                      const BoundaryKinds& kinds, const CancelCheck& cancel, int b,
                                      BlockFit& block) {
  FittedBlock& fitted = block.fitted;
  const std::vector<double> tol = PointTolerances(kinds, b, tolerances);
  std::array<std::vector<double>, 3> p;
  for (int d = 0; d < 3; ++d) p[d] = fitted.distribution.params(d);
  SG_ASSIGN_OR_RETURN(fitted.summary.deviation,
                      MeasureDeviation(fitted.spline, p, grid.blocks[b], cancel, tol));
  const Deviation& dev = fitted.summary.deviation;
  block.tolerance_met = dev.max_ratio <= 1.0;
  block.unmet_reason.clear();
  if (!block.tolerance_met) {
    const Extents& at = dev.max_ratio_at;
    const uint8_t kind = kinds.point_kinds[b][grid.blocks[b].Index(at[0], at[1], at[2])];
    block.unmet_reason = absl::StrCat("block ", b, " ", KindNames(kind), " point (", at[0], ", ",
                                      at[1], ", ", at[2], ") deviates ", dev.max_ratio,
                                      " times its tolerance of ", tolerances.For(kind));
  }
  fitted.summary.num_points = grid.blocks[b].num_points();
  fitted.summary.num_control_points = fitted.spline.num_control_points();
  fitted.summary.compression_ratio =
      static_cast<double>(fitted.summary.num_points) / fitted.summary.num_control_points;
  return absl::OkStatus();
}

}  // namespace

absl::Status ReportFit(const MultiBlockGrid& grid, const CellQualityOptions& quality,
                       const BoundaryTolerances* tolerances,
                       const std::vector<FittedBlock>& unfaired, GridFit& fit) {
  GridFitReport& report = fit.report;
  report.num_points = report.num_control_points = 0;
  report.max_deviation = 0.0;
  report.tolerance_met = tolerances != nullptr;
  report.unmet_reason =
      tolerances ? ""
                 : "no tolerance was given (a fit to control counts, or interpolating): see "
                   "max_deviation";
  report.quality_met = true;
  std::vector<FittedBlock> fitted;
  // The points on poles, whose first-layer edges no fit holds (fit_deviation.h).
  const double pole_tolerance = PoleTolerance(grid);
  const std::vector<std::vector<uint8_t>> on_pole =
      PointsOnPoles(grid, FindPoles(grid, pole_tolerance));
  for (int b = 0; b < static_cast<int>(fit.blocks.size()); ++b) {
    BlockFit& block = fit.blocks[b];
    SG_ASSIGN_OR_RETURN(block.deviation_by_kind,
                        DeviationByKind(block.fitted, grid.blocks[b], fit.kinds.point_kinds[b],
                                        on_pole[b], pole_tolerance));
    if (tolerances) {
      SG_RETURN_IF_ERROR(
          MeasureAgainstTolerances(grid, *tolerances, fit.kinds, quality.cancel, b, block));
      // A held first layer is a tolerance too (a cap on the controls can leave it unmet).
      const double first_layer = block.deviation_by_kind.first_layer;
      if (block.tolerance_met && tolerances->first_layer > 0.0 &&
          first_layer > tolerances->first_layer) {
        block.tolerance_met = false;
        const Extents& at = block.deviation_by_kind.first_layer_at;
        block.unmet_reason = absl::StrCat("block ", b, " first-layer height at wall point (", at[0],
                                          ", ", at[1], ", ", at[2], ") changed by ", first_layer,
                                          ", more than first_layer = ", tolerances->first_layer);
      }
      if (!block.tolerance_met && report.tolerance_met) {
        report.tolerance_met = false;
        report.unmet_reason = block.unmet_reason;
      }
    }
    SG_ASSIGN_OR_RETURN(block.quality, CheckCellQuality(block.fitted, grid.blocks[b], quality),
                        "block ", b, ": ");
    report.quality_met = report.quality_met && block.quality.ok() && block.quality.measured();
    report.num_points += block.fitted.summary.num_points;
    report.num_control_points += block.fitted.summary.num_control_points;
    report.max_deviation = std::max(report.max_deviation, block.fitted.summary.deviation.max);
    fitted.push_back(block.fitted);
  }
  report.max_gap = MaxBoundaryGap(fit.connectivity, fitted, quality.max_level);
  report.wall_curvature = WallCurvatureMetrics(fitted, fit.kinds, kCurvatureLevel);
  report.unfaired_wall_curvature = unfaired.empty()
                                       ? CurvatureMetrics{}
                                       : WallCurvatureMetrics(unfaired, fit.kinds, kCurvatureLevel);
  return absl::OkStatus();
}

}  // namespace splinegrid::internal
