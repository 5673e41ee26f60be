// ExportGrid's and ImportArchive's operations: a grid with its source points and revisions as
// one snapshot, to move between servers or keep with a case (records: store/grid_archive.h).
#ifndef SPLINEGRID_SERVER_OPS_ARCHIVE_H_
#define SPLINEGRID_SERVER_OPS_ARCHIVE_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "core/grid/connectivity.h"
#include "server/ops/ops_context.h"

namespace splinegrid::server::ops {

// Calls `write` with one snapshot of grid `grid_id`; `write` returns how many bytes it keeps
// (the records it built). The memory is charged before the call (the source points' size) and
// after it (what `write` keeps), and held by the result until the records are sent. Errors:
// NOT_FOUND, RESOURCE_EXHAUSTED, and `write`'s.
absl::StatusOr<MemoryReservation> ExportSnapshot(
    const OpsContext& context, const std::string& grid_id,
    const std::function<absl::StatusOr<int64_t>(const StoredGrid&)>& write);

// Stores a grid assembled from an archive, owned by `owner` (the importer, not the exporter).
// The connectivity the archive states must be the one this server finds in its points (the
// grid's): INVALID_ARGUMENT otherwise, since a damaged or edited archive, or one from a release
// that matched boundaries differently, would be fitted otherwise than where it came from.
// Also ALREADY_EXISTS for a taken id, RESOURCE_EXHAUSTED.
absl::Status StoreArchived(const OpsContext& context, std::shared_ptr<StoredGrid> grid,
                           const Connectivity& stated_connectivity, std::string owner);

}  // namespace splinegrid::server::ops

#endif  // SPLINEGRID_SERVER_OPS_ARCHIVE_H_
