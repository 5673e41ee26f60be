// The in-memory store of grids and their immutable revisions.
//
// Everything a reader can reach is immutable and shared: a grid is a snapshot
// (shared_ptr<const StoredGrid>) that holds its source points and revisions by shared_ptr.
// Adding a revision publishes a new snapshot under a short lock, so a running fit never blocks
// readers, and a reader keeps its snapshot alive even if the grid is deleted meanwhile.
//
// Retention: when a revision is published, the deformed revisions (kDeform) beyond the newest
// max_deform_revisions of the grid leave the snapshot; fitted and faired ones always stay. A
// dropped revision's memory goes when its last reader lets go. Numbers are never reused.
//
// Watching: a GridSubscription receives the summaries of a grid's revisions in publication
// order, appended under the store's lock (so the order is the order of the snapshots), then the
// grid's deletion. Its GridWatcher is woken after the lock is released and takes the events
// from the subscription; the store never calls a watcher while it holds its lock.
#ifndef SPLINEGRID_SERVER_GRID_STORE_H_
#define SPLINEGRID_SERVER_GRID_STORE_H_

#include <cstddef>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "core/deform/deform_quality.h"
#include "core/fit/grid_fit.h"
#include "core/grid/structured_grid.h"
#include "server/memory_budget.h"

namespace splinegrid::server {

enum class RevisionOrigin {
  kFit,     // FitGrid
  kFair,    // FairGrid: a faired refit of a parent revision's spec
  kDeform,  // DeformGrid: a parent revision with part of its boundary moved
};

// What the quality gate of a deformation measured.
struct DeformSummary {
  DeformationCheck check;
  int moved_controls = 0;
  double decay_radius = 0.0;
  double seconds = 0.0;
};

// An immutable state of a grid's spline mapping.
struct GridRevision {
  int64_t number = 0;
  absl::Time create_time;
  RevisionOrigin origin = RevisionOrigin::kFit;
  GridFitOptions fit_options;  // provenance (kDeform: the parent's)
  int64_t parent = 0;          // kFair, kDeform: the revision it was made from
  double time = 0.0;           // kDeform: the solver's time and step
  int64_t step = 0;
  DeformSummary deform;  // kDeform
  std::vector<BlockFit> blocks;
  BoundaryKinds kinds;  // the boundary kinds the fit used (walls for curvature)
  GridFitReport report;
  MemoryReservation memory;  // the bytes this revision holds in the budget

  int64_t num_control_points() const;
  double max_deviation() const;
};

// A revision's entry in the grid's history: what it is, without its blocks.
struct RevisionSummary {
  int64_t number = 0;
  absl::Time create_time;
  RevisionOrigin origin = RevisionOrigin::kFit;
  int64_t parent = 0;
  double time = 0.0;  // kDeform
  int64_t step = 0;   // kDeform

  static RevisionSummary Of(const GridRevision& revision);
};

// The points a grid was imported from, with the budget they hold.
struct SourcePoints {
  MultiBlockGrid grid;
  Connectivity connectivity;  // found at import
  std::string format;         // how it arrived, e.g. "plot3d ascii 2d single-block"
  MemoryReservation memory;
};

// A snapshot of a grid resource.
struct StoredGrid {
  std::string id;  // grids/{id}
  std::string display_name;
  absl::Time create_time;
  std::shared_ptr<const SourcePoints> source;
  std::vector<std::shared_ptr<const GridRevision>> revisions;  // ascending numbers

  // The revision `number` (0: the latest), or NOT_FOUND (saying so when retention dropped it:
  // a missing number below the latest) / FAILED_PRECONDITION (none yet).
  absl::StatusOr<std::shared_ptr<const GridRevision>> FindRevision(int64_t number) const;
  // The revision `number`, or with `step` the latest deformed revision of that time step
  // (INVALID_ARGUMENT if both are given; NOT_FOUND if no revision has the step).
  absl::StatusOr<std::shared_ptr<const GridRevision>> FindRevision(
      int64_t number, std::optional<int64_t> step) const;
};

// The receiving end of a GridSubscription (implemented by the WatchGrid reactor).
class GridWatcher {
 public:
  virtual ~GridWatcher() = default;
  // Events were queued on the subscription, or it ended: take them with
  // GridSubscription::Next. Called on any thread, never under the store's lock, possibly more
  // than once per event (and after the events were taken); must not block.
  virtual void Wake() = 0;
};

// The events of one watched grid: its new revisions in publication order, then how the watch
// ended. Filled by the GridStore, drained by one watcher.
class GridSubscription {
 public:
  enum class End {
    kOpen,         // not ended
    kGridDeleted,  // the grid was deleted (after the revisions queued before)
    kLagged,       // more than max_queued revisions waited: the watcher falls too far behind
    kClosed,       // the store closed every subscription (server shutdown)
  };

