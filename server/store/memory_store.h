// The embedded store: grids in this process's memory, optionally made durable by a DurableLog
// that every change goes through before it is published (the `dir:` backend, dir_log.h).
//
// Adding a revision publishes a new snapshot under a short lock, so a running fit never blocks
// readers. Writers of one grid are serialised by a per-grid mutex, held while the log writes:
// the number is assigned, the revision written and then published, so what is on disk is
// always a prefix of what was published, and nothing is published that is not on disk.
#ifndef SPLINEGRID_SERVER_STORE_MEMORY_STORE_H_
#define SPLINEGRID_SERVER_STORE_MEMORY_STORE_H_

#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "server/grid_store.h"
#include "server/store/subscription_hub.h"

namespace splinegrid::server {

// Where a MemoryStore writes its changes before publishing them. A failed write leaves the
// store unchanged and fails the call.
class DurableLog {
 public:
  virtual ~DurableLog() = default;
  // A new grid: its header, source points and the revisions it has.
  virtual absl::Status WriteGrid(const StoredGrid& grid) = 0;
  virtual absl::Status WriteRevision(const std::string& id, const GridRevision& revision) = 0;
  // Retention dropped `numbers` of grid `id`. Best effort: what is left behind is dropped again
  // when the log is loaded.
  virtual void DropRevisions(const std::string& id, const std::vector<int64_t>& numbers) = 0;
  virtual absl::Status DeleteGrid(const std::string& id) = 0;
  // Forgets that grid `id` was found damaged at a start (MemoryStore's `damaged_grids`).
  virtual absl::Status ForgetDamagedGrid(const std::string& id) = 0;
  // Writes, syncs and removes a small file where grids are written: whether writes get
  // through now (after one failed).
  virtual absl::Status Probe() = 0;
};

class MemoryStore final : public GridStore {
 public:
  // Keeps the newest `max_deform_revisions` (>= 1) deformed revisions of each grid; starts with
  // `loaded` grids (what `log` held). `damaged_grids` (id -> why): grids the log found damaged
  // and set aside; asking for one is DATA_LOSS saying so (not "not found") until it is deleted,
  // which frees the id.
  explicit MemoryStore(int max_deform_revisions, std::unique_ptr<DurableLog> log = nullptr,
                       std::vector<std::shared_ptr<const StoredGrid>> loaded = {},
                       std::map<std::string, std::string> damaged_grids = {});

  absl::Status Create(std::shared_ptr<const StoredGrid> grid) override;
  absl::StatusOr<std::shared_ptr<const StoredGrid>> Get(const std::string& id) override;
  bool ReadsAreLocal() const override { return true; }  // the dir: log is only written
  absl::StatusOr<std::shared_ptr<const StoredGrid>> AddRevision(
      const std::string& id, GridRevision revision, int64_t expected_latest = 0,
      const std::string& incarnation = "") override;
  absl::Status Delete(const std::string& id, const DeleteCheck& check = nullptr) override;
  absl::StatusOr<Watch> Subscribe(const std::string& id, std::weak_ptr<GridWatcher> watcher,
                                  size_t max_queued) override;
  void Unsubscribe(const std::string& id, const GridSubscription* subscription) override;
  void CloseSubscriptions() override;
  absl::StatusOr<std::vector<std::shared_ptr<const StoredGrid>>> List(const std::string& after,
                                                                      int limit,
                                                                      bool* more) override;
  absl::StatusOr<Counts> Count() override;
  // With a log: UNAVAILABLE from a failed write of it until a probe write gets through (tried
  // at most once a second, here).
  absl::Status Available() const override;

 private:
  // The mutex that serialises the writers of grid `id`.
  std::shared_ptr<std::mutex> WriterOf(const std::string& id);
  // A write of the log failed (`error`, naming the file): noted for Available() and logged;
  // what the caller gets: RESOURCE_EXHAUSTED for a full disk or quota, UNAVAILABLE for any
  // other fault of the store (a read-only or failing disk, lost permissions), never an error
  // that would be about the caller's request (PERMISSION_DENIED, NOT_FOUND, ...).
  // `what` failed; `outcome` says what that left ("nothing was stored").
  // Under mu_: why grid `id` is not here: DATA_LOSS for a grid found damaged at a start,
  // else NOT_FOUND.
  absl::Status Missing(const std::string& id) const;
  absl::Status LogWriteFailed(const absl::Status& error, const std::string& what,
                              const char* outcome = "nothing was stored") const;

  const int max_deform_revisions_;
  const std::unique_ptr<DurableLog> log_;
  mutable std::mutex mu_;  // before the hub's
  std::map<std::string, std::shared_ptr<const StoredGrid>> grids_;
  std::map<std::string, std::string> damaged_grids_;  // id -> why (the constructor's)
  std::set<std::string> creating_;                    // ids whose Create is writing to the log
  std::map<std::string, std::shared_ptr<std::mutex>> writers_;
  SubscriptionHub hub_;
  // The log's health: OK, or why its last write (or probe) failed.
  mutable std::mutex log_health_mu_;
  mutable absl::Status log_failure_;
  mutable absl::Time last_probe_ = absl::InfinitePast();
  mutable bool probing_ = false;  // a probe runs (outside the lock)
  mutable int64_t failures_ = 0;  // failed writes so far
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_STORE_MEMORY_STORE_H_
