// Grids and their immutable revisions, and the interface of the store that holds them.
//
// Everything a reader can reach is immutable and shared: a grid is a snapshot
// (shared_ptr<const StoredGrid>) that holds its source points and revisions by shared_ptr.
//
// Retention: when a revision is published, the deformed revisions (kDeform) beyond the newest
// max_deform_revisions of the grid leave the snapshot; fitted and faired ones always stay. A
// dropped revision's memory goes when its last reader lets go. Numbers are never reused.
//
// Watching: a GridSubscription receives the summaries of a grid's revisions in publication
// order, then the grid's deletion. Its GridWatcher is woken outside the store's locks and takes
// the events from the subscription.
#ifndef SPLINEGRID_SERVER_GRID_STORE_H_
#define SPLINEGRID_SERVER_GRID_STORE_H_

#include <cstddef>
#include <deque>
#include <functional>
#include <initializer_list>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "core/deform/deform_quality.h"
#include "core/fit/grid_fit.h"
#include "core/grid/fittable_grid.h"
#include "core/grid/source_boundaries.h"
#include "core/grid/structured_grid.h"
#include "core/io/plot3d_source_format.h"
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
  // Boundary-point motions: how far the deformed boundary lies from the points given.
  double boundary_error = 0.0;
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
  // The points, checked for fitting and matched once, when the grid arrived (imported,
  // generated, or loaded by this process); every fit uses them as they are.
  FittableGrid checked;
  std::string format;  // how it arrived, e.g. "plot3d ascii 2d single-block"
  // The file's boundary conditions (CGNS imports): default face kinds of fits, written back
  // with evaluations.
  SourceBoundaries boundaries;
  // Plot3D imports: the file's layout, for writing evaluations back the same way.
  std::optional<Plot3dSourceFormat> plot3d;
  MemoryReservation memory;

  const MultiBlockGrid& grid() const { return checked.grid(); }
  const Connectivity& connectivity() const { return checked.connectivity(); }
};

// A snapshot of a grid resource.
struct StoredGrid {
  std::string id;  // grids/{id}
  std::string display_name;
  // The principal whose token created the grid; empty when it was created without tokens (then
  // only an admin may delete it on a server with tokens).
  std::string owner;
  // Which creation of the id this is: drawn by the store when the grid is created (NewIncarnation;
  // the Redis store's generation) and kept by every later snapshot. A grid deleted and created
  // again under the same id has another, so a revision made from the first is not published on
  // the second (AddRevision). Empty on a grid not yet created.
  std::string incarnation;
  absl::Time create_time;
  std::shared_ptr<const SourcePoints> source;
  std::vector<std::shared_ptr<const GridRevision>> revisions;  // ascending numbers
  // Revisions a dir: store found damaged on disk and set aside (corrupt/): asking for one is
  // DATA_LOSS saying so, not "dropped by retention".
  std::vector<int64_t> damaged_revisions;  // ascending

  // The revision `number` of the request's field `field` (0: the latest), or with `step` the
  // latest deformed revision of that time step. Every handler resolves revisions here, so the
  // errors are the same for every call: INVALID_ARGUMENT naming the field for a negative number
  // or for both a number and a step; NOT_FOUND for a number or step the grid does not have
  // (saying so when retention dropped it); DATA_LOSS for a damaged revision;
  // FAILED_PRECONDITION when it has no revision yet.
  absl::StatusOr<std::shared_ptr<const GridRevision>> ResolveRevision(
      int64_t number, std::optional<int64_t> step = std::nullopt,
      const char* field = "revision") const;

  // The fitted or faired revision that deformed `revision`'s chain of deformations starts from
  // (following parents); nullptr when `revision` is not deformed or retention dropped a link.
  std::shared_ptr<const GridRevision> DeformationBase(const GridRevision& revision) const;
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

