// GenerateGrid's volume operation: hexahedral layers marched off a stored surface grid
// (core/generate/surface_offset.h), stored as a new grid's source points and fitted as its
// revision 1, all or nothing.
#ifndef SPLINEGRID_SERVER_OPS_GENERATE_VOLUME_H_
#define SPLINEGRID_SERVER_OPS_GENERATE_VOLUME_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/fit/grid_fit.h"
#include "core/generate/surface_offset.h"
#include "core/util/cancellation.h"
#include "server/grid_store.h"
#include "server/ops/ops_context.h"

namespace splinegrid::server::ops {

// Every block of revision `revision` (0: the latest) of a stored surface grid.
struct StoredSurface {
  std::string grid_id;
  int64_t revision = 0;
};

struct GenerateVolumeRequest {
  std::string grid_id;  // "": the store picks one
  std::string display_name;
  std::string owner;  // Caller::owner() of the creating call
  StoredSurface surface;
  SurfaceOffsetOptions options;
  // The fit of revision 1; unset: interpolation with uniform parameters (a control point per
  // grid point, every block's face splines equal where blocks meet, so the fit is watertight at
  // every level). A given fit replaces that whole default, parameters included; its face kinds
  // name the stored blocks' faces (i reversed where reversed_i says); unless it names some,
  // k = 0 is the wall and k = max the outer boundary.
  std::optional<GridFitOptions> fit;
  bool allow_folds = false;
  int64_t max_points = 0;  // the server's cap on the generated points
};

struct GenerateVolumeResult {
  std::shared_ptr<const StoredGrid> grid;  // as stored, revision 1 fitted
  SurfaceOffsetGrid generated;             // the march's report; its blocks moved to the grid
  std::vector<bool> reversed_i;            // per block (GenerateVolume)
  SurfaceOffsetOptions options;            // the parameters used
  double layer_seconds = 0.0;              // of the march
};

// Marches, fits and stores. Blocks whose cells the march leaves left-handed (side -1) are
// stored with i reversed, so every stored hexahedron is right-handed. Errors: INVALID_ARGUMENT
// naming the field (a stored grid whose blocks are not 3D surfaces among them), ALREADY_EXISTS
// for a taken grid_id, OUT_OF_RANGE beyond max_points, NOT_FOUND for a missing grid or revision,
// FAILED_PRECONDITION when the march or the fit would fold (nothing is stored),
// RESOURCE_EXHAUSTED, CANCELLED.
absl::StatusOr<GenerateVolumeResult> GenerateVolume(const OpsContext& context,
                                                    GenerateVolumeRequest request,
                                                    const CancelCheck& cancel);

}  // namespace splinegrid::server::ops

#endif  // SPLINEGRID_SERVER_OPS_GENERATE_VOLUME_H_
