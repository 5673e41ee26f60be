// SplineGridService::WatchGrid: a grid's revisions, the stored ones first, then each new one as
// it is published.
//
// The call opens the operation's feed (server/ops/watch.h): the stored revisions, then a
// subscription that queues every later one in publication order; so each revision is sent
// once, in order, and none stored after the call began is missed. The store wakes the reactor
// (GridWatcher::Wake) after publishing, outside its lock; the reactor then takes the next
// revision and writes it, one Write at a time (the rest wait in the subscription, at most
// ServerOptions::max_watch_lag of them). The stream ends
//  - OK when the grid is deleted, after the revisions stored before the deletion;
//  - CANCELLED when the client cancels or goes away (OnCancel, a failed write), or
//    DEADLINE_EXCEEDED when its deadline passes;
//  - UNAVAILABLE when the server shuts down: Server::Shutdown closes every subscription before
//    gRPC waits for calls to finish, so watches end at once instead of holding the grace period;
//  - RESOURCE_EXHAUSTED when the client falls more than max_watch_lag revisions behind;
//  - UNAUTHENTICATED or PERMISSION_DENIED when a reload of the tokens file (SIGHUP) removed the
//    call's token or took its read role: the reload wakes every open watch (OpenWatches), which
//    checks its token again before anything more is sent.
// The initial metadata goes out as soon as the subscription is in place, so a client can wait
// for it (ClientReader::WaitForInitialMetadata) to know that it will see every revision
// published from then on; it says where the stream begins and which creation of the id it
// watches (x-splinegrid-watch-after, x-splinegrid-incarnation), for a client that resumes. No
// reaction blocks: each takes the reactor's mutex for a moment and calls gRPC outside it; at most
// one operation (metadata or a write) is in flight.
//
// Lifetime: the reactor is owned by a shared_ptr that it releases in OnDone; the store reaches it
// only through a weak_ptr, and a wake-up holds a shared_ptr while it runs, so a wake-up racing
// with the end of the call never touches a deleted reactor.
#include <memory>
#include <mutex>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"
#include "server/grid_encoding.h"
#include "server/happens_before.h"
#include "server/ops/watch.h"
#include "server/service.h"

namespace splinegrid::server {
namespace {

constexpr char kWatchAfterHeader[] = "x-splinegrid-watch-after";
constexpr char kIncarnationHeader[] = "x-splinegrid-incarnation";

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
    // Read before authenticating: a reload in between makes the first write check again.
    auth_generation_ = state_->authenticator.generation();
    SG_ASSIGN_OR_RETURN(AdmittedStream admitted,
                        AdmitStream(*state_, context_, Role::kRead, &log_));
    caller_ = std::move(admitted.caller);
    stream_ = std::move(admitted.slot);
    SG_ASSIGN_OR_RETURN(std::string id, ParseGridName(request_->name(), "name"));
    name_ = absl::StrCat("grids/", id);
    SG_ASSIGN_OR_RETURN(
        std::unique_ptr<ops::RevisionFeed> feed,
        ops::RevisionFeed::Open(state_->Ops(), std::move(id), request_->after_revision(),
                                std::weak_ptr<GridWatcher>(self_),
                                static_cast<size_t>(state_->options.max_watch_lag)));
    // Where this stream begins, for a client that resumes it elsewhere (the proto's WatchGrid).
    context_->AddInitialMetadata(kWatchAfterHeader, absl::StrCat(feed->begins_after()));
    context_->AddInitialMetadata(kIncarnationHeader, feed->incarnation());
    std::lock_guard<std::mutex> lock(mu_);
    feed_ = std::move(feed);
    state_->watches.Add(std::weak_ptr<GridWatcher>(self_));
    return absl::OkStatus();
  }

  // Under mu_: OK while the call's token still admits it. After a reload of the tokens file
  // (a new generation) it is checked again: UNAUTHENTICATED once the token is gone, and
  // PERMISSION_DENIED when it lost the read role or names another principal now.
  absl::Status StillAdmitted() {
    const int64_t generation = state_->authenticator.generation();
    if (generation == auth_generation_) return absl::OkStatus();
    auth_generation_ = generation;
    absl::StatusOr<Caller> caller = state_->authenticator.Authenticate(*context_);
    if (!caller.ok()) {
      return absl::UnauthenticatedError(
          absl::StrCat("the tokens file was reloaded and this watch's token is no longer in it (",
                       caller.status().message(), ")"));
    }
    if (caller->role < Role::kRead || caller->principal != caller_.principal) {
      return absl::PermissionDeniedError(
          absl::StrCat("the tokens file was reloaded and this watch's token now names ",
                       caller->principal, " with the role ", RoleName(caller->role),
                       "; the watch was opened by ", caller_.principal));
    }
    return absl::OkStatus();
  }

  // Under mu_: the next revision into message_ (true), or false after noting in status_ how
  // the watch ends, if it does (OK once the grid was deleted).
  bool NextMessage() {
    if (state_->draining.load()) {
      status_ = absl::UnavailableError("the server is shutting down");
      return false;
    }
    if (absl::Status admitted = StillAdmitted(); !admitted.ok()) {
      status_ = std::move(admitted);
      return false;
    }
    const std::optional<RevisionSummary> revision = feed_->Next();
    if (!revision) {
      if (feed_->ended()) {
        ended_ = true;
        status_ = feed_->end_status();
      }
      return false;
    }
    message_.Clear();
    message_.set_name(name_);
    EncodeRevisionInfo(*revision, message_.mutable_revision());
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
      if (status_.ok() && !ended_) write = NextMessage();
      if (write) {
        writing_ = true;
      } else if (!status_.ok() || ended_) {
        finished_ = finish = true;
        final_status = status_;
      }
    }
    if (finish) {
      if (feed_) feed_->Close();
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
  int64_t auth_generation_ = 0;  // the tokens table caller_ was checked against
  // This call's place among its principal's open streams.
  StreamSlot stream_;
  std::shared_ptr<WatchReactor> self_;  // this, until OnDone
  std::string name_;                    // grids/{id}, set by Start before anything else can run
  // Shared between gRPC's threads and the threads that publish revisions.
  std::mutex mu_;
  std::unique_ptr<ops::RevisionFeed> feed_;
  v1::WatchGridResponse message_;  // being written while writing_
  bool started_ = false;
  bool writing_ = false;
  bool ended_ = false;  // the feed ended (status_ says why; OK: the grid was deleted)
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
