#include "server/ops/evaluate_points.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "core/bspline/evaluation.h"
#include "core/util/status_macros.h"

namespace splinegrid::server::ops {
namespace {

// Checks `request` against revision `rev`; the number of points.
absl::StatusOr<int64_t> CheckRequest(const PointsRequest& request, const GridRevision& rev) {
  const int64_t num_values = std::ssize(request.parameters);
  if (num_values % 3 != 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "parameters: ", num_values, " values is not a multiple of 3 (u, v, w per point)"));
  }
  const int64_t n = num_values / 3;
  const int64_t num_given = std::ssize(request.blocks);
  if (num_given != 1 && num_given != n) {
    return absl::InvalidArgumentError(absl::StrCat("blocks: ", num_given, " values for ", n,
                                                   " points; give one, or one per point"));
  }
  const int s = rev.blocks.front().fitted.spline.spatial_dim();
  const int64_t fields = request.derivatives ? 4 : 1;
  if (n > request.max_points || n * s * fields * 9 > request.max_bytes) {
    return absl::OutOfRangeError(
        absl::StrCat(n, " points per call is over the limit of ",
                     std::min(request.max_points, request.max_bytes / (s * fields * 9)),
                     " (server cap and 4 MiB response); split the batch or use EvaluateGrid"));
  }
  const int num_blocks = static_cast<int>(rev.blocks.size());
  for (int64_t i = 0; i < num_given; ++i) {
    if (request.blocks[i] < 0 || request.blocks[i] >= num_blocks) {
      return absl::InvalidArgumentError(absl::StrCat("blocks[", i, "] = ", request.blocks[i],
                                                     " is outside [0, ", num_blocks - 1, "]"));
    }
  }
  for (int64_t i = 0; i < num_values; ++i) {
    const double u = request.parameters[i];
    if (!(u >= 0.0 && u <= 1.0)) {
      return absl::InvalidArgumentError(absl::StrCat("parameters[", i, "] (",
                                                     std::string(1, "uvw"[i % 3]), " of point ",
                                                     i / 3, ") = ", u, " is outside [0, 1]"));
    }
  }
  return n;
}

}  // namespace

absl::StatusOr<EvaluatedPoints> EvaluatePoints(const OpsContext& context,
                                               const PointsRequest& request) {
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> grid,
                      context.store.GetHolding(request.grid_id, {request.revision}));
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const GridRevision> rev,
                      grid->ResolveRevision(request.revision, request.step));
  SG_ASSIGN_OR_RETURN(const int64_t n, CheckRequest(request, *rev));
  EvaluatedPoints out;
  out.revision = rev->number;
  out.spatial_dim = rev->blocks.front().fitted.spline.spatial_dim();
  const int s = out.spatial_dim;
  out.points.resize(n * s);
  if (request.derivatives) {
    out.du.resize(n * s);
    out.dv.resize(n * s);
    out.dw.resize(n * s);
  }
  for (int64_t p = 0; p < n; ++p) {
    const int b = request.blocks[request.blocks.size() == 1 ? 0 : p];
    const Point3 uvw = {request.parameters[3 * p], request.parameters[3 * p + 1],
                        request.parameters[3 * p + 2]};
    const PartialDerivatives d =
        EvaluateDerivatives(rev->blocks[b].fitted.spline, uvw, request.derivatives ? 1 : 0);
    for (int c = 0; c < s; ++c) {
      out.points[s * p + c] = d(0, 0, 0)[c];
      if (!request.derivatives) continue;
      out.du[s * p + c] = d(1, 0, 0)[c];
      out.dv[s * p + c] = d(0, 1, 0)[c];
      out.dw[s * p + c] = d(0, 0, 1)[c];
    }
  }
  return out;
}

}  // namespace splinegrid::server::ops
