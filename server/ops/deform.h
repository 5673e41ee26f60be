// DeformGrid's operation: move part of a revision's boundary, let the grid follow, gate it for
// folds and publish it as a new revision stamped with the solver's time and step.
#ifndef SPLINEGRID_SERVER_OPS_DEFORM_H_
#define SPLINEGRID_SERVER_OPS_DEFORM_H_

#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "core/deform/deform_motion.h"
#include "core/deform/deformer.h"
#include "core/util/cancellation.h"
#include "server/grid_store.h"
#include "server/ops/ops_context.h"

namespace splinegrid::server::ops {

// Highest refinement level of the fold check (16 sub-cells per cell in 2D, 64 in 3D at 2).
inline constexpr int kMaxDeformCheckLevel = 4;

struct DeformRequest {
  std::string grid_id;
  // The latest revision the caller has seen: ABORTED when the grid has a newer one (another
  // client deformed it meanwhile). 0: no check.
  int64_t base_revision = 0;
  // The revision whose geometry is deformed (motions are relative to it); 0: the latest.
  int64_t reference_revision = 0;
  DeformOptions options;  // what moves and how the grid follows
  DeformMotion motion;
  int check_level = 0;  // the fold check's refinement level, [0, kMaxDeformCheckLevel]
  // Boundary-point motions: the largest distance the deformed boundary may keep from the points
  // given; 0: twice the fit's tolerance of the moved boundary's kind (DefaultMaxBoundaryError).
  double max_boundary_error = 0.0;
  double time = 0.0;    // the solver's time and step, stamped on the revision
  int64_t step = 0;
};

// Whether the deformer `request` needs is kept with the fold gate of its check level: its
// deform then costs about half a millisecond (cheap work), while building them factorises the
// boundary fits and evaluates the reference (up to seconds). False for reference_revision 0
// (the latest is only known once the grid is read).
bool HasKeptDeformer(const OpsContext& context, const DeformRequest& request);

// A deformer smaller than this is cheap enough to build in a slice of work (about 0.5 ms of
// classifying the controls and 5 ms of the fold gate at these sizes: BM_DeformerCreate,
// BM_DeformCheck): controls of the reference, and cells of its fold gate at the check level;
// and a deform of at most kSmallDeformControlSweeps control updates (controls times the
// smoothing iterations of DeformOptions, each a Jacobi sweep over the net).
inline constexpr int64_t kSmallDeformerControls = int64_t{1} << 14;
inline constexpr int64_t kSmallDeformerCells = int64_t{1} << 17;
inline constexpr int64_t kSmallDeformControlSweeps = int64_t{1} << 20;

// Whether the deform `request` asks for is small work once its grid is read: its smoothing is
// small and its deformer is kept, or building it and its fold gate is (kSmall*). Reads the grid
// (NOT_FOUND, and the reference's errors, as Deform would answer). The service runs small deforms
// as a slice, so that a solver's first step after a start or a failover does not wait behind other
// principals' fits for the long workers.
absl::StatusOr<bool> DeformIsSmall(const OpsContext& context, const DeformRequest& request);

// Deforms and publishes; the published revision. Errors: NOT_FOUND for the grid or the
// reference, INVALID_ARGUMENT naming the field (negative base_revision, check_level out of
// range, non-finite time, options and motions the deformer refuses), ABORTED for a stale
// base_revision (also when another replica publishes first), FAILED_PRECONDITION when the
// deformation folds cells (nothing is stored), RESOURCE_EXHAUSTED from the memory budget,
// CANCELLED.
absl::StatusOr<std::shared_ptr<const GridRevision>> Deform(const OpsContext& context,
                                                           const DeformRequest& request,
                                                           const CancelCheck& cancel);

}  // namespace splinegrid::server::ops

#endif  // SPLINEGRID_SERVER_OPS_DEFORM_H_
