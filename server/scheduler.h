// The worker threads that run the service's numerics, and the policy that orders their work.
// RPC handlers hand their work here so that gRPC's threads never compute.
//
// Policy (issue 12.3: one client's queued fits must not delay another's quick calls):
//  - Two kinds of task. Cheap tasks (lookups, point evaluations, small grid evaluations) wait
//    in one FIFO queue and always go before long ones (fits, fairing, generation, imports,
//    large evaluations). Nothing preempts a running task.
//  - Long tasks run only on the first `max_running_long` workers (default threads - 1, at
//    least 1); the other workers run cheap tasks only. So with 2 or more threads a worker is
//    always free for cheap work, and since the kernel's fits are single-threaded, a core too.
//    The long-capable workers also run at a lower CPU priority (`long_worker_nice`), so cheap
//    work wins the CPU when the cores are shared (gRPC's threads, other processes).
//  - Long tasks are taken round-robin across principals: each principal has its own FIFO
//    queue, and a ring of the principals with queued long tasks gives the next task to the one
//    at the front, which then goes to the back. A principal with 40 queued fits delays another
//    principal's newly queued fit by the running fits and at most one more of its own (it may
//    be at the front of the ring), not by its whole queue. Turns count tasks, not CPU time.
//  - Slices: a long call that runs as a series of short tasks, each bounded to a few
//    milliseconds (the chunks of a large grid evaluation, produced at the pace the network takes
//    them), submits them as slices. They take turns across principals as long tasks do (a ring
//    of their own), and any worker takes one when no cheap task waits: so a coupling solver's
//    evaluation of a few hundred thousand points goes on while another principal's fit holds
//    the long workers for seconds, and a cheap call waits for at most one slice.
//  - Limits, refused at submission with RESOURCE_EXHAUSTED naming the limit: every waiting
//    task (`max_queued_tasks`), and the waiting long tasks of one principal that start a call
//    (`max_queued_long_calls_per_principal`; a continuation of an admitted call, such as the
//    next chunks of a streamed evaluation, counts only towards `max_queued_tasks`, so that an
//    admitted call is not cut off midway).
// The cost of a submission or a take is O(1) (hash map + deques) under one mutex.
#ifndef SPLINEGRID_SERVER_SCHEDULER_H_
#define SPLINEGRID_SERVER_SCHEDULER_H_

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/status/status.h"

namespace splinegrid::server {

// How a task is scheduled: see the policy above.
enum class WorkKind { kCheap, kLong, kSlice };

// Whether a task starts a call (subject to the per-principal limit) or continues an admitted
// one.
enum class Admission { kNewCall, kContinuation };

struct SchedulerOptions {
  // Worker threads (>= 1).
  int threads = 1;
  // Long tasks running at once, in [1, threads]; 0: threads - 1, at least 1.
  int max_running_long = 0;
  // Tasks (cheap and long) that may wait for a worker (>= 1).
  int max_queued_tasks = 4096;
  // Long tasks starting a call that one principal may have waiting (>= 1).
  int max_queued_long_calls_per_principal = 8;
  // Nice value (Linux, 0-19) of the workers that may run long tasks; 0 leaves them alone. Not
  // applied when every worker may run long tasks (then nothing would be favoured).
  int long_worker_nice = 5;
};

class Scheduler {
 public:
  // Starts the workers.
  explicit Scheduler(const SchedulerOptions& options);
  // Stop().
  ~Scheduler();
  Scheduler(const Scheduler&) = delete;
  Scheduler& operator=(const Scheduler&) = delete;

  // Queues `task` of `principal` (who is charged for it) as `kind`. RESOURCE_EXHAUSTED naming
  // the limit when a queue is full, UNAVAILABLE once stopped; the task is then dropped.
  absl::Status TrySubmit(const std::string& principal, WorkKind kind, std::function<void()> task,
                         Admission admission = Admission::kNewCall);

  // Refuses new tasks, runs the queued ones to the end and joins the workers. Idempotent.
  void Stop();

  int num_threads() const { return static_cast<int>(threads_.size()); }
  int max_running_long() const { return max_running_long_; }

  // Tasks waiting for a worker now, for the metrics endpoint (takes the lock: not for hot paths).
  struct QueueLengths {
    int cheap = 0;
    int long_tasks = 0;                                          // long tasks and slices
    std::vector<std::pair<std::string, int>> long_by_principal;  // principals with any waiting
  };
  QueueLengths queue_lengths() const;

 private:
  struct FairTask {
    std::function<void()> run;
    bool counted;  // towards the principal's max_queued_long_calls_per_principal
  };
  struct PrincipalQueue {
    std::deque<FairTask> tasks;
    int counted = 0;  // tasks with `counted`
  };
  // Tasks that take turns across principals: a FIFO per principal and a ring of the principals
  // with queued tasks, next first.
  struct FairQueue {
    absl::flat_hash_map<std::string, PrincipalQueue> queues;
    std::deque<std::string> ring;
    bool empty() const { return ring.empty(); }
    // The next task of the principal at the front of the ring, which goes to the back.
    std::function<void()> Take();
  };

  // A worker's loop; it takes long tasks only when `may_run_long`.
  void Run(bool may_run_long);
  // Whether a worker has a task it may run.
  bool HasWorkLocked(bool may_run_long) const;
  // The next task for a worker (cheap first, then long ones when it may run them, then slices);
  // empty when there is none it may run.
  std::function<void()> TakeLocked(bool may_run_long);

  const SchedulerOptions options_;
  const int max_running_long_;
  mutable std::mutex mu_;
  std::condition_variable cheap_cv_;  // waited on by cheap-only workers
  std::condition_variable any_cv_;    // waited on by long-capable workers
  std::deque<std::function<void()>> cheap_;
  FairQueue long_;
  FairQueue slices_;
  int queued_ = 0;  // cheap, long and slices waiting
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_SCHEDULER_H_
