#include "server/deformer_cache.h"

namespace splinegrid::server {

absl::StatusOr<std::shared_ptr<const DeformationGate>> KeptDeformer::Gate(int level) const {
  std::lock_guard<std::mutex> lock(mu_);
  if (const auto it = gates_.find(level); it != gates_.end()) return it->second;
  absl::StatusOr<DeformationGate> made =
      DeformationGate::Create(deformer_.reference(), deformer_.kinds(), level);
  if (!made.ok()) return made.status();
  auto gate = std::make_shared<const DeformationGate>(*std::move(made));
  if (gate->num_cells() <= kMaxKeptGateCells) gates_[level] = gate;
  return gate;
}

absl::StatusOr<std::shared_ptr<const KeptDeformer>> DeformerCache::Get(
    const std::string& key, const std::function<absl::StatusOr<Deformer>()>& make) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    for (auto it = entries_.begin(); it != entries_.end(); ++it) {
      if (it->first != key) continue;
      entries_.splice(entries_.begin(), entries_, it);
      return entries_.front().second;
    }
  }
  absl::StatusOr<Deformer> made = make();
  if (!made.ok()) return made.status();
  auto deformer = std::make_shared<const KeptDeformer>(*std::move(made));
  std::lock_guard<std::mutex> lock(mu_);
  entries_.emplace_front(key, deformer);
  while (static_cast<int>(entries_.size()) > capacity_) entries_.pop_back();
  return deformer;
}

bool DeformerCache::HasAny(const std::string& prefix) {
  std::lock_guard<std::mutex> lock(mu_);
  for (const auto& entry : entries_) {
    if (entry.first.rfind(prefix, 0) == 0) return true;
  }
  return false;
}

void DeformerCache::Forget(const std::string& prefix) {
  std::lock_guard<std::mutex> lock(mu_);
  entries_.remove_if([&](const auto& e) { return e.first.rfind(prefix, 0) == 0; });
}

}  // namespace splinegrid::server
