// The open WatchGrid calls of a server, so that a reload of the tokens file can wake each one to
// check its token again (a watch can be idle for hours; without a wake-up a removed token's
// watch would stay open until the next revision).
#ifndef SPLINEGRID_SERVER_OPEN_WATCHES_H_
#define SPLINEGRID_SERVER_OPEN_WATCHES_H_

#include <memory>
#include <mutex>
#include <vector>

#include "server/grid_store.h"

namespace splinegrid::server {

class OpenWatches {
 public:
  // Keeps `watcher` (weakly) until it is gone.
  void Add(std::weak_ptr<GridWatcher> watcher);
  // Wakes every watcher still alive (outside the lock) and forgets the others.
  void WakeAll();

 private:
  std::mutex mu_;
  std::vector<std::weak_ptr<GridWatcher>> watchers_;
  size_t sweep_at_ = 64;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_OPEN_WATCHES_H_
