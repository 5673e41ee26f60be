// Cooperative cancellation for long kernel operations.
//
// The kernel knows nothing of RPCs; a caller that has a deadline or a cancelled call passes a
// check that the kernel polls between work units (a chunk of lines, a fit pass, an adaptive
// iteration). A check that returns true makes the operation stop with CANCELLED.
#ifndef SPLINEGRID_CORE_UTIL_CANCELLATION_H_
#define SPLINEGRID_CORE_UTIL_CANCELLATION_H_

#include <functional>

#include "absl/status/status.h"

namespace splinegrid {

// Returns true when the caller no longer wants the result. Empty means "never".
using CancelCheck = std::function<bool()>;

// CANCELLED if `check` is set and fires, else OK.
inline absl::Status PollCancel(const CancelCheck& check) {
  if (check && check()) return absl::CancelledError("operation cancelled by the caller");
  return absl::OkStatus();
}

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_UTIL_CANCELLATION_H_
