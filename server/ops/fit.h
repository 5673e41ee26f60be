// FitGrid's and FairGrid's operations: fit a grid's source points and publish the result as a
// new revision; FitRevision is the part GenerateGrid shares (its grid is fitted before it is
// stored).
#ifndef SPLINEGRID_SERVER_OPS_FIT_H_
#define SPLINEGRID_SERVER_OPS_FIT_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "core/fit/grid_fit.h"
#include "core/fit/solve/fairing.h"
#include "core/util/cancellation.h"
#include "server/grid_store.h"
#include "server/ops/ops_context.h"

namespace splinegrid::server::ops {

// Fits `source` with `options` into a revision of `origin` (and `parent`), not yet numbered or
// stored; its memory is reserved. Options that do not suit the grid are INVALID_ARGUMENT naming
// the request's field ("spec." or "revision N fit_spec." in front of the kernel's name); a grid
// that cannot be fitted, or whose fit folds without allow_folds, FAILED_PRECONDITION.
absl::StatusOr<GridRevision> FitRevision(const OpsContext& context, const SourcePoints& source,
                                         const GridFitOptions& options, RevisionOrigin origin,
                                         int64_t parent, const CancelCheck& cancel);

// Fits grid `id` with `options` (the imported file's boundary conditions are the default kinds
// of their faces) and publishes the revision.
absl::StatusOr<std::shared_ptr<const GridRevision>> Fit(const OpsContext& context,
                                                        const std::string& id,
                                                        GridFitOptions options,
                                                        const CancelCheck& cancel);

struct FairRequest {
  std::string grid_id;
  int64_t revision = 0;  // the revision refaired; 0: the latest
  // Unset: to the tolerances of a revision fitted to tolerances (kToTolerance); a revision
  // fitted to control counts needs a weight.
  std::optional<FairingOptions> fairing;
  bool allow_folds = false;  // asked by this request, not inherited from the revision
};

// Refits revision `request.revision` with its own options and the fairing asked, and publishes
// the result (origin kFair, parent that revision).
absl::StatusOr<std::shared_ptr<const GridRevision>> Fair(const OpsContext& context,
                                                         const FairRequest& request,
                                                         const CancelCheck& cancel);

}  // namespace splinegrid::server::ops

#endif  // SPLINEGRID_SERVER_OPS_FIT_H_
