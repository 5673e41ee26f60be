// GetWallCurvature's operation: curvature samples along every wall grid line of a revision.
#ifndef SPLINEGRID_SERVER_OPS_WALL_CURVATURE_H_
#define SPLINEGRID_SERVER_OPS_WALL_CURVATURE_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/fit/report/wall_curvature.h"
#include "core/util/cancellation.h"
#include "server/ops/ops_context.h"

namespace splinegrid::server::ops {

// Highest level served: 15 samples between grid points are plenty to see wriggles.
inline constexpr int kMaxCurvatureLevel = 4;

struct WallCurvatureRequest {
  std::string grid_id;
  int64_t revision = 0;     // 0: the latest
  int level = 0;            // samples per grid interval: 2^level, [0, kMaxCurvatureLevel]
  std::vector<int> blocks;  // empty: every block
  // The largest answer the caller can send: arc length, curvature and the point per sample.
  int64_t max_bytes = 0;
};

struct WallCurvatureLine {
  WallLine line;
  std::vector<CurvatureSample> samples;
};

struct WallCurvatureResult {
  int64_t revision = 0;
  int spatial_dim = 0;
  std::vector<WallCurvatureLine> lines;
  CurvatureMetrics metrics;  // over every sample returned
};

// The wall lines of the blocks asked for and their curvature samples. Errors: NOT_FOUND,
// INVALID_ARGUMENT naming the field (level, blocks, revision), RESOURCE_EXHAUSTED when the
// samples would exceed max_bytes (refused before sampling), CANCELLED.
absl::StatusOr<WallCurvatureResult> WallCurvature(const OpsContext& context,
                                                  const WallCurvatureRequest& request,
                                                  const CancelCheck& cancel);

}  // namespace splinegrid::server::ops

#endif  // SPLINEGRID_SERVER_OPS_WALL_CURVATURE_H_
