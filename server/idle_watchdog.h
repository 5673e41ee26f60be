// Ends client streams that go quiet: a reactor starts an IdleWatch when it begins reading,
// touches it on every message, and stops it when reading ends. A watch not touched for its
// timeout runs its callback once, on the watchdog's thread (one thread for the process, started
// on first use), which typically Finishes the call with DEADLINE_EXCEEDED.
//
// Race-freedom: the callback runs under the watch's mutex and Stop() takes that mutex, so after
// Stop() returns the callback is not running and never will. The callback must not call Stop()
// (it would deadlock); a callback that Finishes a gRPC call is fine, as gRPC runs OnDone of
// application reactors on its own threads, never inline in Finish. Reactors call Stop() at the
// start of OnDone, before they delete themselves.
#ifndef SPLINEGRID_SERVER_IDLE_WATCHDOG_H_
#define SPLINEGRID_SERVER_IDLE_WATCHDOG_H_

#include <functional>
#include <memory>
#include <string_view>

#include "absl/status/status.h"
#include "absl/time/time.h"

namespace splinegrid::server {

namespace internal {
struct IdleEntry;
}  // namespace internal

// One watched stream (move-only; the destructor stops it).
class IdleWatch {
 public:
  IdleWatch() = default;
  IdleWatch(IdleWatch&&) = default;
  IdleWatch& operator=(IdleWatch&& other) noexcept;
  ~IdleWatch();

  // Starts watching (stopping an earlier watch): `on_idle` runs once, on the watchdog's thread,
  // when `timeout` passes without Touch(). A zero or negative timeout watches nothing.
  void Start(absl::Duration timeout, std::function<void()> on_idle);
  // Activity: the quiet time starts again. Lock-free (one atomic store).
  void Touch();
  // After it returns, on_idle is not running and will not run. Idempotent.
  void Stop();

 private:
  std::shared_ptr<internal::IdleEntry> entry_;
};

// DEADLINE_EXCEEDED for a `call` stream that received nothing for `timeout`, naming the flag.
absl::Status IdleTimeoutError(std::string_view call, absl::Duration timeout);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_IDLE_WATCHDOG_H_
