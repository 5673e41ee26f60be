// EvaluatePoints' operation: a revision's mapping (and its first derivatives) at a batch of
// (block, u, v, w) parameter points.
#ifndef SPLINEGRID_SERVER_OPS_EVALUATE_POINTS_H_
#define SPLINEGRID_SERVER_OPS_EVALUATE_POINTS_H_

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/ops/ops_context.h"

namespace splinegrid::server::ops {

struct PointsRequest {
  std::string grid_id;
  int64_t revision = 0;         // 0: the latest
  std::optional<int64_t> step;  // instead: the revision deformed at this solver step
  // One block for every point, or one per point.
  std::span<const int32_t> blocks;
  // u, v, w per point, each in [0, 1].
  std::span<const double> parameters;
  bool derivatives = false;  // also d/du, d/dv, d/dw
  // The most points per call, and the largest answer the caller can send (9 bytes per value,
  // as a packed double costs on the wire).
  int64_t max_points = 0;
  int64_t max_bytes = 0;
};

struct EvaluatedPoints {
  int64_t revision = 0;
  int spatial_dim = 0;
  // spatial_dim values per point, in request order; the derivatives only when asked for.
  std::vector<double> points, du, dv, dw;
};

// Evaluates the points. Errors: NOT_FOUND (grid, revision, step), INVALID_ARGUMENT naming the
// field and value (parameters not in triples or outside [0, 1], a block count or index that does
// not fit), OUT_OF_RANGE for more points than max_points or an answer over max_bytes.
absl::StatusOr<EvaluatedPoints> EvaluatePoints(const OpsContext& context,
                                               const PointsRequest& request);

}  // namespace splinegrid::server::ops

#endif  // SPLINEGRID_SERVER_OPS_EVALUATE_POINTS_H_
