#include "server/open_watches.h"

#include <algorithm>
#include <utility>

namespace splinegrid::server {

void OpenWatches::Add(std::weak_ptr<GridWatcher> watcher) {
  std::lock_guard<std::mutex> lock(mu_);
  // Amortised O(1): the expired ones go whenever the list has doubled since the last sweep.
  if (watchers_.size() >= sweep_at_) {
    std::erase_if(watchers_, [](const std::weak_ptr<GridWatcher>& w) { return w.expired(); });
    sweep_at_ = std::max<size_t>(64, 2 * watchers_.size());
  }
  watchers_.push_back(std::move(watcher));
}

void OpenWatches::WakeAll() {
  std::vector<std::shared_ptr<GridWatcher>> alive;
  {
    std::lock_guard<std::mutex> lock(mu_);
    std::erase_if(watchers_, [](const std::weak_ptr<GridWatcher>& w) { return w.expired(); });
    for (const std::weak_ptr<GridWatcher>& watcher : watchers_) {
      if (std::shared_ptr<GridWatcher> locked = watcher.lock()) alive.push_back(std::move(locked));
    }
  }
  for (const std::shared_ptr<GridWatcher>& watcher : alive) watcher->Wake();
}

}  // namespace splinegrid::server
