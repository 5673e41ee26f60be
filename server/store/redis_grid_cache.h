// The Redis store's per-process snapshots: the latest snapshot this process assembled of each
// grid, by generation, so that a grid's source points are decoded once per process and each
// revision once (a new snapshot shares what did not change with the previous one).
//
// What the snapshots hold is charged to the MemoryBudget by whoever decoded it (GridAssembler,
// LoadRevision, the caller of AddRevision); the cache bounds itself through the budget: when a
// reservation fails, MakeRoom drops the least recently used grids' snapshots (their memory goes
// when the last reader lets go) and the caller retries once.
#ifndef SPLINEGRID_SERVER_STORE_REDIS_GRID_CACHE_H_
#define SPLINEGRID_SERVER_STORE_REDIS_GRID_CACHE_H_

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "absl/time/time.h"
#include "server/grid_store.h"
#include "server/memory_budget.h"

namespace splinegrid::server {

class RedisGridCache {
 public:
  struct Entry {
    std::string gen;  // the grid's generation (one per creation)
    std::shared_ptr<const StoredGrid> snapshot;
  };

  explicit RedisGridCache(MemoryBudget* budget) : budget_(budget) {}

  // The cached snapshot of `id` (now the most recently used), if any.
  std::optional<Entry> Find(const std::string& id);
  // The same, if Redis confirmed it (it was Put) at `since` or later.
  std::optional<Entry> FindConfirmedSince(const std::string& id, absl::Time since);
  // Caches `entry` as the snapshot of `id`, unless one of the same generation with a higher
  // latest revision is cached already (a slower reader must not go back in time).
  void Put(const std::string& id, Entry entry);
  void Erase(const std::string& id);
  // Drops least recently used snapshots other than `keep`'s until `bytes` more fit in the
  // budget or nothing else is cached; false if nothing was dropped.
  bool MakeRoom(int64_t bytes, const std::string& keep);

 private:
  struct Slot {
    Entry entry;
    uint64_t used = 0;     // clock_ at the last use
    absl::Time confirmed;  // when it was Put
  };

  MemoryBudget* const budget_;
  mutable std::mutex mu_;
  std::map<std::string, Slot> slots_;
  uint64_t clock_ = 0;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_STORE_REDIS_GRID_CACHE_H_
