// Retrying calls that break off (client.h BrokeOff): a replica died, a balancer had no upstream
// for a moment or reset a stream, or the server is restarting. The waits between attempts grow
// exponentially with jitter (the scheme of gRPC's connection backoff, A6 retry design) and never
// run past the call's deadline.
#ifndef SPLINEGRID_CLIENT_RETRY_H_
#define SPLINEGRID_CLIENT_RETRY_H_

#include <optional>

#include "absl/random/random.h"
#include "absl/time/time.h"

namespace splinegrid::client {

// When and how often a call that broke off is made again. The n-th retry waits
// min(initial_backoff * multiplier^(n-1), max_backoff), scaled by a random factor uniform in
// [1 - jitter, 1 + jitter]; a wait that would end at or past the call's deadline is not taken
// (the call returns its last error). The defaults wait about 50, 100, 200, 400 ms: a call gives
// up after ~0.75 s of failed attempts.
struct RetryPolicy {
  // Attempts of one call in all, the first included; 1 (or less) turns retrying off.
  int max_attempts = 5;
  // Wait before the first retry.
  absl::Duration initial_backoff = absl::Milliseconds(50);
  // Longest wait between two attempts (before jitter).
  absl::Duration max_backoff = absl::Seconds(2);
  // Growth of the wait per retry (values below 1 count as 1).
  double multiplier = 2.0;
  // Relative spread of each wait, in [0, 1], so clients that failed together do not retry in
  // lockstep.
  double jitter = 0.2;
};

// The waits of one call under a RetryPolicy. Not thread-safe; one per call.
class Backoff {
 public:
  explicit Backoff(const RetryPolicy& policy) : policy_(policy) {}

  // After a failed attempt: how long to wait before the next one, or nullopt when the attempts
  // are used up or the wait would end at or after `deadline`. Counts the failed attempt.
  std::optional<absl::Duration> Next(absl::Time deadline);

 private:
  RetryPolicy policy_;
  int failed_ = 0;
  absl::Duration backoff_;  // before jitter; set on the first retry
  std::optional<absl::BitGen> random_;
};

}  // namespace splinegrid::client

#endif  // SPLINEGRID_CLIENT_RETRY_H_
