#include "server/stream_limits.h"

#include "absl/strings/str_cat.h"

namespace splinegrid::server {

StreamSlot::StreamSlot(StreamSlot&& other) noexcept
    : limits_(other.limits_), principal_(std::move(other.principal_)) {
  other.limits_ = nullptr;
}

StreamSlot& StreamSlot::operator=(StreamSlot&& other) noexcept {
  if (this != &other) {
    Release();
    limits_ = other.limits_;
    principal_ = std::move(other.principal_);
    other.limits_ = nullptr;
  }
  return *this;
}

StreamSlot::~StreamSlot() { Release(); }

void StreamSlot::Release() {
  if (limits_ != nullptr) limits_->Close(principal_);
  limits_ = nullptr;
}

absl::StatusOr<StreamSlot> StreamLimits::Open(const std::string& principal) {
  std::lock_guard<std::mutex> lock(mu_);
  int& open = open_[principal];
  if (open >= max_per_principal_) {
    return absl::ResourceExhaustedError(
        absl::StrCat("this caller already has ", open,
                     " streaming calls open (limit "
                     "max_streams_per_principal = ",
                     max_per_principal_, "); end one (e.g. a WatchGrid) before opening another"));
  }
  ++open;
  return StreamSlot(this, principal);
}

int StreamLimits::open(const std::string& principal) const {
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = open_.find(principal);
  return it == open_.end() ? 0 : it->second;
}

int StreamLimits::open_total() const {
  std::lock_guard<std::mutex> lock(mu_);
  int total = 0;
  for (const auto& [principal, open] : open_) total += open;
  return total;
}

void StreamLimits::Close(const std::string& principal) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = open_.find(principal);
  if (it != open_.end() && --it->second <= 0) open_.erase(it);
}

}  // namespace splinegrid::server
