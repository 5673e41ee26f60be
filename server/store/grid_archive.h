// A whole grid as archive records (proto/splinegrid/v1/archive.proto): what the directory
// store writes, the Redis store keeps, ExportGrid sends and ImportArchive receives.
#ifndef SPLINEGRID_SERVER_STORE_GRID_ARCHIVE_H_
#define SPLINEGRID_SERVER_STORE_GRID_ARCHIVE_H_

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "core/util/cancellation.h"
#include "proto/convert/archive_convert.h"
#include "server/grid_store.h"
#include "server/memory_budget.h"
#include "splinegrid/v1/archive.pb.h"

namespace splinegrid::server {

// Values per SourceChunk: 1 MiB of doubles, well inside gRPC's 4 MiB message limit.
inline constexpr int64_t kSourceChunkValues = int64_t{1} << 17;

// The header of `grid` (no points, no revisions), announcing `num_revisions` revisions.
v1::ArchiveHeader EncodeGridHeader(const StoredGrid& grid, int64_t num_revisions);

// `grid` as records in archive order: header, source chunks, revisions.
absl::Status ForEachRecord(const StoredGrid& grid,
                           const std::function<absl::Status(const v1::ArchiveRecord&)>& emit);

// Rebuilds a grid from its records, in archive order: one header, its source chunks, then
// revisions in ascending number. Memory is charged to `budget` as the data arrives (never for
// what a header merely announces). Errors are INVALID_ARGUMENT saying which record and what is
// wrong, or RESOURCE_EXHAUSTED from the budget.
class GridAssembler {
 public:
  // `id`: the grid's id (empty: the header's own).
  GridAssembler(MemoryBudget* budget, std::string id);

  absl::Status Add(const v1::ArchiveRecord& record);
  absl::Status AddHeader(const v1::ArchiveHeader& header);
  absl::Status AddChunk(const v1::SourceChunk& chunk);
  absl::Status AddRevision(const v1::StoredRevision& stored);

  // Whether the header and every source chunk arrived (revisions may follow).
  bool has_source() const;
  // The grid. With `check_counts` the header's num_revisions must match what arrived. Its
  // source points are checked for fitting and matched here (FittableGrid::Check): a block that
  // cannot be fitted is INVALID_ARGUMENT naming it; CANCELLED when `cancel` fires meanwhile.
  absl::StatusOr<std::shared_ptr<StoredGrid>> Finish(bool check_counts,
                                                     const CancelCheck& cancel = {});

  // The connectivity the header states (once the source is finished). The grid keeps the one
  // this server finds in the points; an importer compares the two.
  const Connectivity& stated_connectivity() const { return stated_connectivity_; }

 private:
  // Turns the assembled points into the grid's source (checked by Finish); `event` says what
  // ended them. An error is kept: every later call returns it.
  absl::Status FinishSource(const std::string& event);
  absl::Status AssembleSource(const std::string& event);

  MemoryBudget* budget_;
  std::string id_;
  std::optional<v1::ArchiveHeader> header_;
  std::optional<SourceAssembler> source_;
  MemoryReservation source_memory_;
  int64_t chunks_ = 0;
  Connectivity stated_connectivity_;
  // The finished source without its points, and the points, until Finish checks them.
  std::shared_ptr<SourcePoints> points_;
  MultiBlockGrid unchecked_;
  absl::Status source_error_;
  std::shared_ptr<StoredGrid> grid_;
};

// Parses a revision record and reserves its memory.
absl::StatusOr<std::shared_ptr<const GridRevision>> LoadRevision(const v1::StoredRevision& stored,
                                                                 MemoryBudget* budget);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_STORE_GRID_ARCHIVE_H_