  // `after`: revisions up to this number are in the watcher's snapshot already and are not
  // queued again (a store that learns of revisions asynchronously may offer them).
  GridSubscription(std::weak_ptr<GridWatcher> watcher, size_t max_queued, int64_t after = 0)
      : watcher_(std::move(watcher)), max_queued_(max_queued), after_(after) {}

  // The next revision (true), or false and how the watch ended (kOpen: nothing queued now).
  // kLagged and kClosed come at once, dropping what is queued; kGridDeleted after the queue.
  bool Next(RevisionSummary* revision, End* end);

  size_t max_queued() const { return max_queued_; }

  // For the stores (through SubscriptionHub): queues `revision` unless its number is not above
  // the last one queued or `after`; false (and the watch ends kLagged) when that would exceed
  // max_queued.
  bool Push(const RevisionSummary& revision);
  void Close(End end);
  void Wake() const;

 private:
  const std::weak_ptr<GridWatcher> watcher_;
  const size_t max_queued_;
  int64_t after_;  // the highest number queued or known to the watcher
  std::mutex mu_;
  std::deque<RevisionSummary> queue_;
  End end_ = End::kOpen;
};

// Bytes a block's spline, point distribution and summary take in memory.
int64_t FittedBlockBytes(const FittedBlock& block);

// Bytes a revision made of `fit` takes: its blocks and boundary kinds.
int64_t RevisionBytes(const GridFit& fit);
// The same for a revision (what its `memory` should hold).
int64_t RevisionBytes(const GridRevision& revision);
// Bytes the points of `source` take.
int64_t SourceBytes(const MultiBlockGrid& source);

// Where grids live: one interface, three backends (server/store/): MemoryStore (embedded, the
// default), the same with a DirLog (embedded and durable: every change is on disk before the
// call returns) and RedisStore (shared by any number of replicas). Chosen by OpenStore
// (store/open_store.h) from `serve --store`.
//
// Every backend serves immutable snapshots: Get returns the grid as it was when the call
// looked, and a reader keeps its snapshot alive however the grid changes meanwhile. Revision
// numbers are assigned by the store (latest + 1), atomically with the base-revision check, and
// never reused.
class GridStore {
 public:
  virtual ~GridStore() = default;

  // Adds a new grid with the revisions it already has (an imported archive brings them, under
  // their own numbers); ALREADY_EXISTS if the id is taken.
  virtual absl::Status Create(std::shared_ptr<const StoredGrid> grid) = 0;

  // The current snapshot, or NOT_FOUND.
  virtual absl::StatusOr<std::shared_ptr<const StoredGrid>> Get(const std::string& id) = 0;

  // A snapshot that holds every revision in `numbers` (revisions are immutable), possibly older
  // than Get's: for reads of given revisions, and for writes whose base the store checks
  // atomically anyway (AddRevision's expected_latest). A number <= 0 (the latest) needs Get's.
  // A store with a per-process cache of a shared store (redis) answers from it when the cached
  // snapshot holds them and was confirmed recently, which saves a round trip per call; the
  // others answer Get.
  virtual absl::StatusOr<std::shared_ptr<const StoredGrid>> GetHolding(
      const std::string& id, std::initializer_list<int64_t> /*numbers*/) {
    return Get(id);
  }

  // Whether Get and GetHolding answer from this process's memory (a lookup, no I/O), so that a
  // handler may call them on a gRPC thread instead of the worker pool.
  virtual bool ReadsAreLocal() const { return false; }

  // Publishes `revision` (its number is assigned here: latest + 1) as the grid's newest, drops
  // deformed revisions beyond the retention limit, tells the grid's watchers and returns the new
  // snapshot; NOT_FOUND if the grid was deleted meanwhile, ABORTED if `expected_latest` is not 0
  // and the grid's latest revision is another one (a concurrent writer got there first), or if
  // `incarnation` is not empty and the grid is another creation of the id (the one the revision
  // was made from was deleted and a new one created). Both checks are atomic with the publication.
  virtual absl::StatusOr<std::shared_ptr<const StoredGrid>> AddRevision(
      const std::string& id, GridRevision revision, int64_t expected_latest = 0,
      const std::string& incarnation = "") = 0;

