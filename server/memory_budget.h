// The server's memory budget: stored grids and in-flight work reserve bytes before they use
// them, and a reservation that does not fit is refused (RESOURCE_EXHAUSTED) instead of letting
// the process grow without bound. Reservations are released when destroyed.
#ifndef SPLINEGRID_SERVER_MEMORY_BUDGET_H_
#define SPLINEGRID_SERVER_MEMORY_BUDGET_H_

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/statusor.h"

namespace splinegrid::server {

class MemoryBudget;

// Bytes held against a budget until destruction (move-only).
class MemoryReservation {
 public:
  MemoryReservation() = default;
  MemoryReservation(MemoryReservation&& other) noexcept;
  MemoryReservation& operator=(MemoryReservation&& other) noexcept;
  ~MemoryReservation();

  int64_t bytes() const { return bytes_; }

 private:
  friend class MemoryBudget;
  MemoryReservation(MemoryBudget* budget, int64_t bytes) : budget_(budget), bytes_(bytes) {}

  MemoryBudget* budget_ = nullptr;
  int64_t bytes_ = 0;
};

class MemoryBudget {
 public:
  explicit MemoryBudget(int64_t limit_bytes) : limit_(limit_bytes) {}

  // Reserves `bytes` for `what` (named in the error), or RESOURCE_EXHAUSTED; `held`: what
  // `what` holds already (Extend), which the error states apart from the rest in use.
  absl::StatusOr<MemoryReservation> Reserve(int64_t bytes, const std::string& what,
                                            int64_t held = 0);
  // Adds `bytes` to `reservation` (which then holds against this budget), or RESOURCE_EXHAUSTED
  // leaving it as it was: for data charged as it arrives.
  absl::Status Extend(MemoryReservation* reservation, int64_t bytes, const std::string& what);
  // Makes `reservation` hold exactly `bytes`: releases the excess at once, or Extends by the
  // shortfall (RESOURCE_EXHAUSTED leaving it as it was).
  absl::Status Resize(MemoryReservation* reservation, int64_t bytes, const std::string& what);

  int64_t used() const { return used_.load(); }
  int64_t limit() const { return limit_; }

 private:
  friend class MemoryReservation;
  void Release(int64_t bytes) { used_.fetch_sub(bytes); }

  const int64_t limit_;
  std::atomic<int64_t> used_{0};
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_MEMORY_BUDGET_H_
