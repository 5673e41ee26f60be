#include "server/store/memory_store.h"

#include <algorithm>
#include <cstdio>
#include <string_view>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid::server {
MemoryStore::MemoryStore(int max_deform_revisions, std::unique_ptr<DurableLog> log,
                         std::vector<std::shared_ptr<const StoredGrid>> loaded,
                         std::map<std::string, std::string> damaged_grids)
    : max_deform_revisions_(max_deform_revisions),
      log_(std::move(log)),
      damaged_grids_(std::move(damaged_grids)) {
  // A loaded grid keeps its creation's incarnation (older store files have none).
  for (auto& grid : loaded) {
    if (grid->incarnation.empty()) grid = WithIncarnation(*grid, NewIncarnation());
    grids_.emplace(grid->id, std::move(grid));
  }
}

absl::Status MemoryStore::Missing(const std::string& id) const {
  if (const auto it = damaged_grids_.find(id); it != damaged_grids_.end()) {
    return absl::DataLossError(absl::StrCat(
        "grids/", id, " was damaged on disk (", it->second,
        "): the server set it aside at a start (its log names the directory in the store's "
        "corrupt/); delete grids/",
        id, " to use the id again, or import it from an export"));
  }
  return absl::NotFoundError(absl::StrCat("grids/", id, " not found"));
}

std::shared_ptr<std::mutex> MemoryStore::WriterOf(const std::string& id) {
  std::lock_guard<std::mutex> lock(mu_);
  std::shared_ptr<std::mutex>& writer = writers_[id];
  if (!writer) writer = std::make_shared<std::mutex>();
  return writer;
}

absl::Status MemoryStore::Create(std::shared_ptr<const StoredGrid> grid) {
  grid = WithinRetention(std::move(grid), max_deform_revisions_);
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (grids_.contains(grid->id) || creating_.contains(grid->id)) {
      return absl::AlreadyExistsError(absl::StrCat("grids/", grid->id, " already exists"));
    }
    if (damaged_grids_.contains(grid->id)) {
      return absl::AlreadyExistsError(absl::StrCat(
          "grids/", grid->id, " already exists, damaged on disk: ", Missing(grid->id).message()));
    }
    if (!log_) {
      grids_.emplace(grid->id, WithIncarnation(*grid, NewIncarnation()));
      return absl::OkStatus();
    }
    creating_.insert(grid->id);
  }
  // The source points may take a while to write: outside the lock, the id held by creating_.
  // The incarnation is written with them, so that a restart keeps it.
  std::shared_ptr<const StoredGrid> created = WithIncarnation(*grid, NewIncarnation());
  const absl::Status written = log_->WriteGrid(*created);
  const std::string id = created->id;
  {
    std::lock_guard<std::mutex> lock(mu_);
    creating_.erase(id);
    if (written.ok()) {
      grids_.emplace(id, std::move(created));
      return absl::OkStatus();
    }
  }
  return LogWriteFailed(written, absl::StrCat("grids/", id));
}

absl::StatusOr<std::shared_ptr<const StoredGrid>> MemoryStore::Get(const std::string& id) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = grids_.find(id);
  if (it == grids_.end()) return Missing(id);
  return it->second;
}

absl::StatusOr<std::shared_ptr<const StoredGrid>> MemoryStore::AddRevision(
    const std::string& id, GridRevision revision, int64_t expected_latest,
    const std::string& incarnation) {
  const std::shared_ptr<std::mutex> writer = WriterOf(id);
  std::lock_guard<std::mutex> write(*writer);
  auto published = std::make_shared<GridRevision>(std::move(revision));
  {
    std::lock_guard<std::mutex> lock(mu_);
    const auto it = grids_.find(id);
    if (it == grids_.end()) {
      return absl::NotFoundError(absl::StrCat("grids/", id, " was deleted"));
    }
    if (!incarnation.empty() && it->second->incarnation != incarnation) {
      return ReplacedMeanwhile(id);
    }
    const auto& revisions = it->second->revisions;
    const int64_t latest = revisions.empty() ? 0 : revisions.back()->number;
    if (expected_latest != 0 && latest != expected_latest) {
      return absl::AbortedError(absl::StrCat("grids/", id, ": base_revision ", expected_latest,
                                             " is stale; the latest revision is ", latest));
    }
    // Past a damaged revision too: its number stays taken (a client may have been given it).
    const auto& damaged = it->second->damaged_revisions;
    published->number = std::max(latest, damaged.empty() ? 0 : damaged.back()) + 1;
  }
  // Only this writer changes the grid's revisions, so the number stays free while it is written.
  if (log_) {
    if (absl::Status written = log_->WriteRevision(id, *published); !written.ok()) {
      return LogWriteFailed(written, absl::StrCat("grids/", id, " revision ", published->number));
    }
  }
  std::shared_ptr<const StoredGrid> replaced;  // released after the lock, with what it dropped
  std::shared_ptr<const StoredGrid> result;
  std::vector<int64_t> dropped;
  SubscriptionHub::Woken woken;
  {
    std::lock_guard<std::mutex> lock(mu_);
    const auto it = grids_.find(id);  // Delete takes the writer lock too: still here
    auto next = std::make_shared<StoredGrid>(*it->second);
    next->revisions.push_back(published);
    dropped = DeformRevisionsBeyond(next->revisions, max_deform_revisions_);
    if (!dropped.empty()) {
      std::erase_if(next->revisions, [&](const std::shared_ptr<const GridRevision>& r) {
        return std::find(dropped.begin(), dropped.end(), r->number) != dropped.end();
      });
    }
    replaced = std::move(it->second);
    it->second = next;
    result = std::move(next);
    woken = hub_.Publish(id, RevisionSummary::Of(*published));
  }
  SubscriptionHub::Wake(woken);
  if (log_ && !dropped.empty()) log_->DropRevisions(id, dropped);
  return result;
}

