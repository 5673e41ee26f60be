// A fixed set of threads running submitted tasks from a bounded queue. RPC handlers hand their
// numerics to the pool so that gRPC's threads never compute; a full queue is reported to the
// caller (RESOURCE_EXHAUSTED) instead of queueing without bound.
#ifndef SPLINEGRID_SERVER_WORKER_POOL_H_
#define SPLINEGRID_SERVER_WORKER_POOL_H_

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace splinegrid::server {

// How a task is scheduled: cheap tasks (lookups, point evaluations, small grid evaluations)
// must never wait behind long ones (fits, fairing, generation, large evaluations).
enum class WorkKind { kCheap, kLong };

class WorkerPool {
 public:
  // Starts `threads` workers (>= 1); at most `max_queued` tasks wait at any time.
  WorkerPool(int threads, int max_queued);
  // Stop().
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  // Queues `task` of `principal` (who is charged for it) and `kind`; false (and the task is
  // dropped) when the queue is full or the pool stopped.
  bool TrySubmit(const std::string& principal, WorkKind kind, std::function<void()> task);

  // Refuses new tasks, runs the queued ones to the end and joins the workers. Idempotent.
  void Stop();

  int num_threads() const { return static_cast<int>(threads_.size()); }

 private:
  void Run();

  const int max_queued_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> queue_;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_WORKER_POOL_H_
