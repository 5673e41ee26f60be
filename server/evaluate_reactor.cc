// SplineGridService::EvaluateGrid: a header, then chunks of about 256 KiB per field.
//
// Chunks are produced on the worker pool, a few ahead of the network: while one chunk is being
// written the next ones are evaluated, so evaluation and transport overlap. Memory stays
// O(chunks in flight + the evaluator's intermediate nets), whatever the output size. A
// cancelled call or an expired deadline stops production at the next chunk.
#include <algorithm>
#include <deque>
#include <mutex>

#include "absl/strings/str_cat.h"
#include "core/bspline/evaluation.h"
#include "core/grid/sampling.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"
#include "server/happens_before.h"
#include "server/service.h"

namespace splinegrid::server {
namespace {

constexpr int64_t kChunkBytes = 256 << 10;
constexpr size_t kMaxReady = 8;  // messages evaluated ahead of the network
// Evaluations of at most this many points in all are cheap work for the scheduler (about a
// millisecond: the points of a 225 x 65 grid); larger ones are long work, shared fairly.
constexpr int64_t kMaxCheapPoints = int64_t{1} << 16;

struct BlockPlan {
  int block;
  Extents extents;
  std::array<std::vector<double>, 3> params;
};

class EvaluateReactor : public grpc::ServerWriteReactor<v1::EvaluateGridResponse> {
 public:
  EvaluateReactor(ServiceState* state, grpc::CallbackServerContext* context,
                  const v1::EvaluateGridRequest* request)
      : state_(state),
        context_(context),
        request_(request),
        cancel_(CallCancelCheck(context)),
        log_("EvaluateGrid", request->name(), state->options) {
    absl::StatusOr<AdmittedStream> admitted = AdmitStream(*state_, context, Role::kRead, &log_);
    if (!admitted.ok()) {
      Fail(admitted.status());
      return;
    }
    caller_ = std::move(admitted->caller);
    stream_ = std::move(admitted->slot);
    if (absl::Status status =
            state_->pool.TrySubmit(caller_.principal, WorkKind::kCheap, [this] { Start(); });
        !status.ok()) {
      Fail(status);
    }
  }

  void OnWriteDone(bool ok) override {
    SG_HAPPENS_AFTER(this);
    {
      std::lock_guard<std::mutex> lock(mu_);
      writing_ = false;
      ready_.pop_front();
      if (!ok && status_.ok()) status_ = WhyCallEnded(*state_, context_);
    }
    Pump();
  }

  void OnDone() override {
    SG_HAPPENS_AFTER(this);
    delete this;
  }

 private:
  bool float_values() const { return request_->precision() == v1::PRECISION_FLOAT; }
  int num_fields() const { return request_->derivatives() ? 4 : 1; }

  void Fail(const absl::Status& status) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (status_.ok()) status_ = status;
    }
    Pump();
  }

  // Validates and plans the call, then queues the header.
  void Start() {
    absl::StatusOr<std::unique_ptr<v1::EvaluateGridResponse>> header = Plan();
    if (!header.ok()) return Fail(header.status());
    {
      std::lock_guard<std::mutex> lock(mu_);
      ready_.push_back(*std::move(header));
      started_ = true;
    }
    Pump();
  }

