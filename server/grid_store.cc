#include "server/grid_store.h"

#include <algorithm>

#include "absl/strings/str_cat.h"

namespace splinegrid::server {

int64_t GridRevision::num_control_points() const {
  int64_t n = 0;
  for (const BlockFit& b : blocks) n += b.fitted.summary.num_control_points;
  return n;
}

double GridRevision::max_deviation() const {
  double m = 0.0;
  for (const BlockFit& b : blocks) m = std::max(m, b.fitted.summary.deviation.max);
  return m;
}

RevisionSummary RevisionSummary::Of(const GridRevision& revision) {
  RevisionSummary s;
  s.number = revision.number;
  s.create_time = revision.create_time;
  s.origin = revision.origin;
  s.parent = revision.parent;
  s.time = revision.time;
  s.step = revision.step;
  return s;
}

namespace {

// Whether retention dropped revisions of `grid`: numbers are consecutive from 1 and the latest
// is never dropped, so fewer revisions than the latest number means some were.
bool DroppedSome(const StoredGrid& grid) {
  return !grid.revisions.empty() &&
         static_cast<int64_t>(grid.revisions.size()) < grid.revisions.back()->number;
}

}  // namespace

absl::StatusOr<std::shared_ptr<const GridRevision>> StoredGrid::FindRevision(int64_t number) const {
  if (revisions.empty()) {
    return absl::FailedPreconditionError(
        absl::StrCat("grids/", id, " has no revision yet; call FitGrid first"));
  }
  if (number == 0) return revisions.back();
  const auto it = std::lower_bound(
      revisions.begin(), revisions.end(), number,
      [](const std::shared_ptr<const GridRevision>& r, int64_t n) { return r->number < n; });
  if (it != revisions.end() && (*it)->number == number) return *it;
  const int64_t latest = revisions.back()->number;
  if (number > 0 && number < latest) {
    return absl::NotFoundError(absl::StrCat(
        "grids/", id, " revision ", number,
        " was dropped by retention: a grid keeps its fitted and faired revisions and only its "
        "newest deformed ones (server flag --keep_revisions); the latest is ",
        latest));
  }
  return absl::NotFoundError(
      absl::StrCat("grids/", id, " has no revision ", number, " (latest is ", latest, ")"));
}

absl::StatusOr<std::shared_ptr<const GridRevision>> StoredGrid::FindRevision(
    int64_t number, std::optional<int64_t> step) const {
  if (!step) return FindRevision(number);
  if (number != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("revision = ", number, " and step = ", *step, " are both given; give one"));
  }
  for (auto it = revisions.rbegin(); it != revisions.rend(); ++it) {
    if ((*it)->origin == RevisionOrigin::kDeform && (*it)->step == *step) return *it;
  }
  return absl::NotFoundError(absl::StrCat(
      "grids/", id, " has no revision of step ", *step,
      DroppedSome(*this) ? " (older deformed revisions were dropped by retention)" : ""));
}

bool GridSubscription::Next(RevisionSummary* revision, End* end) {
  std::lock_guard<std::mutex> lock(mu_);
  if (end_ == End::kLagged || end_ == End::kClosed || queue_.empty()) {
    *end = end_;
    return false;
  }
  *revision = queue_.front();
  queue_.pop_front();
  return true;
}

bool GridSubscription::Push(const RevisionSummary& revision) {
  std::lock_guard<std::mutex> lock(mu_);
  if (end_ != End::kOpen) return false;
  if (queue_.size() >= max_queued_) {
    end_ = End::kLagged;
    queue_.clear();
    return false;
  }
  queue_.push_back(revision);
  return true;
}

void GridSubscription::Close(End end) {
  std::lock_guard<std::mutex> lock(mu_);
  if (end_ != End::kOpen) return;
  end_ = end;
  if (end != End::kGridDeleted) queue_.clear();
}

void GridSubscription::Wake() const {
  if (const std::shared_ptr<GridWatcher> watcher = watcher_.lock()) watcher->Wake();
}

int64_t FittedBlockBytes(const FittedBlock& block) {
  int64_t bytes = static_cast<int64_t>(block.spline.control().size()) * sizeof(double);
  for (int d = 0; d < 3; ++d) {
    bytes += static_cast<int64_t>(block.spline.knots(d).knots().size() +
                                  2 * block.distribution.params(d).size()) *
             sizeof(double);
  }
  return bytes + static_cast<int64_t>(sizeof(FittedBlock));
}

int64_t RevisionBytes(const GridFit& fit) {
  int64_t bytes = 0;
  for (const BlockFit& block : fit.blocks) {
    bytes += FittedBlockBytes(block.fitted) + static_cast<int64_t>(sizeof(BlockFit)) +
             static_cast<int64_t>(block.quality.bad_cells.size() * sizeof(Extents));
  }
  for (const std::vector<uint8_t>& kinds : fit.kinds.point_kinds) {
    bytes += static_cast<int64_t>(kinds.size());
  }
  return bytes;
}

