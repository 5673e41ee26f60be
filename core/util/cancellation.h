// Cooperative cancellation for long kernel operations.
//
// The kernel knows nothing of RPCs; a caller that has a deadline or a cancelled call passes a
// check that the kernel polls between work units (a chunk of lines, a fit pass, an adaptive
// iteration). A check that returns true makes the operation stop with CANCELLED.
#ifndef SPLINEGRID_CORE_UTIL_CANCELLATION_H_
#define SPLINEGRID_CORE_UTIL_CANCELLATION_H_

#include <cstdint>
#include <functional>
#include <utility>

#include "absl/status/status.h"

namespace splinegrid {

// Returns true when the caller no longer wants the result. Empty means "never".
using CancelCheck = std::function<bool()>;

// CANCELLED if `check` is set and fires, else OK.
inline absl::Status PollCancel(const CancelCheck& check) {
  if (check && check()) return absl::CancelledError("operation cancelled by the caller");
  return absl::OkStatus();
}

// Polls a check once per `interval` units of work, for loops whose single steps are too cheap to
// poll every time (a hash insert, a point comparison). Once fired it stays fired.
class CancelPoller {
 public:
  explicit CancelPoller(CancelCheck check, int64_t interval = int64_t{1} << 16)
      : check_(std::move(check)), interval_(interval) {}

  // Counts `work` units; true once the check has fired.
  bool Tick(int64_t work = 1) {
    if (!check_ || cancelled_) return cancelled_;
    done_ += work;
    if (done_ >= interval_) {
      done_ = 0;
      cancelled_ = check_();
    }
    return cancelled_;
  }

  bool cancelled() const { return cancelled_; }

  // CANCELLED once the check has fired, else OK.
  absl::Status status() const {
    return cancelled_ ? absl::CancelledError("operation cancelled by the caller")
                      : absl::OkStatus();
  }

 private:
  CancelCheck check_;
  int64_t interval_;
  int64_t done_ = 0;
  bool cancelled_ = false;
};

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_UTIL_CANCELLATION_H_