  absl::StatusOr<std::unique_ptr<v1::EvaluateGridResponse>> Plan() {
    SG_ASSIGN_OR_RETURN(const std::string id, ParseGridName(request_->name(), "name"));
    SG_ASSIGN_OR_RETURN(grid_, state_->store->GetHolding(id, {request_->revision()}));
    SG_ASSIGN_OR_RETURN(revision_,
                        grid_->ResolveRevision(request_->revision(), OptionalStep(*request_)));
    SG_ASSIGN_OR_RETURN(const Resolution resolution, ParseResolution(*request_));
    const int num_blocks = static_cast<int>(revision_->blocks.size());
    std::vector<int> blocks(request_->blocks().begin(), request_->blocks().end());
    if (blocks.empty()) {
      for (int b = 0; b < num_blocks; ++b) blocks.push_back(b);
    }
    auto header = std::make_unique<v1::EvaluateGridResponse>();
    v1::EvaluationHeader* h = header->mutable_header();
    const int s = revision_->blocks.front().fitted.spline.spatial_dim();
    int64_t total = 0, work_bytes = 0, param_bytes = 0;
    std::vector<bool> seen(num_blocks, false);
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
      const FittedBlock& fitted = revision_->blocks[b].fitted;
      SG_ASSIGN_OR_RETURN(const Extents extents, SampleExtents(fitted.distribution, resolution),
                          "block ", b, ": ");
      total += NumPoints(extents);
      if (total > state_->options.max_output_points) {
        return absl::OutOfRangeError(absl::StrCat("the requested resolution gives over ", total,
                                                  " points, more than the server's cap of ",
                                                  state_->options.max_output_points,
                                                  " (flag --max_output_points)"));
      }
      // The evaluator's intermediate nets: n_u' x n_v x n_w, and planes of n_u' x n_v.
      const Extents n = fitted.spline.control_extents();
      const int64_t net = int64_t{s} * extents[0] * n[1] * (n[2] + 3) * sizeof(double);
      work_bytes = std::max(work_bytes, net * (request_->derivatives() ? 2 : 1));
      v1::EvaluatedBlock* eb = h->add_blocks();
      eb->set_block(b);
      EncodeExtents(extents, eb->mutable_extents());
      plan_.push_back({b, extents, {}});
      param_bytes += (int64_t{extents[0]} + extents[1] + extents[2]) * int64_t{sizeof(double)};
    }
    // Reserved before the parameters are sampled: a small request may ask for 2^30 of them.
    SG_ASSIGN_OR_RETURN(memory_, state_->budget.Reserve(work_bytes + param_bytes +
                                                            int64_t{kMaxReady + 4} * kChunkBytes,
                                                        "the evaluation"));
    for (BlockPlan& block : plan_) {
      SG_ASSIGN_OR_RETURN(
          block.params,
          SampleParameters(revision_->blocks[block.block].fitted.distribution, resolution));
    }
    h->set_revision(revision_->number);
    h->set_spatial_dim(s);
    h->set_precision(float_values() ? v1::PRECISION_FLOAT : v1::PRECISION_DOUBLE);
    h->set_derivatives(request_->derivatives());
    h->set_total_points(total);
    produce_kind_ = total <= kMaxCheapPoints ? WorkKind::kCheap : WorkKind::kLong;
    spatial_dim_ = s;
    points_per_chunk_ = std::max<int64_t>(
        1,
        kChunkBytes / (s * static_cast<int64_t>(float_values() ? sizeof(float) : sizeof(double))));
    return header;
  }

  // Moves the call forward: writes the next ready message, starts a producer when there is
  // room for more, or finishes once everything is written (or on error, once no write or
  // production is in flight).
  void Pump() {
    bool finish = false, produce = false;
    v1::EvaluateGridResponse* next = nullptr;
    absl::Status final_status;
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (finished_) return;
      const bool stop = !status_.ok();
      if ((stop || (produced_all_ && ready_.empty())) && !writing_ && !producing_) {
        finished_ = true;
        finish = true;
        final_status = status_;
      } else if (!stop) {
        if (!writing_ && !ready_.empty()) {
          writing_ = true;
          next = ready_.front().get();
        }
        if (started_ && !producing_ && !produced_all_ &&
            ready_.size() + num_fields() <= kMaxReady) {
          producing_ = produce = true;
        }
      }
    }
    if (finish) {
      stream_.Release();  // the call is over for its principal once its status goes out
      log_.Finish(final_status);
      SG_HAPPENS_BEFORE(this);
      Finish(ToGrpcStatus(final_status));
      return;
    }
    if (next) {
      SG_HAPPENS_BEFORE(this);
      StartWrite(next);
    }
    if (!produce) return;
    if (absl::Status status = state_->pool.TrySubmit(
            caller_.principal, produce_kind_, [this] { Produce(); }, Admission::kContinuation);
        !status.ok()) {
      {
        std::lock_guard<std::mutex> lock(mu_);
        producing_ = false;
      }
      Fail(status);
    }
  }

  // Evaluates chunks until kMaxReady messages wait or everything is produced (on the pool).
  void Produce() {
    absl::Status status;
    for (;;) {
      {
        std::lock_guard<std::mutex> lock(mu_);
        if (!status_.ok() || ready_.size() + num_fields() > kMaxReady) break;
      }
      if (cancel_()) {
        status = WhyCallEnded(*state_, context_);
        break;
      }
      std::vector<std::unique_ptr<v1::EvaluateGridResponse>> step;
      const bool more = NextStep(&step);
      std::lock_guard<std::mutex> lock(mu_);
      for (auto& message : step) ready_.push_back(std::move(message));
      if (!more) {
        produced_all_ = true;
        break;
      }
    }
    {
      std::lock_guard<std::mutex> lock(mu_);
      producing_ = false;
      if (!status.ok() && status_.ok()) status_ = status;
    }
    Pump();
  }

  // One message per field for the next range of points; false when this was the last one.
  bool NextStep(std::vector<std::unique_ptr<v1::EvaluateGridResponse>>* step) {
    const BlockPlan& block = plan_[block_cursor_];
    if (!evaluator_) {
      evaluator_ = std::make_unique<GridEvaluator>(revision_->blocks[block.block].fitted.spline,
                                                   block.params, request_->derivatives());
    }
    const int ni = block.extents[0];
    const int64_t s = spatial_dim_;
    int64_t line_end = line_ + 1;
    int i_end = ni;
    if (i_ == 0 && ni <= points_per_chunk_) {
      line_end =
          std::min(evaluator_->num_lines(), line_ + std::max<int64_t>(1, points_per_chunk_ / ni));
    } else {
      i_end = static_cast<int>(std::min<int64_t>(ni, i_ + points_per_chunk_));
    }
    const int64_t offset = s * (line_ * ni + i_);
    const int64_t count = s * ((line_end - line_) * ni - i_ - (ni - i_end));
    std::array<double*, 4> out{};
    std::array<std::unique_ptr<v1::EvaluateGridResponse>, 4> messages;
    for (int f = 0; f < num_fields(); ++f) {
      messages[f] = std::make_unique<v1::EvaluateGridResponse>();
      v1::EvaluationChunk* chunk = messages[f]->mutable_chunk();
      chunk->set_block(block.block);
      chunk->set_field(static_cast<v1::Field>(v1::FIELD_POINTS + f));
      chunk->set_offset(offset);
      if (float_values()) {
        scratch_[f].resize(count);
        out[f] = scratch_[f].data();
      } else {
        chunk->mutable_values()->Resize(static_cast<int>(count), 0.0);
        out[f] = chunk->mutable_values()->mutable_data();
      }
    }
    if (line_end == line_ + 1 && (i_ != 0 || i_end != ni)) {
      evaluator_->EvaluateLineRange(line_, i_, i_end, out[0], out[1], out[2], out[3]);
    } else {
      evaluator_->EvaluateLines(line_, line_end, out[0], out[1], out[2], out[3]);
    }
    for (int f = 0; f < num_fields(); ++f) {
      if (float_values()) {
        // One narrowing copy of the chunk (vectorised), not a Set call per value.
        auto* values = messages[f]->mutable_chunk()->mutable_float_values();
        values->Resize(static_cast<int>(count), 0.0f);
        std::transform(out[f], out[f] + count, values->mutable_data(),
                       [](double v) { return static_cast<float>(v); });
      }
      step->push_back(std::move(messages[f]));
    }
    // Advance the cursor.
    if (i_end == ni) {
      line_ = line_end;
      i_ = 0;
    } else {
      i_ = i_end;
    }
    if (line_ == evaluator_->num_lines()) {
      evaluator_.reset();
      line_ = 0;
      ++block_cursor_;
    }
    return block_cursor_ < plan_.size();
  }

  ServiceState* state_;
  grpc::CallbackServerContext* context_;
  const v1::EvaluateGridRequest* request_;
  CancelCheck cancel_;
  CallLog log_;
  Caller caller_;
  // This call's place among its principal's open streams.
  StreamSlot stream_;
  WorkKind produce_kind_ = WorkKind::kLong;  // set by Plan()
  std::shared_ptr<const StoredGrid> grid_;
  std::shared_ptr<const GridRevision> revision_;
  std::vector<BlockPlan> plan_;
  MemoryReservation memory_;
  int spatial_dim_ = 3;
  int64_t points_per_chunk_ = 1;
  // Production cursor (used by one Produce task at a time).
  size_t block_cursor_ = 0;
  int64_t line_ = 0;
  int i_ = 0;
  std::unique_ptr<GridEvaluator> evaluator_;
  std::array<std::vector<double>, 4> scratch_;
  // Shared between gRPC's and the pool's threads.
  std::mutex mu_;
  std::deque<std::unique_ptr<v1::EvaluateGridResponse>> ready_;  // front: being written
  bool writing_ = false;
  bool producing_ = false;
  bool started_ = false;
  bool produced_all_ = false;
  bool finished_ = false;
  absl::Status status_;
};

}  // namespace

grpc::ServerWriteReactor<v1::EvaluateGridResponse>* SplineGridService::EvaluateGrid(
    grpc::CallbackServerContext* context, const v1::EvaluateGridRequest* request) {
  return new EvaluateReactor(state_, context, request);
}

}  // namespace splinegrid::server
