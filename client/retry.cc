#include "client/retry.h"

#include <algorithm>

#include "absl/random/distributions.h"
#include "absl/time/clock.h"

namespace splinegrid::client {

std::optional<absl::Duration> Backoff::Next(absl::Time deadline) {
  ++failed_;
  if (failed_ >= policy_.max_attempts) return std::nullopt;
  const absl::Duration cap = std::max(policy_.max_backoff, absl::ZeroDuration());
  backoff_ = failed_ == 1 ? policy_.initial_backoff : backoff_ * std::max(policy_.multiplier, 1.0);
  backoff_ = std::clamp(backoff_, absl::ZeroDuration(), cap);
  absl::Duration wait = backoff_;
  if (const double jitter = std::clamp(policy_.jitter, 0.0, 1.0); jitter > 0.0) {
    if (!random_) random_.emplace();
    wait *= absl::Uniform(absl::IntervalClosed, *random_, 1.0 - jitter, 1.0 + jitter);
  }
  if (absl::Now() + wait >= deadline) return std::nullopt;
  return wait;
}

}  // namespace splinegrid::client