absl::Status MemoryStore::Delete(const std::string& id, const DeleteCheck& check) {
  const std::shared_ptr<std::mutex> writer = WriterOf(id);
  std::lock_guard<std::mutex> write(*writer);
  std::string owner;
  bool damaged = false;
  {
    std::lock_guard<std::mutex> lock(mu_);
    const auto it = grids_.find(id);
    if (it == grids_.end() && !damaged_grids_.contains(id)) {
      writers_.erase(id);
      return Missing(id);
    }
    damaged = it == grids_.end();
    if (!damaged) owner = it->second->owner;  // a damaged grid's owner is unknown: admins only
  }
  // Under the grid's writer lock: no one deletes or creates it meanwhile.
  if (check) SG_RETURN_IF_ERROR(check(owner));
  if (damaged) {
    if (absl::Status forgotten = log_->ForgetDamagedGrid(id); !forgotten.ok()) {
      return LogWriteFailed(forgotten, absl::StrCat("grids/", id),
                            "it was not deleted and is still reported damaged");
    }
    std::lock_guard<std::mutex> lock(mu_);
    damaged_grids_.erase(id);
    writers_.erase(id);
    return absl::OkStatus();
  }
  if (log_) {
    if (absl::Status deleted = log_->DeleteGrid(id); !deleted.ok()) {
      return LogWriteFailed(deleted, absl::StrCat("grids/", id),
                            "it was not deleted and is still served");
    }
  }
  std::shared_ptr<const StoredGrid> removed;  // released after the lock
  SubscriptionHub::Woken ended;
  {
    std::lock_guard<std::mutex> lock(mu_);
    const auto it = grids_.find(id);
    removed = std::move(it->second);
    grids_.erase(it);
    writers_.erase(id);
    ended = hub_.EndGrid(id);
  }
  SubscriptionHub::Wake(ended);
  return absl::OkStatus();
}

absl::StatusOr<GridStore::Watch> MemoryStore::Subscribe(const std::string& id,
                                                        std::weak_ptr<GridWatcher> watcher,
                                                        size_t max_queued) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = grids_.find(id);
  if (it == grids_.end()) return Missing(id);
  const auto& revisions = it->second->revisions;
  auto subscription = std::make_shared<GridSubscription>(
      std::move(watcher), max_queued, revisions.empty() ? 0 : revisions.back()->number);
  if (absl::Status added = hub_.Add(id, subscription); !added.ok()) return added;
  return Watch{it->second, std::move(subscription)};
}

void MemoryStore::Unsubscribe(const std::string& id, const GridSubscription* subscription) {
  hub_.Remove(id, subscription);
}

void MemoryStore::CloseSubscriptions() { SubscriptionHub::Wake(hub_.CloseAll()); }

absl::StatusOr<std::vector<std::shared_ptr<const StoredGrid>>> MemoryStore::List(
    const std::string& after, int limit, bool* more) {
  std::vector<std::shared_ptr<const StoredGrid>> page;
  std::lock_guard<std::mutex> lock(mu_);
  auto it = grids_.upper_bound(after);
  for (; it != grids_.end() && static_cast<int>(page.size()) < limit; ++it) {
    page.push_back(it->second);
  }
  *more = it != grids_.end();
  return page;
}

absl::StatusOr<GridStore::Counts> MemoryStore::Count() {
  Counts counts;
  counts.revisions = 0;
  std::lock_guard<std::mutex> lock(mu_);
  for (const auto& [id, grid] : grids_) {
    ++counts.grids;
    *counts.revisions += static_cast<int64_t>(grid->revisions.size());
  }
  return counts;
}

absl::Status MemoryStore::LogWriteFailed(const absl::Status& error, const std::string& what,
                                         const char* outcome) const {
  std::fprintf(stderr, "splinegrid: store: %s failed: %s\n", what.c_str(),
               std::string(error.message()).c_str());
  {
    std::lock_guard<std::mutex> lock(log_health_mu_);
    log_failure_ = absl::UnavailableError(absl::StrCat("cannot write: ", error.message()));
    last_probe_ = absl::Now();
    ++failures_;
  }
  // The file system's own words (after the path the message names first): the caller gets no
  // server paths.
  const absl::string_view message = error.message();
  const size_t colon = message.rfind(": ");
  const absl::string_view cause =
      colon == std::string_view::npos ? message : message.substr(colon + 2);
  const absl::StatusCode code = error.code() == absl::StatusCode::kResourceExhausted
                                    ? absl::StatusCode::kResourceExhausted
                                    : absl::StatusCode::kUnavailable;
  return absl::Status(code, absl::StrCat(what, ": the server's store could not be written (", cause,
                                         "); ", outcome));
}

absl::Status MemoryStore::Available() const {
  if (!log_) return absl::OkStatus();
  int64_t failures = 0;
  {
    std::lock_guard<std::mutex> lock(log_health_mu_);
    if (log_failure_.ok() || probing_ || absl::Now() - last_probe_ < absl::Seconds(1)) {
      return log_failure_;
    }
    last_probe_ = absl::Now();
    probing_ = true;
    failures = failures_;
  }
  // Outside the lock: a slow disk holds up only this caller (the health thread).
  const absl::Status probe = log_->Probe();
  std::lock_guard<std::mutex> lock(log_health_mu_);
  probing_ = false;
  if (failures_ == failures) {  // no write failed meanwhile (that failure would stand)
    log_failure_ = probe.ok()
                       ? absl::OkStatus()
                       : absl::UnavailableError(absl::StrCat("cannot write: ", probe.message()));
  }
  return log_failure_;
}

}  // namespace splinegrid::server
