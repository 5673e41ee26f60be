// The watches of a store's grids: which subscriptions each grid has, and telling them of new
// revisions, the grid's deletion or the server's shutdown. Every backend uses one; the memory
// store publishes under its own lock (so events come in snapshot order), the Redis store from
// the thread that reads the grids' event streams (in stream order).
//
// Publish, EndGrid and CloseAll return the subscriptions to wake: call Wake on them after
// releasing any lock of the caller (a watcher must never be called under a store's lock).
#ifndef SPLINEGRID_SERVER_STORE_SUBSCRIPTION_HUB_H_
#define SPLINEGRID_SERVER_STORE_SUBSCRIPTION_HUB_H_

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "server/grid_store.h"

namespace splinegrid::server {

class SubscriptionHub {
 public:
  using Woken = std::vector<std::shared_ptr<GridSubscription>>;

  // Adds `subscription` to grid `id`; UNAVAILABLE after CloseAll.
  absl::Status Add(const std::string& id, std::shared_ptr<GridSubscription> subscription);
  void Remove(const std::string& id, const GridSubscription* subscription);

  // Queues `revision` on grid `id`'s subscriptions; one that lags too far ends (kLagged) and
  // leaves.
  Woken Publish(const std::string& id, const RevisionSummary& revision);
  // Ends grid `id`'s subscriptions with kGridDeleted.
  Woken EndGrid(const std::string& id);
  // Ends every subscription (kClosed) and refuses new ones.
  Woken CloseAll();

  // The grids with at least one subscription.
  std::vector<std::string> WatchedGrids() const;
  bool closed() const;

  static void Wake(const Woken& woken) {
    for (const auto& subscription : woken) subscription->Wake();
  }

 private:
  mutable std::mutex mu_;  // after the store's lock, before any GridSubscription::mu_
  std::map<std::string, std::vector<std::shared_ptr<GridSubscription>>> subscriptions_;
  bool closed_ = false;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_STORE_SUBSCRIPTION_HUB_H_
