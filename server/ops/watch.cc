#include "server/ops/watch.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid::server::ops {

namespace {

int64_t NumberOf(int64_t number) { return number; }
int64_t NumberOf(const std::shared_ptr<const GridRevision>& revision) { return revision->number; }

// A watch that asks for the revisions after `after_revision` must not silently miss some:
// OUT_OF_RANGE when retention dropped one of them (a client resuming after a long absence, or
// asking for an old number). Damaged revisions are never sent and are not counted.
absl::Status CheckNoneDropped(const StoredGrid& grid, int64_t after_revision) {
  if (grid.revisions.empty()) return absl::OkStatus();
  const auto& kept = grid.revisions;
  const auto& damaged = grid.damaged_revisions;  // never sent, so not missed
  const int64_t latest = kept.back()->number;
  auto by_number = [](const auto& a, const auto& b) { return NumberOf(a) < NumberOf(b); };
  const auto kept_after = std::upper_bound(kept.begin(), kept.end(), after_revision, by_number);
  const auto damaged_after = std::upper_bound(damaged.begin(), damaged.end(), after_revision);
  const auto damaged_end = std::upper_bound(damaged_after, damaged.end(), latest);
  const int64_t dropped =
      latest - after_revision - (kept.end() - kept_after) - (damaged_end - damaged_after);
  if (dropped <= 0) return absl::OkStatus();
  // The newest number that is neither kept nor damaged: a walk down past at most the kept and
  // damaged numbers above it.
  int64_t newest_dropped = latest;
  while (std::binary_search(kept_after, kept.end(), newest_dropped, by_number) ||
         std::binary_search(damaged_after, damaged_end, newest_dropped)) {
    --newest_dropped;
  }
  return absl::OutOfRangeError(absl::StrCat(
      "after_revision = ", after_revision, ": grids/", grid.id, " no longer keeps ", dropped,
      " of the revisions after it (dropped by retention, which keeps the fit, faired revisions "
      "and the newest deformed ones; the newest dropped is ",
      newest_dropped, "); watch with after_revision = ", newest_dropped,
      " for those after it, or 0 for every revision kept"));
}

}  // namespace

absl::StatusOr<std::unique_ptr<RevisionFeed>> RevisionFeed::Open(const OpsContext& context,
                                                                 std::string grid_id,
                                                                 int64_t after_revision,
                                                                 std::weak_ptr<GridWatcher> watcher,
                                                                 size_t max_lag) {
  if (after_revision < -1) {
    return absl::InvalidArgumentError(
        absl::StrCat("after_revision = ", after_revision,
                     " is below -1 (0: every stored revision, -1: only new ones)"));
  }
  SG_ASSIGN_OR_RETURN(GridStore::Watch watch,
                      context.store.Subscribe(grid_id, std::move(watcher), max_lag));
  std::unique_ptr<RevisionFeed> feed(
      new RevisionFeed(context.store, std::move(grid_id), after_revision, max_lag));
  feed->subscription_ = std::move(watch.subscription);
  const auto& stored = watch.snapshot->revisions;
  if (after_revision > 0) {
    SG_RETURN_IF_ERROR(CheckNoneDropped(*watch.snapshot, after_revision));
  }
  if (after_revision >= 0) {
    feed->last_taken_ = after_revision;
    for (const auto& revision : stored) {
      if (revision->number > after_revision) {
        feed->backlog_.push_back(RevisionSummary::Of(*revision));
      }
    }
  } else {
    feed->last_taken_ = stored.empty() ? 0 : stored.back()->number;
  }
  feed->begins_after_ = feed->last_taken_;
  feed->incarnation_ = watch.snapshot->incarnation;
  return feed;
}

std::optional<RevisionSummary> RevisionFeed::Next() {
  if (ended_) return std::nullopt;
  RevisionSummary revision;
  if (!backlog_.empty()) {
    revision = backlog_.front();
    backlog_.pop_front();
  } else {
    GridSubscription::End end = GridSubscription::End::kOpen;
    bool found = false;
    while (!found && subscription_->Next(&revision, &end)) {
      found = revision.number > after_;  // after_ may lie beyond the latest at the start
    }
    if (!found) {
      switch (end) {
        case GridSubscription::End::kOpen:  // nothing new yet
          return std::nullopt;
        case GridSubscription::End::kGridDeleted:
          break;
        case GridSubscription::End::kLagged:
          end_status_ = absl::ResourceExhaustedError(absl::StrCat(
              "the client fell more than ", max_lag_, " revisions behind grids/", grid_id_,
              " and the watch was ended; watch again with after_revision = ", last_taken_));
          break;
        case GridSubscription::End::kClosed:
          end_status_ = absl::UnavailableError("the server is shutting down");
          break;
      }
      ended_ = true;  // the owner closes the subscription (outside its own locks)
      return std::nullopt;
    }
  }
  last_taken_ = revision.number;
  return revision;
}

void RevisionFeed::Close() {
  ended_ = true;
  if (subscription_) store_.Unsubscribe(grid_id_, subscription_.get());
  subscription_.reset();
}

}  // namespace splinegrid::server::ops
