// SplineGridService::EvaluateGrid: a header, then chunks of about 256 KiB per field, produced by
// the operation (server/ops/evaluate_grid.h).
//
// Chunks are produced on the worker pool, a few ahead of the network: while one chunk is being
// written the next ones are evaluated, so evaluation and transport overlap. Memory stays
// O(chunks in flight + the evaluator's intermediate nets), whatever the output size. A
// cancelled call or an expired deadline stops production at the next chunk.
#include <algorithm>
#include <deque>
#include <mutex>

#include "core/grid/sampling.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"
#include "server/happens_before.h"
#include "server/ops/evaluate_grid.h"
#include "server/service.h"

namespace splinegrid::server {
namespace {

constexpr int64_t kChunkBytes = 256 << 10;
constexpr size_t kMaxReady = 8;  // messages evaluated ahead of the network
// Evaluations of at most this many points in all are cheap work for the scheduler (about a
// millisecond: the points of a 225 x 65 grid); larger ones are slices of long work (scheduler.h),
// one chunk per task so that a task stays within a few milliseconds (a chunk is about 10,900
// points; placed one by one for a measured distribution, ~0.25 us each).
constexpr int64_t kMaxCheapPoints = int64_t{1} << 16;

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
    // Planning a measured distribution places every output point: long work.
    // (A resolution that does not parse is refused by Start, cheaply.)
    const absl::StatusOr<Resolution> resolution = ParseResolution(*request);
    const bool measured = resolution.ok() && MeasuredDirection(*resolution) >= 0;
    if (absl::Status status = state_->pool.TrySubmit(
            caller_.principal, measured ? WorkKind::kLong : WorkKind::kCheap, [this] { Start(); });
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

  // The operation's plan, and the header that announces it.
  absl::StatusOr<std::unique_ptr<v1::EvaluateGridResponse>> Plan() {
    ops::GridEvaluationRequest plan;
    SG_ASSIGN_OR_RETURN(plan.grid_id, ParseGridName(request_->name(), "name"));
    plan.revision = request_->revision();
    plan.step = OptionalStep(*request_);
    SG_ASSIGN_OR_RETURN(plan.resolution, ParseResolution(*request_));
    plan.blocks.assign(request_->blocks().begin(), request_->blocks().end());
    plan.derivatives = request_->derivatives();
    plan.max_points = state_->options.max_output_points;
    plan.chunk_values =
        kChunkBytes / static_cast<int64_t>(float_values() ? sizeof(float) : sizeof(double));
    plan.buffer_bytes = int64_t{kMaxReady + 4} * kChunkBytes;
    plan.cancel = cancel_;
    SG_ASSIGN_OR_RETURN(evaluation_, ops::GridEvaluation::Plan(state_->Ops(), plan));
    auto header = std::make_unique<v1::EvaluateGridResponse>();
    v1::EvaluationHeader* h = header->mutable_header();
    for (const ops::EvaluatedBlock& block : evaluation_->blocks()) {
      v1::EvaluatedBlock* eb = h->add_blocks();
      eb->set_block(block.block);
      EncodeExtents(block.extents, eb->mutable_extents());
    }
    h->set_revision(evaluation_->revision());
    h->set_spatial_dim(evaluation_->spatial_dim());
    h->set_precision(float_values() ? v1::PRECISION_FLOAT : v1::PRECISION_DOUBLE);
    h->set_derivatives(request_->derivatives());
    h->set_total_points(evaluation_->total_points());
    produce_kind_ = evaluation_->total_points() <= kMaxCheapPoints && !evaluation_->pointwise()
                        ? WorkKind::kCheap
                        : WorkKind::kSlice;
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

  // Evaluates chunks until kMaxReady messages wait or everything is produced (on the pool); a
  // slice evaluates one chunk, and Pump submits the next.
  void Produce() {
    absl::Status status;
    for (int chunks = 0; produce_kind_ != WorkKind::kSlice || chunks < 1; ++chunks) {
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

  // One message per field for the next chunk of points; false when this was the last one.
  bool NextStep(std::vector<std::unique_ptr<v1::EvaluateGridResponse>>* step) {
    const ops::EvaluationChunk next = evaluation_->Next();
    std::array<double*, 4> out{};
    std::array<std::unique_ptr<v1::EvaluateGridResponse>, 4> messages;
    for (int f = 0; f < num_fields(); ++f) {
      messages[f] = std::make_unique<v1::EvaluateGridResponse>();
      v1::EvaluationChunk* chunk = messages[f]->mutable_chunk();
      chunk->set_block(next.block);
      chunk->set_field(static_cast<v1::Field>(v1::FIELD_POINTS + f));
      chunk->set_offset(next.offset);
      if (float_values()) {
        scratch_[f].resize(next.count);
        out[f] = scratch_[f].data();
      } else {
        chunk->mutable_values()->Resize(static_cast<int>(next.count), 0.0);
        out[f] = chunk->mutable_values()->mutable_data();
      }
    }
    evaluation_->EvaluateNext(out);
    for (int f = 0; f < num_fields(); ++f) {
      if (float_values()) {
        // One narrowing copy of the chunk (vectorised), not a Set call per value.
        auto* values = messages[f]->mutable_chunk()->mutable_float_values();
        values->Resize(static_cast<int>(next.count), 0.0f);
        std::transform(out[f], out[f] + next.count, values->mutable_data(),
                       [](double v) { return static_cast<float>(v); });
      }
      step->push_back(std::move(messages[f]));
    }
    return !evaluation_->done();
  }

  ServiceState* state_;
  grpc::CallbackServerContext* context_;
  const v1::EvaluateGridRequest* request_;
  CancelCheck cancel_;
  CallLog log_;
  Caller caller_;
  // This call's place among its principal's open streams.
  StreamSlot stream_;
  WorkKind produce_kind_ = WorkKind::kSlice;  // set by Plan()
  std::unique_ptr<ops::GridEvaluation>
      evaluation_;  // set by Plan(); produced by one task at a time
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
