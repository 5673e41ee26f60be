// The lifecycle every client-streamed upload shares (ImportGrid, ImportArchive): admitted as a
// write call, one of its principal's open streams, ended when nothing arrives for
// --import_idle_timeout; each message accepted on gRPC's thread as it arrives (copies and
// checks only), and once the client has closed its side the work runs on the pool as a long
// task. Every path ends the call once, with one log line.
//
// A subclass implements Accept (one message) and Complete (the work), and calls Start() last in
// its constructor: reads may complete on another thread as soon as they start, so they must not
// start before the subclass is built.
#ifndef SPLINEGRID_SERVER_UPLOAD_REACTOR_H_
#define SPLINEGRID_SERVER_UPLOAD_REACTOR_H_

#include <mutex>

#include "absl/status/status.h"
#include "server/call_log.h"
#include "server/decoded_request.h"
#include "server/happens_before.h"
#include "server/idle_watchdog.h"
#include "server/service.h"

namespace splinegrid::server {

template <typename Request>
class UploadReactor : public grpc::ServerReadReactor<Decoded<Request>> {
 public:
  void OnReadDone(bool ok) override {
    SG_HAPPENS_AFTER(this);
    if (!ok) {  // the client closed its side: everything has arrived
      idle_.Stop();  // from here on the call is the pool's
      if (std::lock_guard<std::mutex> lock(mu_); ended_) return;  // the idle timeout ended it
      // Reads also end when the client cancels or the shutdown's grace runs out: then nothing
      // is stored and the status says why.
      if (context_->IsCancelled()) {
        End(WhyCallEnded(*state_, context_));
        return;
      }
      if (absl::Status status = state_->pool.TrySubmit(caller_.principal, WorkKind::kLong,
                                                       [this] { RunComplete(); });
          !status.ok()) {
        End(status);
      }
      return;
    }
    idle_.Touch();
    std::lock_guard<std::mutex> lock(mu_);
    if (ended_) return;  // the idle timeout ended the call meanwhile
    if (absl::Status status = message_.status.ok() ? Accept(message_.message) : message_.status;
        !status.ok()) {
      ended_ = true;
      End(status);
      return;
    }
    SG_HAPPENS_BEFORE(this);
    this->StartRead(&message_);
  }

  void OnDone() override {
    SG_HAPPENS_AFTER(this);
    idle_.Stop();
    delete this;
  }

 protected:
  // `method` names the call in the log and in the idle timeout's message.
  UploadReactor(ServiceState* state, grpc::CallbackServerContext* context, const char* method)
      : state_(state), context_(context), log_(method, "", state->options), method_(method) {}
  ~UploadReactor() override = default;

  // Admits the call and starts reading (the last statement of the subclass's constructor).
  void Start() {
    absl::StatusOr<AdmittedStream> admitted =
        AdmitStream(*state_, context_, Role::kWrite, &log_);
    if (!admitted.ok()) {
      End(admitted.status());
      return;
    }
    caller_ = std::move(admitted->caller);
    stream_ = std::move(admitted->slot);
    idle_.Start(state_->options.import_idle_timeout, [this] { OnIdle(); });
    SG_HAPPENS_BEFORE(this);
    this->StartRead(&message_);
  }

  // One decoded message, on gRPC's thread: an error ends the call with it.
  virtual absl::Status Accept(const Request& message) = 0;
  // Everything arrived, on the pool: its status ends the call.
  virtual absl::Status Complete() = 0;

  // The call's cancellation and deadline, for the kernel work of Complete().
  CancelCheck Cancel() const { return CallCancelCheck(context_); }

  // Frees the read buffer's capacity (e.g. after a large header); only at the end of Accept, as
  // the message Accept was given lives there.
  void ReleaseMessage() { message_.message = Request(); }

  ServiceState* const state_;
  grpc::CallbackServerContext* const context_;
  CallLog log_;
  Caller caller_;

 private:
  void RunComplete() {
    SG_HAPPENS_AFTER(this);
    End(Complete());
  }

  // On the watchdog's thread: nothing arrived for import_idle_timeout (a read is pending).
  void OnIdle() {
    std::lock_guard<std::mutex> lock(mu_);
    if (ended_) return;
    ended_ = true;
    End(IdleTimeoutError(method_, state_->options.import_idle_timeout));
  }

  void End(const absl::Status& status) {
    stream_.Release();  // the call is over for its principal once its status goes out
    log_.Finish(status);
    SG_HAPPENS_BEFORE(this);
    this->Finish(ToGrpcStatus(status));
  }

  const char* const method_;
  StreamSlot stream_;  // this call's place among its principal's open streams
  Decoded<Request> message_;
  IdleWatch idle_;      // ends the call when nothing arrives for import_idle_timeout
  std::mutex mu_;       // orders the reads' Finish/StartRead against the idle watch's Finish
  bool ended_ = false;  // guarded by mu_: Finish was called from OnReadDone or OnIdle
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_UPLOAD_REACTOR_H_
