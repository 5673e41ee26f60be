// SplineGridService::WatchGrid: a grid's revisions, the stored ones first, then each new one as
// it is published.
//
// The call subscribes to the grid (GridStore::Subscribe), which gives, atomically, the current
// snapshot and a subscription that queues every later revision in publication order; so each
// revision is sent once, in order, and none stored after the call began is missed. The store
// wakes the reactor (GridWatcher::Wake) after publishing, outside its lock; the reactor then
// takes the next event and writes it, one Write at a time (the rest wait in the subscription,
// at most ServerOptions::max_watch_lag of them). The stream ends
//  - OK when the grid is deleted, after the revisions stored before the deletion;
//  - CANCELLED when the client cancels or goes away (OnCancel, a failed write), or
//    DEADLINE_EXCEEDED when its deadline passes;
//  - UNAVAILABLE when the server shuts down: Server::Shutdown closes every subscription before
//    gRPC waits for calls to finish, so watches end at once instead of holding the grace period;
//  - RESOURCE_EXHAUSTED when the client falls more than max_watch_lag revisions behind.
// The initial metadata goes out as soon as the subscription is in place, so a client can wait
// for it (ClientReader::WaitForInitialMetadata) to know that it will see every revision
// published from then on. No reaction blocks: each takes the reactor's mutex for a moment and
// calls gRPC outside it; at most one operation (metadata or a write) is in flight.
//
// Lifetime: the reactor is owned by a shared_ptr that it releases in OnDone; the store reaches it
// only through a weak_ptr, and a wake-up holds a shared_ptr while it runs, so a wake-up racing
// with the end of the call never touches a deleted reactor.
#include <deque>
#include <memory>
#include <mutex>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"
#include "server/grid_encoding.h"
#include "server/happens_before.h"
#include "server/service.h"

namespace splinegrid::server {
namespace {

class WatchReactor : public grpc::ServerWriteReactor<v1::WatchGridResponse>, public GridWatcher {
 public:
  WatchReactor(ServiceState* state, grpc::CallbackServerContext* context,
               const v1::WatchGridRequest* request)
      : state_(state),
        context_(context),
        request_(request),
        log_("WatchGrid", request->name(), state->options) {}

  // Validates the request, subscribes and writes the first revision; `self` owns this reactor
  // until OnDone.
  void Start(std::shared_ptr<WatchReactor> self) {
    self_ = std::move(self);
    const absl::Status status = Subscribe();
    {
      std::lock_guard<std::mutex> lock(mu_);
      status_ = status;
      started_ = true;
      writing_ = status.ok();  // the initial metadata, in flight like a write
    }
    if (status.ok()) {
      SG_HAPPENS_BEFORE(this);
      StartSendInitialMetadata();
    } else {
      Pump();
    }
  }

  void OnSendInitialMetadataDone(bool ok) override { OnWriteDone(ok); }

  void Wake() override { Pump(); }

  void OnWriteDone(bool ok) override {
    SG_HAPPENS_AFTER(this);
    {
      std::lock_guard<std::mutex> lock(mu_);
      writing_ = false;
      if (!ok && status_.ok()) status_ = WhyCallEnded(*state_, context_);
    }
    Pump();
  }

  void OnCancel() override {
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (status_.ok()) status_ = WhyCallEnded(*state_, context_);
    }
    Pump();
  }

  void OnDone() override {
    SG_HAPPENS_AFTER(this);
    // The last owner but a running wake-up: this reactor may be destroyed on return.
    const std::shared_ptr<WatchReactor> self = std::move(self_);
  }

 private:
  absl::Status Subscribe() {
    SG_ASSIGN_OR_RETURN(AdmittedStream admitted,
                        AdmitStream(*state_, context_, Role::kRead, &log_));
    caller_ = std::move(admitted.caller);
    stream_ = std::move(admitted.slot);
    absl::StatusOr<std::string> id = ParseGridName(request_->name(), "name");
    if (!id.ok()) return id.status();
    id_ = *std::move(id);
    after_ = request_->after_revision();
    if (after_ < -1) {
      return absl::InvalidArgumentError(
          absl::StrCat("after_revision = ", after_,
                       " is below -1 (0: every stored revision, -1: only new ones)"));
    }
    absl::StatusOr<GridStore::Watch> watch = state_->store->Subscribe(
        id_, std::weak_ptr<GridWatcher>(self_), static_cast<size_t>(state_->options.max_watch_lag));
    if (!watch.ok()) return watch.status();
    std::lock_guard<std::mutex> lock(mu_);
    subscription_ = std::move(watch->subscription);
    const auto& stored = watch->snapshot->revisions;
    last_sent_ = after_ >= 0 ? after_ : (stored.empty() ? 0 : stored.back()->number);
    if (after_ >= 0) {
      for (const auto& revision : stored) {
        if (revision->number > after_) backlog_.push_back(RevisionSummary::Of(*revision));
      }
    }
    return absl::OkStatus();
  }

