// WatchGrid's operation: a grid's revisions in publication order, the stored ones first, then
// each new one as it is published, until the grid is deleted.
#ifndef SPLINEGRID_SERVER_OPS_WATCH_H_
#define SPLINEGRID_SERVER_OPS_WATCH_H_

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "server/ops/ops_context.h"

namespace splinegrid::server::ops {

// A subscription with the stored revisions still to be taken. Not thread-safe: its owner
// serialises the calls (the watcher's Wake may come on any thread).
class RevisionFeed {
 public:
  // Subscribes `watcher` to grid `grid_id`: the stored revisions above `after_revision` come
  // first (0: every one; -1: none, only new ones), then each published one, each once, none
  // missed. Errors: INVALID_ARGUMENT for after_revision below -1, NOT_FOUND for the grid,
  // UNAVAILABLE when the server is shutting down.
  static absl::StatusOr<std::unique_ptr<RevisionFeed>> Open(const OpsContext& context,
                                                            std::string grid_id,
                                                            int64_t after_revision,
                                                            std::weak_ptr<GridWatcher> watcher,
                                                            size_t max_lag);
  ~RevisionFeed() { Close(); }

  // The next revision; nullopt when there is nothing new yet or the feed has ended.
  std::optional<RevisionSummary> Next();
  // Whether it ended, and why: OK once the grid is deleted (after every revision stored before
  // the deletion was taken); RESOURCE_EXHAUSTED when more than max_lag revisions waited
  // (naming the revision to watch again after); UNAVAILABLE when the server shuts down.
  bool ended() const { return ended_; }
  // Where the feed began: revisions after this one are sent (the request's after_revision, or
  // for -1 the latest stored when it was opened).
  int64_t begins_after() const { return begins_after_; }
  // The creation of the grid id that is watched (StoredGrid::incarnation).
  const std::string& incarnation() const { return incarnation_; }
  const absl::Status& end_status() const { return end_status_; }

  // Stops the subscription (the feed ends); a no-op the second time. Takes the store's lock.
  void Close();

 private:
  RevisionFeed(GridStore& store, std::string grid_id, int64_t after, size_t max_lag)
      : store_(store), grid_id_(std::move(grid_id)), after_(after), max_lag_(max_lag) {}

  GridStore& store_;
  const std::string grid_id_;
  const int64_t after_;
  const size_t max_lag_;
  std::shared_ptr<GridSubscription> subscription_;
  std::deque<RevisionSummary> backlog_;  // the stored revisions not yet taken
  int64_t last_taken_ = 0;               // (or where the feed began)
  int64_t begins_after_ = 0;
  std::string incarnation_;
  bool ended_ = false;
  absl::Status end_status_;
};

}  // namespace splinegrid::server::ops

#endif  // SPLINEGRID_SERVER_OPS_WATCH_H_
