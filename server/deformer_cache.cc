#include "server/deformer_cache.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid::server {

namespace {

// A gate with the budget its bytes are charged to.
struct ChargedGate {
  DeformationGate gate;
  MemoryReservation memory;
};

// About what DeformationGate::bytes() will say for `reference` at `level`: 25 bytes per cell at
// most (a surface's area vector and state), before the gate is built. Counted in double and
// capped, so that no level overflows.
int64_t EstimatedGateBytes(const std::vector<FittedBlock>& reference, int level) {
  double bytes = 0.0;
  for (const FittedBlock& block : reference) {
    double cells = 1.0;
    for (int d = 0; d < 3; ++d) {
      const int m = block.distribution.num_points(d);
      if (m > 1) cells *= std::ldexp(m - 1.0, level);
    }
    bytes += 25.0 * cells;
  }
  return static_cast<int64_t>(std::min(bytes, 1e18));
}

}  // namespace

absl::StatusOr<std::shared_ptr<const DeformationGate>> KeptDeformer::Gate(
    int level, MemoryBudget& budget, const CancelCheck& cancel) const {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (const auto it = gates_.find(level); it != gates_.end()) return it->second;
  }
  const std::string what = absl::StrCat("the fold gate of check_level ", level);
  SG_ASSIGN_OR_RETURN(MemoryReservation memory,
                      budget.Reserve(EstimatedGateBytes(deformer_.reference(), level), what));
  SG_ASSIGN_OR_RETURN(
      DeformationGate made,
      DeformationGate::Create(deformer_.reference(), deformer_.kinds(), level, cancel));
  // The estimate becomes the gate's own size (kept as estimated when the budget is short).
  budget.Resize(&memory, made.bytes(), what).IgnoreError();
  auto charged = std::make_shared<ChargedGate>(ChargedGate{std::move(made), std::move(memory)});
  std::shared_ptr<const DeformationGate> gate(charged, &charged->gate);
  if (gate->num_cells() > kMaxKeptGateCells) return gate;  // this call's only
  std::lock_guard<std::mutex> lock(mu_);
  // Another call may have kept one meanwhile: that one stays, this one goes with the call.
  return gates_.emplace(level, std::move(gate)).first->second;
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
  // Another call may have made and kept one meanwhile: keep that one (and its gates).
  for (const auto& entry : entries_) {
    if (entry.first == key) return entry.second;
  }
  entries_.emplace_front(key, deformer);
  while (static_cast<int>(entries_.size()) > capacity_) entries_.pop_back();
  return deformer;
}

bool KeptDeformer::HasGate(int level) const {
  std::lock_guard<std::mutex> lock(mu_);
  return gates_.contains(level);
}

bool DeformerCache::HasReady(const std::string& prefix, int level) {
  std::lock_guard<std::mutex> lock(mu_);
  for (const auto& entry : entries_) {
    if (entry.first.rfind(prefix, 0) == 0 && entry.second->HasGate(level)) return true;
  }
  return false;
}

void DeformerCache::Forget(const std::string& prefix) {
  std::lock_guard<std::mutex> lock(mu_);
  entries_.remove_if([&](const auto& e) { return e.first.rfind(prefix, 0) == 0; });
}

}  // namespace splinegrid::server
