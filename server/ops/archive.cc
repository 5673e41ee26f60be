#include "server/ops/archive.h"

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid::server::ops {
namespace {

absl::Status CheckConnectivity(const Connectivity& stated_connectivity, const Connectivity& found) {
  if (stated_connectivity == found) return absl::OkStatus();
  const size_t stated = stated_connectivity.matches.size();
  return absl::InvalidArgumentError(absl::StrCat(
      "header.connectivity does not match the archive's source points: it lists ", stated,
      " block boundary match(es), this server finds ", found.matches.size(),
      stated == found.matches.size() ? " other ones" : "",
      " in the points; the archive was changed or damaged, or written by a release that "
      "matched boundaries differently (export it again from that server)"));
}

}  // namespace

absl::StatusOr<MemoryReservation> ExportSnapshot(
    const OpsContext& context, const std::string& grid_id,
    const std::function<absl::StatusOr<int64_t>(const StoredGrid&)>& write) {
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> grid, context.store.Get(grid_id));
  SG_ASSIGN_OR_RETURN(
      MemoryReservation memory,
      context.budget.Reserve(SourceBytes(grid->source->grid()), "the export's records"));
  SG_ASSIGN_OR_RETURN(const int64_t kept, write(*grid));
  SG_RETURN_IF_ERROR(context.budget.Resize(&memory, kept, "the export's records"));
  return memory;
}

absl::Status StoreArchived(const OpsContext& context, std::shared_ptr<StoredGrid> grid,
                           const Connectivity& stated_connectivity, std::string owner) {
  SG_RETURN_IF_ERROR(CheckConnectivity(stated_connectivity, grid->source->connectivity()));
  grid->owner = std::move(owner);
  return context.store.Create(grid);
}

}  // namespace splinegrid::server::ops
