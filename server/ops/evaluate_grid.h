// EvaluateGrid's operation: a revision's blocks evaluated at a resolution, planned once and then
// produced in chunks of a bounded size, so that a caller streams any output size in
// O(chunk + the evaluator's intermediate nets) memory.
#ifndef SPLINEGRID_SERVER_OPS_EVALUATE_GRID_H_
#define SPLINEGRID_SERVER_OPS_EVALUATE_GRID_H_

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/bspline/block_sampling.h"
#include "core/bspline/evaluation.h"
#include "core/grid/sampling.h"
#include "server/ops/ops_context.h"

namespace splinegrid::server::ops {

struct GridEvaluationRequest {
  std::string grid_id;
  int64_t revision = 0;         // 0: the latest
  std::optional<int64_t> step;  // instead: the revision deformed at this solver step
  Resolution resolution;
  std::vector<int> blocks;   // in this order; empty: every block
  bool derivatives = false;  // also d/du, d/dv, d/dw (four fields instead of one)
  int64_t max_points = 0;    // the server's cap on the output
  // Values per chunk and field; the memory the caller keeps for chunks in flight, reserved
  // with the evaluator's.
  int64_t chunk_values = 1;
  int64_t buffer_bytes = 0;
  CancelCheck cancel;  // polled while a measured distribution is placed
};

struct EvaluatedBlock {
  int block = 0;
  Extents extents = {1, 1, 1};  // output points per direction
};

// The next piece of output: `count` values of each field of block `block`, from value `offset`
// of that block (spatial_dim values per point, i fastest).
struct EvaluationChunk {
  int block = 0;
  int64_t offset = 0;
  int64_t count = 0;
};

class GridEvaluation {
 public:
  // Resolves the revision, checks the blocks (in range, each once), the output size against
  // max_points and reserves the memory, then samples the parameters (O(points) for a measured
  // distribution: plan it as long work). Errors: NOT_FOUND (grid, revision, step),
  // INVALID_ARGUMENT naming the field and value, OUT_OF_RANGE over max_points,
  // RESOURCE_EXHAUSTED from the memory budget, CANCELLED.
  static absl::StatusOr<std::unique_ptr<GridEvaluation>> Plan(const OpsContext& context,
                                                              const GridEvaluationRequest& request);

  int64_t revision() const { return revision_->number; }
  int spatial_dim() const { return spatial_dim_; }
  int num_fields() const { return derivatives_ ? 4 : 1; }
  int64_t total_points() const { return total_points_; }
  // Whether some block has a measured distribution (block_sampling.h): its points are placed
  // and evaluated one by one, about 100x the cost of a tensor grid's.
  bool pointwise() const;
  const std::vector<EvaluatedBlock>& blocks() const { return blocks_; }

  bool done() const { return cursor_ == blocks_.size(); }
  // The chunk EvaluateNext writes (precondition: !done()).
  EvaluationChunk Next();
  // Writes Next()'s values of every field to out[0..num_fields()) (count doubles each) and
  // moves on.
  void EvaluateNext(const std::array<double*, 4>& out);

 private:
  GridEvaluation() = default;

  std::shared_ptr<const StoredGrid> grid_;  // holds the revision in the store's retention
  std::shared_ptr<const GridRevision> revision_;
  MemoryReservation memory_;
  bool derivatives_ = false;
  int spatial_dim_ = 0;
  int64_t total_points_ = 0;
  int64_t chunk_points_ = 1;
  std::vector<EvaluatedBlock> blocks_;
  std::vector<BlockSampling> samplings_;  // per entry of blocks_
  // Cursor: block entry, line and first point of the next chunk, and the chunk's end.
  size_t cursor_ = 0;
  int64_t line_ = 0;
  int i_ = 0;
  int64_t line_end_ = 0;
  int i_end_ = 0;
  std::unique_ptr<GridEvaluator> evaluator_;  // for the current block, unless it is measured
};

}  // namespace splinegrid::server::ops

#endif  // SPLINEGRID_SERVER_OPS_EVALUATE_GRID_H_
