#include "server/ops/watch.h"

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid::server::ops {

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
