// ImportGrid's operation: an uploaded grid file (or points) checked, matched and stored as a new
// grid.
#ifndef SPLINEGRID_SERVER_OPS_IMPORT_H_
#define SPLINEGRID_SERVER_OPS_IMPORT_H_

#include <memory>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "core/grid/source_boundaries.h"
#include "core/io/plot3d.h"
#include "core/io/plot3d_source_format.h"
#include "core/util/cancellation.h"
#include "server/ops/ops_context.h"

namespace splinegrid::server::ops {

// What an upload decoded into, with the memory its points hold.
struct ImportedSource {
  ImportedGrid imported;
  std::optional<Plot3dSourceFormat> plot3d;  // Plot3D uploads: the file's layout
  MemoryReservation memory;
};

// Whether a Plot3D file of two k-planes is stored as its planar (2D) view.
enum class PlanarViewChoice { kNever, kAlways, kIfTwoPlanes };

// Parses a Plot3D upload. The parser's memory is charged to `memory` first, bounded from the
// bytes (text repeats "n*x" make a few bytes stand for gigabytes), then exactly the grid's.
// Errors: the parser's (INVALID_ARGUMENT naming the line or offset), kAlways for a file that is
// not a two-plane grid, RESOURCE_EXHAUSTED from the budget.
absl::StatusOr<ImportedSource> ReadPlot3dUpload(const OpsContext& context, const std::string& bytes,
                                                const Plot3dReadOptions& options,
                                                PlanarViewChoice planar, MemoryReservation memory);

struct ImportRequest {
  std::string grid_id;  // empty: the server picks one
  std::string display_name;
  std::string owner;   // the importing principal
  CancelCheck cancel;  // polled while the connectivity is found
};

// Stores `source` as a new grid. A grid that cannot be fitted (all points equal, a direction of
// zero length, cells of no area or volume) is refused here, naming the block, not stored for
// every fit to fail. The block-to-block connectivity is found once, here, for every later fit;
// the file's stated connections it does not confirm become notes of the source's boundaries.
// Errors: INVALID_ARGUMENT (no blocks, an unfittable block), ALREADY_EXISTS for a taken id,
// RESOURCE_EXHAUSTED.
absl::StatusOr<std::shared_ptr<const StoredGrid>> StoreImported(const OpsContext& context,
                                                                const ImportRequest& request,
                                                                ImportedSource source);

}  // namespace splinegrid::server::ops

#endif  // SPLINEGRID_SERVER_OPS_IMPORT_H_
