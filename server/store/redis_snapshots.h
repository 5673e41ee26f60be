// The reading side of the Redis store: snapshots of grids assembled from what GetScript and
// AddRevisionScript return, reusing this process's cached snapshot (redis_grid_cache.h) for
// everything that did not change. A revision is decoded once per process; a grid's source
// points once per generation (one loader at a time per grid: concurrent cache misses wait for
// the first instead of reading the same points again).
//
// Errors: NOT_FOUND when the grid went away while it was read; DATA_LOSS for values in Redis
// that do not decode (naming the grid and the record); RESOURCE_EXHAUSTED when the budget
// cannot hold what was read even after making room in the cache; UNAVAILABLE from the pool.
#ifndef SPLINEGRID_SERVER_STORE_REDIS_SNAPSHOTS_H_
#define SPLINEGRID_SERVER_STORE_REDIS_SNAPSHOTS_H_

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "server/grid_store.h"
#include "server/memory_budget.h"
#include "server/store/redis_connection.h"
#include "server/store/redis_grid_cache.h"
#include "server/store/redis_scripts.h"
#include "splinegrid/v1/archive.pb.h"

namespace splinegrid::server {

class RedisSnapshots {
 public:
  struct Fetched {
    std::string gen;
    std::shared_ptr<const StoredGrid> snapshot;
  };

  // Reads through `pool` under `keys`; decoded data charged to `budget`. All must outlive this.
  RedisSnapshots(RedisPool* pool, const RedisKeys* keys, MemoryBudget* budget)
      : pool_(pool), keys_(keys), budget_(budget), cache_(budget) {}

  // The cached snapshot of `id`, if any.
  std::optional<RedisGridCache::Entry> Cached(const std::string& id) { return cache_.Find(id); }
  // The cached snapshot of `id` if Redis confirmed it within `window`.
  std::optional<RedisGridCache::Entry> Recent(const std::string& id, absl::Duration window) {
    return cache_.FindConfirmedSince(id, absl::Now() - window);
  }
  // Appends the scripts' "what the caller has" arguments for `cached`: its generation ("" if
  // none), then its revision numbers.
  static void AppendKnown(const std::optional<RedisGridCache::Entry>& cached,
                          std::vector<std::string>* args);

  // The current snapshot of `id`: one GetScript round trip, plus the source on a cache miss.
  absl::StatusOr<Fetched> Fetch(const std::string& id);
  // The snapshot of `id`, generation `gen`, with the revisions `numbers` (ascending); `values`
  // hold the StoredRevisions of those that neither `cached` (if of `gen`) nor `published` has
  // ("" for the others). Cached as the grid's latest snapshot.
  absl::StatusOr<Fetched> Assemble(const std::string& id, const std::string& gen,
                                   RedisValue numbers, RedisValue values,
                                   const std::optional<RedisGridCache::Entry>& cached,
                                   const std::shared_ptr<const GridRevision>& published);

  void Put(const std::string& id, RedisGridCache::Entry entry) { cache_.Put(id, std::move(entry)); }
  void Erase(const std::string& id) { cache_.Erase(id); }

 private:
  // `value` as revision `number` of grid `id` on `source`, charged to the budget; on a
  // refusal, makes `room` bytes in the cache (once per snapshot: `*made_room`) and retries.
  absl::StatusOr<std::shared_ptr<const GridRevision>> DecodeRevision(const std::string& id,
                                                                     int64_t number,
                                                                     std::string_view value,
                                                                     const SourcePoints& source,
                                                                     int64_t room, bool* made_room);
  // Grid `id` of generation `gen` without revisions: its header and source points.
  absl::StatusOr<std::shared_ptr<const StoredGrid>> LoadShell(const std::string& id,
                                                              const std::string& gen);
  absl::StatusOr<std::shared_ptr<const StoredGrid>> ReadSource(RedisConnection& connection,
                                                               const std::string& id,
                                                               const std::string& gen,
                                                               const v1::ArchiveHeader& header);
  // The mutex that serialises the source loads of grid `id`.
  std::shared_ptr<std::mutex> LoaderOf(const std::string& id);

  RedisPool* const pool_;
  const RedisKeys* const keys_;
  MemoryBudget* const budget_;
  RedisGridCache cache_;
  std::mutex loaders_mu_;
  std::map<std::string, std::weak_ptr<std::mutex>> loaders_;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_STORE_REDIS_SNAPSHOTS_H_
