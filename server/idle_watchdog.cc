#include "server/idle_watchdog.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <limits>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_set>
#include <vector>

#include "absl/strings/str_cat.h"

namespace splinegrid::server {
namespace internal {

int64_t SteadyNanos() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

struct IdleEntry {
  int64_t timeout_ns = 0;
  std::atomic<int64_t> deadline_ns{0};  // steady clock; moved on by Touch
  std::mutex mu;                        // held while on_idle runs, and by Stop
  std::function<void()> on_idle;        // guarded by mu; empty once run or stopped
};

}  // namespace internal

namespace {

using internal::IdleEntry;
using internal::SteadyNanos;

// The process's watchdog thread and the watches it keeps. Lock order: an entry's mu, then mu_
// (the thread never holds mu_ while it takes an entry's mu).
class Watchdog {
 public:
  static Watchdog& Get() {
    static Watchdog* const watchdog = new Watchdog();  // never destroyed: its thread runs on
    return *watchdog;
  }

  void Add(std::shared_ptr<IdleEntry> entry) {
    std::lock_guard<std::mutex> lock(mu_);
    entries_.insert(std::move(entry));
    if (!thread_.joinable()) thread_ = std::thread([this] { Run(); });
    cv_.notify_one();
  }

  void Remove(const std::shared_ptr<IdleEntry>& entry) {
    std::lock_guard<std::mutex> lock(mu_);
    entries_.erase(entry);
  }

 private:
  void Run() {
    std::unique_lock<std::mutex> lock(mu_);
    for (;;) {
      const int64_t now = SteadyNanos();
      int64_t next = std::numeric_limits<int64_t>::max();
      std::vector<std::shared_ptr<IdleEntry>> due;
      for (const std::shared_ptr<IdleEntry>& entry : entries_) {
        const int64_t deadline = entry->deadline_ns.load(std::memory_order_relaxed);
        if (deadline <= now) {
          due.push_back(entry);
        } else {
          next = std::min(next, deadline);
        }
      }
      if (!due.empty()) {
        for (const std::shared_ptr<IdleEntry>& entry : due) entries_.erase(entry);
        lock.unlock();
        for (const std::shared_ptr<IdleEntry>& entry : due) Fire(entry);
        lock.lock();
        continue;
      }
      if (next == std::numeric_limits<int64_t>::max()) {
        cv_.wait(lock);
      } else {
        cv_.wait_for(lock, std::chrono::nanoseconds(next - now));
      }
    }
  }

  // Runs the entry's callback unless it was stopped or touched since the scan.
  void Fire(const std::shared_ptr<IdleEntry>& entry) {
    std::lock_guard<std::mutex> entry_lock(entry->mu);
    if (!entry->on_idle) return;
    if (entry->deadline_ns.load(std::memory_order_relaxed) > SteadyNanos()) {
      Add(entry);  // touched after the scan: watch on
      return;
    }
    std::function<void()> on_idle = std::move(entry->on_idle);
    entry->on_idle = nullptr;
    on_idle();
  }

  std::mutex mu_;
  std::condition_variable cv_;
  std::unordered_set<std::shared_ptr<IdleEntry>> entries_;
  std::thread thread_;
};

}  // namespace

IdleWatch& IdleWatch::operator=(IdleWatch&& other) noexcept {
  if (this != &other) {
    Stop();
    entry_ = std::move(other.entry_);
  }
  return *this;
}

IdleWatch::~IdleWatch() { Stop(); }

void IdleWatch::Start(absl::Duration timeout, std::function<void()> on_idle) {
  Stop();
  if (timeout <= absl::ZeroDuration()) return;
  entry_ = std::make_shared<IdleEntry>();
  // At most ~3 years, so that now + timeout cannot overflow.
  entry_->timeout_ns = std::min<int64_t>(absl::ToInt64Nanoseconds(timeout), int64_t{1} << 56);
  entry_->deadline_ns.store(SteadyNanos() + entry_->timeout_ns);
  entry_->on_idle = std::move(on_idle);
  Watchdog::Get().Add(entry_);
}

void IdleWatch::Touch() {
  if (entry_) {
    entry_->deadline_ns.store(SteadyNanos() + entry_->timeout_ns, std::memory_order_relaxed);
  }
}

void IdleWatch::Stop() {
  if (!entry_) return;
  {
    std::lock_guard<std::mutex> lock(entry_->mu);
    entry_->on_idle = nullptr;
  }
  Watchdog::Get().Remove(entry_);
  entry_.reset();
}

absl::Status IdleTimeoutError(std::string_view call, absl::Duration timeout) {
  return absl::DeadlineExceededError(absl::StrCat(
      std::string(call), " received no message for ", absl::FormatDuration(timeout),
      ", the limit for a quiet stream (flag --import_idle_timeout); what arrived is discarded"));
}

}  // namespace splinegrid::server
