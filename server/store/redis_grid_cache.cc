#include "server/store/redis_grid_cache.h"

#include <utility>

namespace splinegrid::server {
namespace {

int64_t LatestOf(const StoredGrid& grid) {
  return grid.revisions.empty() ? 0 : grid.revisions.back()->number;
}

}  // namespace

std::optional<RedisGridCache::Entry> RedisGridCache::Find(const std::string& id) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = slots_.find(id);
  if (it == slots_.end()) return std::nullopt;
  it->second.used = ++clock_;
  return it->second.entry;
}

std::optional<RedisGridCache::Entry> RedisGridCache::FindConfirmedSince(const std::string& id,
                                                                        absl::Time since) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = slots_.find(id);
  if (it == slots_.end() || it->second.confirmed < since) return std::nullopt;
  it->second.used = ++clock_;
  return it->second.entry;
}

void RedisGridCache::Put(const std::string& id, Entry entry) {
  Entry replaced;  // released after the lock
  std::lock_guard<std::mutex> lock(mu_);
  Slot& slot = slots_[id];
  if (slot.entry.snapshot && slot.entry.gen == entry.gen &&
      LatestOf(*slot.entry.snapshot) > LatestOf(*entry.snapshot)) {
    return;
  }
  replaced = std::exchange(slot.entry, std::move(entry));
  slot.used = ++clock_;
  slot.confirmed = absl::Now();
}

void RedisGridCache::Erase(const std::string& id) {
  Entry erased;  // released after the lock
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = slots_.find(id);
  if (it == slots_.end()) return;
  erased = std::move(it->second.entry);
  slots_.erase(it);
}

bool RedisGridCache::MakeRoom(int64_t bytes, const std::string& keep) {
  bool dropped = false;
  while (budget_->limit() - budget_->used() < bytes) {
    Entry evicted;  // released outside the lock, before the budget is looked at again
    {
      std::lock_guard<std::mutex> lock(mu_);
      auto oldest = slots_.end();
      for (auto it = slots_.begin(); it != slots_.end(); ++it) {
        if (it->first != keep &&
            (oldest == slots_.end() || it->second.used < oldest->second.used)) {
          oldest = it;
        }
      }
      if (oldest == slots_.end()) break;
      evicted = std::move(oldest->second.entry);
      slots_.erase(oldest);
    }
    dropped = true;
  }
  return dropped;
}

}  // namespace splinegrid::server