absl::Status GridStore::Create(std::shared_ptr<const StoredGrid> grid) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto [it, inserted] = grids_.emplace(grid->id, grid);
  if (!inserted) {
    return absl::AlreadyExistsError(absl::StrCat("grids/", grid->id, " already exists"));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::shared_ptr<const StoredGrid>> GridStore::Get(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = grids_.find(id);
  if (it == grids_.end()) return absl::NotFoundError(absl::StrCat("grids/", id, " not found"));
  return it->second;
}

absl::StatusOr<std::shared_ptr<const StoredGrid>> GridStore::AddRevision(const std::string& id,
                                                                         GridRevision revision,
                                                                         int64_t expected_latest) {
  auto published = std::make_shared<GridRevision>(std::move(revision));
  std::shared_ptr<const StoredGrid> replaced;  // released after the lock, with what it dropped
  std::vector<std::shared_ptr<GridSubscription>> woken;
  std::shared_ptr<const StoredGrid> result;
  {
    std::lock_guard<std::mutex> lock(mu_);
    const auto it = grids_.find(id);
    if (it == grids_.end()) {
      return absl::NotFoundError(absl::StrCat("grids/", id, " was deleted"));
    }
    const int64_t latest = it->second->revisions.empty() ? 0 : it->second->revisions.back()->number;
    if (expected_latest != 0 && latest != expected_latest) {
      return absl::AbortedError(absl::StrCat("grids/", id, ": base_revision ", expected_latest,
                                             " is stale; the latest revision is ", latest));
    }
    auto next = std::make_shared<StoredGrid>(*it->second);
    published->number = latest + 1;
    next->revisions.push_back(published);
    // Retention: drop the oldest deformed revisions beyond the newest max_deform_revisions_
    // (the one just published is the newest, so it stays, and so does the latest number).
    int64_t excess = -max_deform_revisions_;
    for (const auto& r : next->revisions) excess += r->origin == RevisionOrigin::kDeform;
    if (excess > 0) {
      std::vector<std::shared_ptr<const GridRevision>> kept;
      kept.reserve(next->revisions.size() - excess);
      for (auto& r : next->revisions) {
        if (r->origin == RevisionOrigin::kDeform && excess > 0) {
          --excess;
          continue;
        }
        kept.push_back(std::move(r));
      }
      next->revisions = std::move(kept);
    }
    replaced = std::move(it->second);
    it->second = next;
    result = std::move(next);
    if (const auto subs = subscriptions_.find(id); subs != subscriptions_.end()) {
      const RevisionSummary summary = RevisionSummary::Of(*published);
      std::vector<std::shared_ptr<GridSubscription>>& list = subs->second;
      // A watcher that lags too far is ended (kLagged) and leaves the list.
      woken = list;
      std::erase_if(list, [&](const std::shared_ptr<GridSubscription>& subscription) {
        return !subscription->Push(summary);
      });
      if (list.empty()) subscriptions_.erase(subs);
    }
  }
  for (const auto& subscription : woken) subscription->Wake();
  return result;
}

absl::Status GridStore::Delete(const std::string& id) {
  std::shared_ptr<const StoredGrid> removed;  // released after the lock
  std::vector<std::shared_ptr<GridSubscription>> ended;
  {
    std::lock_guard<std::mutex> lock(mu_);
    const auto it = grids_.find(id);
    if (it == grids_.end()) return absl::NotFoundError(absl::StrCat("grids/", id, " not found"));
    removed = std::move(it->second);
    grids_.erase(it);
    if (const auto subs = subscriptions_.find(id); subs != subscriptions_.end()) {
      ended = std::move(subs->second);
      subscriptions_.erase(subs);
    }
    for (const auto& subscription : ended) subscription->Close(GridSubscription::End::kGridDeleted);
  }
  for (const auto& subscription : ended) subscription->Wake();
  return absl::OkStatus();
}

absl::StatusOr<GridStore::Watch> GridStore::Subscribe(const std::string& id,
                                                      std::weak_ptr<GridWatcher> watcher,
                                                      size_t max_queued) {
  auto subscription = std::make_shared<GridSubscription>(std::move(watcher), max_queued);
  std::lock_guard<std::mutex> lock(mu_);
  if (closed_) return absl::UnavailableError("the server is shutting down");
  const auto it = grids_.find(id);
  if (it == grids_.end()) return absl::NotFoundError(absl::StrCat("grids/", id, " not found"));
  subscriptions_[id].push_back(subscription);
  return Watch{it->second, std::move(subscription)};
}

void GridStore::Unsubscribe(const std::string& id, const GridSubscription* subscription) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto subs = subscriptions_.find(id);
  if (subs == subscriptions_.end()) return;
  std::erase_if(subs->second, [subscription](const std::shared_ptr<GridSubscription>& s) {
    return s.get() == subscription;
  });
  if (subs->second.empty()) subscriptions_.erase(subs);
}

void GridStore::CloseSubscriptions() {
  std::vector<std::shared_ptr<GridSubscription>> ended;
  {
    std::lock_guard<std::mutex> lock(mu_);
    closed_ = true;
    for (auto& [id, list] : subscriptions_) {
      for (auto& subscription : list) ended.push_back(std::move(subscription));
    }
    subscriptions_.clear();
    for (const auto& subscription : ended) subscription->Close(GridSubscription::End::kClosed);
  }
  for (const auto& subscription : ended) subscription->Wake();
}

std::vector<std::shared_ptr<const StoredGrid>> GridStore::List(const std::string& after, int limit,
                                                               bool* more) const {
  std::vector<std::shared_ptr<const StoredGrid>> page;
  std::lock_guard<std::mutex> lock(mu_);
  auto it = grids_.upper_bound(after);
  for (; it != grids_.end() && static_cast<int>(page.size()) < limit; ++it) {
    page.push_back(it->second);
  }
  *more = it != grids_.end();
  return page;
}

}  // namespace splinegrid::server