  // Decides from a grid's owner whether it may be deleted (OK, or the error to return).
  using DeleteCheck = std::function<absl::Status(const std::string& owner)>;

  // Removes the grid and ends its watches (kGridDeleted); NOT_FOUND if absent. Readers holding
  // snapshots keep them. With `check`, the grid is removed only if `check` of its owner is OK,
  // decided atomically with the removal (a grid deleted and created again by someone else in
  // between is not removed); otherwise `check`'s error.
  virtual absl::Status Delete(const std::string& id, const DeleteCheck& check = nullptr) = 0;

  // A watch of grid `id`: its current snapshot, and a subscription that receives every revision
  // published after that snapshot (at most `max_queued` waiting) and the grid's deletion.
  // NOT_FOUND if absent, UNAVAILABLE after CloseSubscriptions.
  struct Watch {
    std::shared_ptr<const StoredGrid> snapshot;
    std::shared_ptr<GridSubscription> subscription;
  };
  virtual absl::StatusOr<Watch> Subscribe(const std::string& id, std::weak_ptr<GridWatcher> watcher,
                                          size_t max_queued) = 0;

  // Stops queuing on `subscription` (a watch that ended); a no-op when it is gone already.
  virtual void Unsubscribe(const std::string& id, const GridSubscription* subscription) = 0;

  // Ends every subscription (kClosed) and refuses new ones: the server is shutting down.
  virtual void CloseSubscriptions() = 0;

  // Up to `limit` grids with ids greater than `after`, in id order, and whether more follow.
  virtual absl::StatusOr<std::vector<std::shared_ptr<const StoredGrid>>> List(
      const std::string& after, int limit, bool* more) = 0;

  // How many grids and revisions the store holds (metrics). Cheap: reads no revision and lists
  // nothing; a shared store counts its index in one command and leaves `revisions` unknown
  // (counting them would walk every grid inside Redis, blocking its other clients).
  struct Counts {
    int64_t grids = 0;
    std::optional<int64_t> revisions;
  };
  virtual absl::StatusOr<Counts> Count() = 0;

  // OK while the store can serve; otherwise why not (UNAVAILABLE: e.g. Redis is unreachable).
  // Cheap: health checks poll it.
  virtual absl::Status Available() const { return absl::OkStatus(); }
};

// Retention: the numbers of the deformed revisions of `revisions` (ascending) beyond the newest
// `max_deform_revisions`, which publishing the last one drops.
std::vector<int64_t> DeformRevisionsBeyond(
    const std::vector<std::shared_ptr<const GridRevision>>& revisions, int max_deform_revisions);

// `grid` without the deformed revisions beyond the newest `max_deform_revisions` (itself when
// none is beyond): what a store creates, so that a grid imported from an archive keeps what a
// grid deformed here keeps (the numbers of the kept ones unchanged).
std::shared_ptr<const StoredGrid> WithinRetention(std::shared_ptr<const StoredGrid> grid,
                                                  int max_deform_revisions);

// A new incarnation (StoredGrid::incarnation): 64 random bits as 16 hex digits.
std::string NewIncarnation();

// `grid` as the store keeps a creation of it: a copy (its parts are shared) with `incarnation`.
std::shared_ptr<const StoredGrid> WithIncarnation(const StoredGrid& grid, std::string incarnation);

// ABORTED: grid `id` was deleted and created again while a call made a revision of the earlier
// one.
absl::Status ReplacedMeanwhile(const std::string& id);

// Adds `grid` to `store` under `requested_id`, or, when that is empty, under a random id
// "grid-xxxxxxxx" (retrying a few collisions); sets grid->id. ALREADY_EXISTS for a taken
// requested id.
absl::Status CreateGrid(GridStore& store, const std::string& requested_id,
                        const std::shared_ptr<StoredGrid>& grid);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_GRID_STORE_H_
