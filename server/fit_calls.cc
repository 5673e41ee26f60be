// FitGrid and FairGrid: fit a grid's source points and store the result as a new revision.
#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"
#include "server/grid_encoding.h"
#include "server/service.h"

namespace splinegrid::server {
namespace {

// The request field the options of a revision of `origin` came from, in front of the kernel's
// field names: "spec." (FitGrid, GenerateGrid) or the fit spec of the refaired revision.
std::string SpecField(RevisionOrigin origin, int64_t parent) {
  return origin == RevisionOrigin::kFair ? absl::StrCat("revision ", parent, " fit_spec.")
                                         : std::string("spec.");
}

}  // namespace

absl::StatusOr<GridRevision> SplineGridService::FitRevision(const SourcePoints& source,
                                                            const GridFitOptions& options,
                                                            RevisionOrigin origin, int64_t parent,
                                                            const CancelCheck& cancel) {
  // Options that do not suit the grid are refused, naming the request's field, value and limit
  // ("spec.control_counts[0] = 1000 exceeds the 113 points of block 0 in i"); nothing is
  // clamped, and nothing is stored.
  SG_RETURN_IF_ERROR(options.Validate(source.grid), SpecField(origin, parent));
  // Working memory of a fit: about the intermediate nets, parameters, tolerances and the
  // evaluations of the deviation and quality checks, bounded by a few times the source size.
  SG_ASSIGN_OR_RETURN(MemoryReservation work,
                      state_->budget.Reserve(2 * source.memory.bytes(), "the fit"));
  // The connectivity found at import (kept with the source points), not found again.
  absl::StatusOr<GridFit> fitted =
      splinegrid::FitGrid(source.grid, source.connectivity, options, cancel);
  if (fitted.status().code() == absl::StatusCode::kFailedPrecondition) {
    // A grid that cannot be fitted, or one whose fit folds without options.allow_folds.
    return absl::FailedPreconditionError(
        absl::StrCat(fitted.status().message(), "; nothing was stored"));
  }
  SG_ASSIGN_OR_RETURN(GridFit fit, std::move(fitted));
  GridRevision revision;
  revision.create_time = absl::Now();
  revision.origin = origin;
  revision.parent = parent;
  revision.fit_options = options;
  SG_ASSIGN_OR_RETURN(revision.memory,
                      state_->budget.Reserve(RevisionBytes(fit), "the fitted revision"));
  revision.blocks = std::move(fit.blocks);
  revision.kinds = std::move(fit.kinds);
  revision.report = fit.report;
  return revision;
}

absl::Status SplineGridService::FitAndStore(const StoredGrid& grid, const GridFitOptions& options,
                                            RevisionOrigin origin, int64_t parent,
                                            const CancelCheck& cancel,
                                            v1::FitGridResponse* response) {
  SG_ASSIGN_OR_RETURN(GridRevision revision,
                      FitRevision(*grid.source, options, origin, parent, cancel));
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> stored,
                      state_->store->AddRevision(grid.id, std::move(revision)));
  EncodeFitResponse(*stored->revisions.back(), response);
  return absl::OkStatus();
}

grpc::ServerUnaryReactor* SplineGridService::FitGrid(grpc::CallbackServerContext* context,
                                                     const v1::FitGridRequest* request,
                                                     v1::FitGridResponse* response) {
  CallLog log("FitGrid", request->name(), state_->options);
  CancelCheck cancel = CallCancelCheck(context);
  return RunOnPool(
      context, log, Role::kWrite, WorkKind::kLong,
      [this, request, response, cancel](const Caller&) -> absl::Status {
        SG_ASSIGN_OR_RETURN(const std::string id, ParseGridName(request->name(), "name"));
        SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> grid, state_->store->Get(id));
        SG_ASSIGN_OR_RETURN(GridFitOptions options, ParseFitSpec(request->spec()));
        // The imported file's boundary conditions are the default kinds of their faces.
        options.face_kinds = WithDefaultFaceKinds(std::move(options.face_kinds),
                                                  grid->source->boundaries.face_kinds);
        return FitAndStore(*grid, options, RevisionOrigin::kFit, 0, cancel, response);
      });
}

grpc::ServerUnaryReactor* SplineGridService::FairGrid(grpc::CallbackServerContext* context,
                                                      const v1::FairGridRequest* request,
                                                      v1::FitGridResponse* response) {
  CallLog log("FairGrid", request->name(), state_->options);
  CancelCheck cancel = CallCancelCheck(context);
  return RunOnPool(
      context, log, Role::kWrite, WorkKind::kLong,
      [this, request, response, cancel](const Caller&) -> absl::Status {
        SG_ASSIGN_OR_RETURN(const std::string id, ParseGridName(request->name(), "name"));
        SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> grid, state_->store->Get(id));
        SG_ASSIGN_OR_RETURN(const std::shared_ptr<const GridRevision> parent,
                            grid->ResolveRevision(request->revision()));
        GridFitOptions options = parent->fit_options;
        if (request->has_fairing()) {
          SG_ASSIGN_OR_RETURN(options.fairing, ParseFairing(request->fairing(), "fairing"));
        } else if (options.tolerance_mode()) {
          options.fairing = FairingOptions{FairingMode::kToTolerance};
        } else {
          return absl::InvalidArgumentError(
              absl::StrCat("fairing is unset and revision ", parent->number,
                           " was fitted with control counts: give a fairing weight (mode WEIGHT)"));
        }
        if (options.fairing.mode == FairingMode::kOff) {
          return absl::InvalidArgumentError(
              "fairing.mode = OFF; FairGrid needs WEIGHT or TO_TOLERANCE");
        }
        // Folds are accepted only when this request says so, not because the parent did.
        options.allow_folds = request->allow_folds();
        return FitAndStore(*grid, options, RevisionOrigin::kFair, parent->number, cancel, response);
      });
}

}  // namespace splinegrid::server