  GridSubscription(std::weak_ptr<GridWatcher> watcher, size_t max_queued)
      : watcher_(std::move(watcher)), max_queued_(max_queued) {}

  // The next revision (true), or false and how the watch ended (kOpen: nothing queued now).
  // kLagged and kClosed come at once, dropping what is queued; kGridDeleted after the queue.
  bool Next(RevisionSummary* revision, End* end);

  size_t max_queued() const { return max_queued_; }

 private:
  friend class GridStore;
  // Queues `revision`; false (and the watch ends kLagged) when that would exceed max_queued.
  bool Push(const RevisionSummary& revision);
  void Close(End end);
  void Wake() const;

  const std::weak_ptr<GridWatcher> watcher_;
  const size_t max_queued_;
  std::mutex mu_;
  std::deque<RevisionSummary> queue_;
  End end_ = End::kOpen;
};

// Bytes a block's spline, point distribution and summary take in memory.
int64_t FittedBlockBytes(const FittedBlock& block);

// Bytes a revision made of `fit` takes: its blocks and boundary kinds.
int64_t RevisionBytes(const GridFit& fit);

class GridStore {
 public:
  // Keeps the newest `max_deform_revisions` (>= 1) deformed revisions of each grid.
  explicit GridStore(int max_deform_revisions) : max_deform_revisions_(max_deform_revisions) {}

  // Adds a new grid; ALREADY_EXISTS if the id is taken.
  absl::Status Create(std::shared_ptr<const StoredGrid> grid);

  // The current snapshot, or NOT_FOUND.
  absl::StatusOr<std::shared_ptr<const StoredGrid>> Get(const std::string& id) const;

  // Publishes `revision` (its number is assigned here: latest + 1) as the grid's newest, drops
  // deformed revisions beyond the retention limit, queues the revision on the grid's
  // subscriptions and returns the new snapshot; NOT_FOUND if the grid was deleted meanwhile,
  // ABORTED if `expected_latest` is not 0 and the grid's latest revision is another one (a
  // concurrent writer got there first).
  absl::StatusOr<std::shared_ptr<const StoredGrid>> AddRevision(const std::string& id,
                                                                GridRevision revision,
                                                                int64_t expected_latest = 0);

  // Removes the grid and ends its subscriptions (kGridDeleted); NOT_FOUND if absent. Readers
  // holding snapshots keep them.
  absl::Status Delete(const std::string& id);

  // A watch of grid `id`: its current snapshot, and a subscription that receives every revision
  // published after that snapshot (at most `max_queued` waiting) and the grid's deletion.
  // NOT_FOUND if absent, UNAVAILABLE after CloseSubscriptions.
  struct Watch {
    std::shared_ptr<const StoredGrid> snapshot;
    std::shared_ptr<GridSubscription> subscription;
  };
  absl::StatusOr<Watch> Subscribe(const std::string& id, std::weak_ptr<GridWatcher> watcher,
                                  size_t max_queued);

  // Stops queuing on `subscription` (a watch that ended); a no-op when it is gone already.
  void Unsubscribe(const std::string& id, const GridSubscription* subscription);

  // Ends every subscription (kClosed) and refuses new ones: the server is shutting down.
  void CloseSubscriptions();

  // Up to `limit` grids with ids greater than `after`, in id order, and whether more follow.
  std::vector<std::shared_ptr<const StoredGrid>> List(const std::string& after, int limit,
                                                      bool* more) const;

 private:
  const int max_deform_revisions_;
  mutable std::mutex mu_;  // before any GridSubscription::mu_
  std::map<std::string, std::shared_ptr<const StoredGrid>> grids_;
  std::map<std::string, std::vector<std::shared_ptr<GridSubscription>>> subscriptions_;
  bool closed_ = false;  // CloseSubscriptions was called
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_GRID_STORE_H_
