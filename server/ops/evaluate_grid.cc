#include "server/ops/evaluate_grid.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid::server::ops {
namespace {

// Output lines (all i for one (j, k)) of a block.
int64_t NumLines(const EvaluatedBlock& block) {
  return int64_t{block.extents[1]} * block.extents[2];
}

}  // namespace

absl::StatusOr<std::unique_ptr<GridEvaluation>> GridEvaluation::Plan(
    const OpsContext& context, const GridEvaluationRequest& request) {
  std::unique_ptr<GridEvaluation> plan(new GridEvaluation());
  SG_ASSIGN_OR_RETURN(plan->grid_, context.store.GetHolding(request.grid_id, {request.revision}));
  SG_ASSIGN_OR_RETURN(plan->revision_,
                      plan->grid_->ResolveRevision(request.revision, request.step));
  const GridRevision& rev = *plan->revision_;
  const int num_blocks = static_cast<int>(rev.blocks.size());
  std::vector<int> blocks = request.blocks;
  if (blocks.empty()) {
    for (int b = 0; b < num_blocks; ++b) blocks.push_back(b);
  }
  const int s = rev.blocks.front().fitted.spline.spatial_dim();
  int64_t total = 0, work_bytes = 0, param_bytes = 0;
  std::vector<bool> seen(num_blocks, false);
  const bool measured = MeasuredDirection(request.resolution) >= 0;
  for (size_t q = 0; q < blocks.size(); ++q) {
    const int b = blocks[q];
    if (b < 0 || b >= num_blocks) {
      return absl::InvalidArgumentError(
          absl::StrCat("blocks[", q, "] = ", b, " is outside [0, ", num_blocks - 1, "]"));
    }
    if (seen[b]) {
      return absl::InvalidArgumentError(
          absl::StrCat("blocks[", q, "] = ", b, " is repeated; name each block once"));
    }
    seen[b] = true;
    const FittedBlock& fitted = rev.blocks[b].fitted;
    SG_ASSIGN_OR_RETURN(const Extents extents,
                        SampleExtents(fitted.distribution, request.resolution), "block ", b, ": ");
    total += NumPoints(extents);  // each at most 2^40 (SampleExtents): no overflow
    if (total > request.max_points) {
      // `total` counts the blocks up to this one: the rest would add to it.
      return absl::OutOfRangeError(
          absl::StrCat("the requested resolution gives ", total, " points in ",
                       q + 1 == blocks.size()
                           ? absl::StrCat("all ", blocks.size(), " requested")
                           : absl::StrCat("the first ", q + 1, " of ", blocks.size(), " requested"),
                       " blocks, more than the server's cap of ", request.max_points,
                       " (flag --max_output_points)"));
    }
    // The evaluator's intermediate nets: n_u' x n_v x n_w, and planes of n_u' x n_v.
    // Measured blocks are evaluated point by point, without them.
    const Extents n = fitted.spline.control_extents();
    const int64_t net = int64_t{s} * extents[0] * n[1] * (n[2] + 3) * sizeof(double);
    if (!measured) work_bytes = std::max(work_bytes, net * (request.derivatives ? 2 : 1));
    plan->blocks_.push_back({b, extents});
    param_bytes += BlockSampling::Bytes(request.resolution, extents);
  }
  // Reserved before the parameters are sampled: a small request may ask for 2^30 of them.
  SG_ASSIGN_OR_RETURN(
      plan->memory_,
      context.budget.Reserve(work_bytes + param_bytes + request.buffer_bytes, "the evaluation"));
  for (const EvaluatedBlock& block : plan->blocks_) {
    const FittedBlock& fitted = rev.blocks[block.block].fitted;
    SG_ASSIGN_OR_RETURN(plan->samplings_.emplace_back(),
                        BlockSampling::Create(fitted.spline, fitted.distribution,
                                              request.resolution, request.cancel),
                        "block ", block.block, ": ");
  }
  plan->derivatives_ = request.derivatives;
  plan->spatial_dim_ = s;
  plan->total_points_ = total;
  plan->chunk_points_ = std::max<int64_t>(1, request.chunk_values / s);
  return plan;
}

bool GridEvaluation::pointwise() const {
  return std::any_of(samplings_.begin(), samplings_.end(),
                     [](const BlockSampling& s) { return s.measured_direction() >= 0; });
}

EvaluationChunk GridEvaluation::Next() {
  const EvaluatedBlock& block = blocks_[cursor_];
  const BlockSampling& sampling = samplings_[cursor_];
  if (!evaluator_ && sampling.measured_direction() < 0) {
    evaluator_ = std::make_unique<GridEvaluator>(revision_->blocks[block.block].fitted.spline,
                                                 sampling.params(), derivatives_);
  }
  // Whole lines while they fit in a chunk, else pieces of one line.
  const int ni = block.extents[0];
  line_end_ = line_ + 1;
  i_end_ = ni;
  if (i_ == 0 && ni <= chunk_points_) {
    line_end_ = std::min(NumLines(block), line_ + std::max<int64_t>(1, chunk_points_ / ni));
  } else {
    i_end_ = static_cast<int>(std::min<int64_t>(ni, i_ + chunk_points_));
  }
  const int64_t s = spatial_dim_;
  return {block.block, s * (line_ * ni + i_), s * ((line_end_ - line_) * ni - i_ - (ni - i_end_))};
}

void GridEvaluation::EvaluateNext(const std::array<double*, 4>& out) {
  const EvaluatedBlock& block = blocks_[cursor_];
  const int ni = block.extents[0];
  if (!evaluator_) {  // a measured distribution: point by point
    const int64_t first = line_ * ni + i_, last = (line_end_ - 1) * ni + i_end_;
    EvaluateSampledPoints(revision_->blocks[block.block].fitted.spline, samplings_[cursor_], first,
                          last - first, out[0], out[1], out[2], out[3]);
  } else if (line_end_ == line_ + 1 && (i_ != 0 || i_end_ != ni)) {
    evaluator_->EvaluateLineRange(line_, i_, i_end_, out[0], out[1], out[2], out[3]);
  } else {
    evaluator_->EvaluateLines(line_, line_end_, out[0], out[1], out[2], out[3]);
  }
  if (i_end_ == ni) {
    line_ = line_end_;
    i_ = 0;
  } else {
    i_ = i_end_;
  }
  if (line_ == NumLines(block)) {
    evaluator_.reset();
    line_ = 0;
    ++cursor_;
  }
}

}  // namespace splinegrid::server::ops
