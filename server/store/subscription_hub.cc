#include "server/store/subscription_hub.h"

namespace splinegrid::server {

absl::Status SubscriptionHub::Add(const std::string& id,
                                  std::shared_ptr<GridSubscription> subscription) {
  std::lock_guard<std::mutex> lock(mu_);
  if (closed_) return absl::UnavailableError("the server is shutting down");
  subscriptions_[id].push_back(std::move(subscription));
  return absl::OkStatus();
}

void SubscriptionHub::Remove(const std::string& id, const GridSubscription* subscription) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto subs = subscriptions_.find(id);
  if (subs == subscriptions_.end()) return;
  std::erase_if(subs->second, [subscription](const std::shared_ptr<GridSubscription>& s) {
    return s.get() == subscription;
  });
  if (subs->second.empty()) subscriptions_.erase(subs);
}

SubscriptionHub::Woken SubscriptionHub::Publish(const std::string& id,
                                                const RevisionSummary& revision) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto subs = subscriptions_.find(id);
  if (subs == subscriptions_.end()) return {};
  Woken woken = subs->second;
  std::erase_if(subs->second, [&](const std::shared_ptr<GridSubscription>& subscription) {
    return !subscription->Push(revision);
  });
  if (subs->second.empty()) subscriptions_.erase(subs);
  return woken;
}

SubscriptionHub::Woken SubscriptionHub::EndGrid(const std::string& id) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto subs = subscriptions_.find(id);
  if (subs == subscriptions_.end()) return {};
  Woken ended = std::move(subs->second);
  subscriptions_.erase(subs);
  for (const auto& subscription : ended) subscription->Close(GridSubscription::End::kGridDeleted);
  return ended;
}

SubscriptionHub::Woken SubscriptionHub::CloseAll() {
  std::lock_guard<std::mutex> lock(mu_);
  closed_ = true;
  Woken ended;
  for (auto& [id, list] : subscriptions_) {
    for (auto& subscription : list) ended.push_back(std::move(subscription));
  }
  subscriptions_.clear();
  for (const auto& subscription : ended) subscription->Close(GridSubscription::End::kClosed);
  return ended;
}

std::vector<std::string> SubscriptionHub::WatchedGrids() const {
  std::lock_guard<std::mutex> lock(mu_);
  std::vector<std::string> ids;
  for (const auto& [id, list] : subscriptions_) ids.push_back(id);
  return ids;
}

bool SubscriptionHub::closed() const {
  std::lock_guard<std::mutex> lock(mu_);
  return closed_;
}

}  // namespace splinegrid::server
