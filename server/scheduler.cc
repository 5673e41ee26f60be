#include "server/scheduler.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>

#include "absl/strings/str_cat.h"

namespace splinegrid::server {
namespace {

int MaxRunningLong(const SchedulerOptions& options) {
  const int threads = std::max(options.threads, 1);
  if (options.max_running_long > 0) return std::min(options.max_running_long, threads);
  return std::max(threads - 1, 1);
}

// Lowers the calling thread's CPU priority (Linux: the nice value is per thread).
void NiceThisThread(int nice) {
  if (nice > 0) setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), nice);
}

}  // namespace

Scheduler::Scheduler(const SchedulerOptions& options)
    : options_(options), max_running_long_(MaxRunningLong(options)) {
  const int threads = std::max(options.threads, 1);
  const int nice = max_running_long_ < threads ? options.long_worker_nice : 0;
  threads_.reserve(threads);
  for (int i = 0; i < threads; ++i) {
    const bool may_run_long = i < max_running_long_;
    threads_.emplace_back([this, may_run_long, nice] {
      if (may_run_long) NiceThisThread(nice);
      Run(may_run_long);
    });
  }
}

Scheduler::~Scheduler() { Stop(); }

void Scheduler::Stop() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stopping_ = true;
  }
  cheap_cv_.notify_all();
  any_cv_.notify_all();
  for (std::thread& t : threads_) {
    if (t.joinable()) t.join();
  }
}

absl::Status Scheduler::TrySubmit(const std::string& principal, WorkKind kind,
                                  std::function<void()> task, Admission admission) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (stopping_) return absl::UnavailableError("the server is shutting down");
    if (queued_ >= options_.max_queued_tasks) {
      return absl::ResourceExhaustedError(absl::StrCat("the server is busy: ", queued_,
                                                       " tasks wait for a worker (limit "
                                                       "max_queued_tasks = ",
                                                       options_.max_queued_tasks,
                                                       "); retry later"));
    }
    if (kind == WorkKind::kCheap) {
      cheap_.push_back(std::move(task));
    } else {
      FairQueue& fair = kind == WorkKind::kLong ? long_ : slices_;
      PrincipalQueue& queue = fair.queues[principal];
      const bool counted = kind == WorkKind::kLong && admission == Admission::kNewCall;
      if (counted && queue.counted >= options_.max_queued_long_calls_per_principal) {
        if (queue.tasks.empty()) fair.queues.erase(principal);
        return absl::ResourceExhaustedError(absl::StrCat(
            "this caller already has ", queue.counted,
            " long calls waiting (limit "
            "max_queued_long_calls_per_principal = ",
            options_.max_queued_long_calls_per_principal, "); retry when one has finished"));
      }
      if (queue.tasks.empty()) fair.ring.push_back(principal);
      queue.tasks.push_back({std::move(task), counted});
      queue.counted += counted ? 1 : 0;
    }
    ++queued_;
  }
  // A cheap task or a slice may go to either kind of worker: wake one of each (the one that
  // finds nothing sleeps again); a long task only to a long-capable one.
  if (kind != WorkKind::kLong) cheap_cv_.notify_one();
  any_cv_.notify_one();
  return absl::OkStatus();
}

std::function<void()> Scheduler::FairQueue::Take() {
  std::string principal = std::move(ring.front());
  ring.pop_front();
  auto it = queues.find(principal);
  PrincipalQueue& queue = it->second;
  std::function<void()> task = std::move(queue.tasks.front().run);
  queue.counted -= queue.tasks.front().counted ? 1 : 0;
  queue.tasks.pop_front();
  if (queue.tasks.empty()) {
    queues.erase(it);
  } else {
    ring.push_back(std::move(principal));
  }
  return task;
}

bool Scheduler::HasWorkLocked(bool may_run_long) const {
  return !cheap_.empty() || (may_run_long && !long_.empty()) || !slices_.empty();
}

std::function<void()> Scheduler::TakeLocked(bool may_run_long) {
  std::function<void()> task;
  if (!cheap_.empty()) {
    task = std::move(cheap_.front());
    cheap_.pop_front();
  } else if (may_run_long && !long_.empty()) {
    task = long_.Take();
  } else if (!slices_.empty()) {
    task = slices_.Take();
  } else {
    return task;
  }
  --queued_;
  return task;
}

void Scheduler::Run(bool may_run_long) {
  std::condition_variable& cv = may_run_long ? any_cv_ : cheap_cv_;
  for (;;) {
    std::function<void()> task;
    {
      std::unique_lock<std::mutex> lock(mu_);
      cv.wait(lock, [&] { return stopping_ || HasWorkLocked(may_run_long); });
      task = TakeLocked(may_run_long);
      if (!task) return;  // stopping, and nothing left this worker may run
    }
    task();
  }
}

Scheduler::QueueLengths Scheduler::queue_lengths() const {
  std::lock_guard<std::mutex> lock(mu_);
  QueueLengths lengths;
  lengths.cheap = static_cast<int>(cheap_.size());
  absl::flat_hash_map<std::string, int> by_principal;
  for (const FairQueue* fair : {&long_, &slices_}) {
    for (const auto& [principal, queue] : fair->queues) {
      if (queue.tasks.empty()) continue;
      lengths.long_tasks += static_cast<int>(queue.tasks.size());
      by_principal[principal] += static_cast<int>(queue.tasks.size());
    }
  }
  lengths.long_by_principal.assign(by_principal.begin(), by_principal.end());
  return lengths;
}

}  // namespace splinegrid::server
