// The report stage of FitGrid (grid_fit.h), internal: one report for both modes, filled into
// the GridFit the fit stage left (blocks fitted, connectivity and kinds set).
#ifndef SPLINEGRID_CORE_FIT_REPORT_FIT_REPORT_H_
#define SPLINEGRID_CORE_FIT_REPORT_FIT_REPORT_H_

#include <vector>

#include "absl/status/status.h"
#include "core/fit/grid_fit.h"

namespace splinegrid::internal {

// For every block of `fit`: its deviation by kind and its cell quality (`quality`: levels,
// thresholds, cancel), and with `tolerances` (the tolerance mode, in the grid's unit) its
// deviation re-measured against them (summary.deviation.max_ratio), whether they are met and,
// if not, why. Then the report's totals (points, controls, largest deviation), tolerance_met
// (true only when measured and met; without tolerances the reason says none was given),
// quality_met, the largest gap between matched boundaries at levels 0..quality.max_level, the
// wall curvature, and the unfaired fit's (`unfaired`, when not empty). Errors: CANCELLED.
absl::Status ReportFit(const MultiBlockGrid& grid, const CellQualityOptions& quality,
                       const BoundaryTolerances* tolerances,
                       const std::vector<FittedBlock>& unfaired, GridFit& fit);

}  // namespace splinegrid::internal

#endif  // SPLINEGRID_CORE_FIT_REPORT_FIT_REPORT_H_
