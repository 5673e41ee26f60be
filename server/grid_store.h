// The in-memory store of grids and their immutable revisions.
//
// Everything a reader can reach is immutable and shared: a grid is a snapshot
// (shared_ptr<const StoredGrid>) that holds its source points and revisions by shared_ptr.
// Adding a revision publishes a new snapshot under a short lock, so a running fit never blocks
// readers, and a reader keeps its snapshot alive even if the grid is deleted meanwhile.
#ifndef SPLINEGRID_SERVER_GRID_STORE_H_
#define SPLINEGRID_SERVER_GRID_STORE_H_

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

  // The revision `number` (0: the latest), or NOT_FOUND / FAILED_PRECONDITION (none yet).
  absl::StatusOr<std::shared_ptr<const GridRevision>> FindRevision(int64_t number) const;
  // The revision `number`, or with `step` the latest deformed revision of that time step
  // (INVALID_ARGUMENT if both are given; NOT_FOUND if no revision has the step).
  absl::StatusOr<std::shared_ptr<const GridRevision>> FindRevision(
      int64_t number, std::optional<int64_t> step) const;
};

// Bytes a block's spline, point distribution and summary take in memory.
int64_t FittedBlockBytes(const FittedBlock& block);

// Bytes a revision made of `fit` takes: its blocks and boundary kinds.
int64_t RevisionBytes(const GridFit& fit);

class GridStore {
 public:
  // Adds a new grid; ALREADY_EXISTS if the id is taken.
  absl::Status Create(std::shared_ptr<const StoredGrid> grid);

  // The current snapshot, or NOT_FOUND.
  absl::StatusOr<std::shared_ptr<const StoredGrid>> Get(const std::string& id) const;

  // Publishes `revision` (its number is assigned here: latest + 1) as the grid's newest and
  // returns the new snapshot; NOT_FOUND if the grid was deleted meanwhile, ABORTED if
  // `expected_latest` is not 0 and the grid's latest revision is another one (a concurrent
  // writer got there first).
  absl::StatusOr<std::shared_ptr<const StoredGrid>> AddRevision(const std::string& id,
                                                                GridRevision revision,
                                                                int64_t expected_latest = 0);

  // Removes the grid; NOT_FOUND if absent. Readers holding snapshots keep them.
  absl::Status Delete(const std::string& id);

  // Up to `limit` grids with ids greater than `after`, in id order, and whether more follow.
  std::vector<std::shared_ptr<const StoredGrid>> List(const std::string& after, int limit,
                                                      bool* more) const;

 private:
  mutable std::mutex mu_;
  std::map<std::string, std::shared_ptr<const StoredGrid>> grids_;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_GRID_STORE_H_