  // Under mu_: the next revision to write into message_ (true), or false after noting in
  // status_ / deleted_ how the watch ends, if it does.
  bool NextMessage() {
    if (state_->draining.load()) {
      status_ = absl::UnavailableError("the server is shutting down");
      return false;
    }
    RevisionSummary revision;
    if (!backlog_.empty()) {
      revision = backlog_.front();
      backlog_.pop_front();
    } else {
      GridSubscription::End end = GridSubscription::End::kOpen;
      bool found = false;
      while (!found && subscription_->Next(&revision, &end)) {
        found = revision.number > after_;  // after_ may lie beyond the latest at the start
      }
      if (!found) {
        switch (end) {
          case GridSubscription::End::kOpen:  // nothing new yet
            break;
          case GridSubscription::End::kGridDeleted:
            deleted_ = true;
            break;
          case GridSubscription::End::kLagged:
            status_ = absl::ResourceExhaustedError(absl::StrCat(
                "the client fell more than ", state_->options.max_watch_lag,
                " revisions behind grids/", id_,
                " and the watch was ended; watch again with after_revision = ", last_sent_));
            break;
          case GridSubscription::End::kClosed:
            status_ = absl::UnavailableError("the server is shutting down");
            break;
        }
        return false;
      }
    }
    message_.Clear();
    message_.set_name(absl::StrCat("grids/", id_));
    EncodeRevisionInfo(revision, message_.mutable_revision());
    last_sent_ = revision.number;
    return true;
  }

  // Moves the call forward: writes the next revision when no write is in flight, or finishes
  // once the watch has ended (and no write is in flight).
  void Pump() {
    bool write = false, finish = false;
    absl::Status final_status;
    {
      std::lock_guard<std::mutex> lock(mu_);
      // While a write is in flight, OnWriteDone pumps again; before Start is done, Start does.
      if (finished_ || writing_ || !started_) return;
      if (status_.ok() && !deleted_) write = NextMessage();
      if (write) {
        writing_ = true;
      } else if (!status_.ok() || deleted_) {
        finished_ = finish = true;
        final_status = status_;
      }
    }
    if (finish) {
      if (subscription_) state_->store->Unsubscribe(id_, subscription_.get());
      stream_.Release();  // the call is over for its principal once its status goes out
      log_.Finish(final_status);
      SG_HAPPENS_BEFORE(this);
      Finish(ToGrpcStatus(final_status));
      return;
    }
    if (write) {
      SG_HAPPENS_BEFORE(this);
      StartWrite(&message_);
    }
  }

  ServiceState* state_;
  grpc::CallbackServerContext* context_;
  const v1::WatchGridRequest* request_;
  CallLog log_;
  Caller caller_;
  // This call's place among its principal's open streams.
  StreamSlot stream_;
  std::shared_ptr<WatchReactor> self_;  // this, until OnDone
  // Set by Start before anything else can run.
  std::string id_;
  int64_t after_ = 0;
  // Shared between gRPC's threads and the threads that publish revisions.
  std::mutex mu_;
  std::shared_ptr<GridSubscription> subscription_;
  std::deque<RevisionSummary> backlog_;  // the stored revisions still to send
  v1::WatchGridResponse message_;        // being written while writing_
  int64_t last_sent_ = 0;                // (or where the watch began)
  bool started_ = false;
  bool writing_ = false;
  bool deleted_ = false;  // the grid was deleted and everything before it sent
  bool finished_ = false;
  absl::Status status_;
};

}  // namespace

grpc::ServerWriteReactor<v1::WatchGridResponse>* SplineGridService::WatchGrid(
    grpc::CallbackServerContext* context, const v1::WatchGridRequest* request) {
  auto reactor = std::make_shared<WatchReactor>(state_, context, request);
  reactor->Start(reactor);
  return reactor.get();  // owned by itself until OnDone
}

}  // namespace splinegrid::server
