// DeformGrid: move part of a revision's boundary, let the grid follow, gate it for folds and
// store it as a new revision stamped with the solver's time and step.
#include <chrono>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/deform/deform_quality.h"
#include "core/deform/deformer.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"
#include "proto/convert/deform_convert.h"
#include "server/grid_encoding.h"
#include "server/service.h"

namespace splinegrid::server {
namespace {

// Highest refinement level of the fold check (16 sub-cells per cell in 2D, 64 in 3D at 2).
constexpr int kMaxCheckLevel = 4;

// The start of a deformer's cache key: the grid's id, the reference revision and everything the
// deformer is built from (length-prefixed, so that no key is the prefix of another's).
std::string DeformerShapeKey(const std::string& id, int64_t reference,
                             const v1::DeformGridRequest& request) {
  v1::DeformGridRequest shape;
  *shape.mutable_boundary() = request.boundary();
  shape.set_propagation(request.propagation());
  shape.set_rigid_radius(request.rigid_radius());
  shape.set_decay_radius(request.decay_radius());
  shape.set_smoothing_iterations(request.smoothing_iterations());
  const std::string bytes = shape.SerializeAsString();
  return absl::StrCat(DeformerKeyPrefix(id), reference, "#", bytes.size(), ":", bytes, "#");
}

// The whole key: the shape key and the grid's creation (an id may be used again).
std::string DeformerKey(const StoredGrid& grid, int64_t reference,
                        const v1::DeformGridRequest& request) {
  return absl::StrCat(DeformerShapeKey(grid.id, reference, request),
                      absl::ToUnixNanos(grid.create_time));
}

}  // namespace

grpc::ServerUnaryReactor* SplineGridService::DeformGrid(grpc::CallbackServerContext* context,
                                                        const v1::DeformGridRequest* request,
                                                        v1::DeformGridResponse* response) {
  CallLog log("DeformGrid", request->name(), state_->options);
  CancelCheck cancel = CallCancelCheck(context);
  // A deform with a kept deformer costs about a millisecond: cheap work. Building the deformer
  // (the first deform with this reference and boundary, or after it was evicted) factorises the
  // boundary fits, up to seconds: long work, scheduled fairly. The request names the deformer
  // up to the grid's creation, so a kept one for the same shape decides (a grid deleted and made
  // again under the same id builds once on the cheap lane); reference 0 (the latest) is long.
  const absl::StatusOr<std::string> grid_id = ParseGridName(request->name(), "name");
  const WorkKind kind = grid_id.ok() && request->reference_revision() > 0 &&
                                state_->deformers.HasAny(DeformerShapeKey(
                                    *grid_id, request->reference_revision(), *request))
                            ? WorkKind::kCheap
                            : WorkKind::kLong;
  return RunOnPool(
      context, log, Role::kWrite, kind,
      [this, request, response, cancel](const Caller&) -> absl::Status {
        const auto start = std::chrono::steady_clock::now();
        SG_ASSIGN_OR_RETURN(const std::string id, ParseGridName(request->name(), "name"));
        // The base is checked again, atomically, when the revision is added.
        SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> grid,
                            state_->store->GetHolding(
                                id, {request->base_revision(), request->reference_revision()}));
        // The base is compared with the latest, not looked up: a stale one is ABORTED.
        if (request->base_revision() < 0) {
          return absl::InvalidArgumentError(
              absl::StrCat("base_revision = ", request->base_revision(), " is negative"));
        }
        if (request->check_level() < 0 || request->check_level() > kMaxCheckLevel) {
          return absl::InvalidArgumentError(absl::StrCat("check_level = ", request->check_level(),
                                                         " is outside [0, ", kMaxCheckLevel, "]"));
        }
        if (!std::isfinite(request->time())) {
          return absl::InvalidArgumentError(
              absl::StrCat("time = ", request->time(), " is not finite"));
        }
        if (request->motion_case() == v1::DeformGridRequest::MOTION_NOT_SET) {
          return absl::InvalidArgumentError(
              "motion is unset: give rigid, controls or boundary_points");
        }
        SG_ASSIGN_OR_RETURN(const DeformOptions options, ParseDeformOptions(*request));
        const int64_t latest = grid->revisions.empty() ? 0 : grid->revisions.back()->number;
        if (request->base_revision() != 0 && request->base_revision() != latest) {
          return absl::AbortedError(absl::StrCat("grids/", id, ": base_revision ",
                                                 request->base_revision(),
                                                 " is stale; the latest revision is ", latest));
        }
        SG_ASSIGN_OR_RETURN(const std::shared_ptr<const GridRevision> reference,
                            grid->ResolveRevision(request->reference_revision(), std::nullopt,
                                                  "reference_revision"));
        SG_ASSIGN_OR_RETURN(
            const std::shared_ptr<const Deformer> deformer,
            state_->deformers.Get(
                DeformerKey(*grid, reference->number, *request), [&]() -> absl::StatusOr<Deformer> {
                  std::vector<FittedBlock> blocks;
                  for (const BlockFit& b : reference->blocks) blocks.push_back(b.fitted);
                  return Deformer::Create(std::move(blocks), reference->kinds, options);
                }));
        std::vector<FittedBlock> moved;
        switch (request->motion_case()) {
          case v1::DeformGridRequest::kRigid: {
            SG_ASSIGN_OR_RETURN(const RigidMotion motion, ParseRigidMotion(request->rigid()));
            SG_ASSIGN_OR_RETURN(moved, deformer->Rigid(motion));
            break;
          }
          case v1::DeformGridRequest::kControls: {
            SG_ASSIGN_OR_RETURN(const std::vector<double> displacements,
                                ParseControlDisplacements(*deformer, request->controls()));
            SG_ASSIGN_OR_RETURN(moved, deformer->DisplaceControls(displacements));
            break;
          }
          case v1::DeformGridRequest::kBoundaryPoints: {
            SG_ASSIGN_OR_RETURN(const std::vector<BoundaryPoints> points,
                                ParseBoundaryPoints(request->boundary_points()));
            SG_ASSIGN_OR_RETURN(moved, deformer->MoveBoundaryPoints(points));
            break;
          }
          case v1::DeformGridRequest::MOTION_NOT_SET:
            break;
        }
        SG_ASSIGN_OR_RETURN(const DeformationCheck check,
                            CheckDeformation(deformer->reference(), moved, deformer->kinds(),
                                             request->check_level(), cancel));
        if (!check.ok()) {
          const Extents& c = check.worst_cell;
          return absl::FailedPreconditionError(absl::StrCat(
              "the deformation folds ", check.folded, " cells at refinement level ", check.level,
              "; the worst in block ", check.worst_block, " at cell (", c[0], ", ", c[1], ", ",
              c[2], ") with Jacobian ratio ", check.min_jacobian_ratio,
              "; nothing was stored (move less per step, or widen decay_radius)"));
        }
        GridRevision revision;
        revision.create_time = absl::Now();
        revision.origin = RevisionOrigin::kDeform;
        revision.parent = reference->number;
        revision.time = request->time();
        revision.step = request->step();
        revision.fit_options = reference->fit_options;
        revision.kinds = reference->kinds;
        revision.blocks = reference->blocks;
        for (size_t b = 0; b < moved.size(); ++b)
          revision.blocks[b].fitted.spline = moved[b].spline;
        revision.deform.check = check;
        revision.deform.moved_controls = static_cast<int>(deformer->moved_controls().size());
        revision.deform.decay_radius = deformer->decay_radius();
        revision.deform.seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        SG_ASSIGN_OR_RETURN(revision.memory, state_->budget.Reserve(RevisionBytes(revision),
                                                                    "the deformed revision"));
        SG_ASSIGN_OR_RETURN(
            const std::shared_ptr<const StoredGrid> stored,
            state_->store->AddRevision(id, std::move(revision), request->base_revision()));
        const GridRevision& published = *stored->revisions.back();
        response->set_revision(published.number);
        EncodeDeformReport(published.deform, response->mutable_report());
        return absl::OkStatus();
      });
}

}  // namespace splinegrid::server
