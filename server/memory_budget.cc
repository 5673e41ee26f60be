#include "server/memory_budget.h"

#include "absl/strings/str_cat.h"

namespace splinegrid::server {

MemoryReservation::MemoryReservation(MemoryReservation&& other) noexcept
    : budget_(other.budget_), bytes_(other.bytes_) {
  other.budget_ = nullptr;
  other.bytes_ = 0;
}

MemoryReservation& MemoryReservation::operator=(MemoryReservation&& other) noexcept {
  if (this != &other) {
    if (budget_) budget_->Release(bytes_);
    budget_ = other.budget_;
    bytes_ = other.bytes_;
    other.budget_ = nullptr;
    other.bytes_ = 0;
  }
  return *this;
}

MemoryReservation::~MemoryReservation() {
  if (budget_) budget_->Release(bytes_);
}

namespace {

int64_t MiBUp(int64_t bytes) { return (bytes + (1 << 20) - 1) >> 20; }

}  // namespace

absl::StatusOr<MemoryReservation> MemoryBudget::Reserve(int64_t bytes, const std::string& what,
                                                        int64_t held) {
  if (bytes < 0) bytes = 0;
  int64_t used = used_.load();
  for (;;) {
    if (bytes > limit_ - used) {
      // What `what` holds already is part of `used`: said, so that it does not read as a leak.
      const std::string needs = held > 0
                                    ? absl::StrCat(MiBUp(bytes), " MiB more (", MiBUp(held + bytes),
                                                   " MiB in all; it holds ", held >> 20, " MiB)")
                                    : absl::StrCat(MiBUp(bytes), " MiB");
      return absl::ResourceExhaustedError(
          absl::StrCat(what, " needs ", needs, " but the server's memory budget has ",
                       std::max<int64_t>(limit_ - used, 0) >> 20, " MiB of ", limit_ >> 20,
                       " MiB left (flag --memory_budget_mb)"));
    }
    if (used_.compare_exchange_weak(used, used + bytes)) break;
  }
  return MemoryReservation(this, bytes);
}

absl::Status MemoryBudget::Extend(MemoryReservation* reservation, int64_t bytes,
                                  const std::string& what) {
  absl::StatusOr<MemoryReservation> more = Reserve(bytes, what, reservation->bytes_);
  if (!more.ok()) return more.status();
  if (reservation->budget_ != nullptr && reservation->budget_ != this) {
    return absl::InternalError("a reservation was extended from another budget");
  }
  reservation->budget_ = this;
  reservation->bytes_ += more->bytes_;
  more->bytes_ = 0;
  return absl::OkStatus();
}

absl::Status MemoryBudget::Resize(MemoryReservation* reservation, int64_t bytes,
                                  const std::string& what) {
  if (bytes < 0) bytes = 0;
  if (bytes >= reservation->bytes_) return Extend(reservation, bytes - reservation->bytes_, what);
  if (reservation->budget_ != this) {
    return absl::InternalError("a reservation was resized in another budget");
  }
  Release(reservation->bytes_ - bytes);
  reservation->bytes_ = bytes;
  return absl::OkStatus();
}

}  // namespace splinegrid::server
