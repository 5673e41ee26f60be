#include "server/ops/fit.h"

#include <optional>
#include <string>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid::server::ops {
namespace {

// The request field the options of a revision of `origin` came from, in front of the kernel's
// field names: "spec." (FitGrid, GenerateGrid) or the fit spec of the refaired revision.
std::string SpecField(RevisionOrigin origin, int64_t parent) {
  return origin == RevisionOrigin::kFair ? absl::StrCat("revision ", parent, " fit_spec.")
                                         : std::string("spec.");
}

// Whether a kernel message starts with a GridFitOptions field ("boundary_tolerances.wall = ..."),
// which the request names under its spec; other refusals are about the data.
bool NamesAnOption(absl::string_view message) {
  for (const char* field :
       {"boundary_tolerances.", "tolerance ", "features.", "order ", "max_controls_per_direction ",
        "block_control_counts", "reference_length ", "face_kinds"}) {
    if (absl::StartsWith(message, field)) return true;
  }
  return false;
}

// Fits grid `grid` and publishes the revision.
absl::StatusOr<std::shared_ptr<const GridRevision>> FitAndPublish(
    const OpsContext& context, const StoredGrid& grid, const GridFitOptions& options,
    RevisionOrigin origin, int64_t parent, const CancelCheck& cancel) {
  SG_ASSIGN_OR_RETURN(GridRevision revision,
                      FitRevision(context, *grid.source, options, origin, parent, cancel));
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> stored,
                      context.store.AddRevision(grid.id, std::move(revision), 0, grid.incarnation));
  return stored->revisions.back();
}

// FairGrid refits the grid's imported points with a revision's spec: a deformed revision's
// geometry is not in them, so fairing it would silently undo the deformation (it did: the
// "faired" latest revision was the undeformed grid). FAILED_PRECONDITION naming the fitted
// revision the deformations start from.
absl::Status CheckFairable(const StoredGrid& grid, const GridRevision& revision) {
  if (revision.origin != RevisionOrigin::kDeform) return absl::OkStatus();
  // Retention may have dropped a link of the chain back to the fit.
  const std::shared_ptr<const GridRevision> base = grid.DeformationBase(revision);
  const std::optional<int64_t> fitted =
      base == nullptr ? std::nullopt : std::optional<int64_t>(base->number);
  return absl::FailedPreconditionError(absl::StrCat(
      "grids/", grid.id, " revision ", revision.number,
      " is deformed: FairGrid refits the grid's imported points, which do not carry the "
      "deformation, so the faired grid would undo it; fair ",
      fitted ? absl::StrCat("revision ", *fitted) : std::string("the fitted revision"),
      " (the fit the deformations start from) and deform that"));
}

// Whether two fairings give the same fit (the weight is the lambda, or the upper end of the
// search to tolerance).
bool SameFairing(const FairingOptions& a, const FairingOptions& b) {
  return a.mode == b.mode && (a.mode == FairingMode::kOff || a.weight == b.weight);
}

// The options of refairing `parent` as `request` asks.
absl::StatusOr<GridFitOptions> FairOptions(const GridRevision& parent, const FairRequest& request) {
  GridFitOptions options = parent.fit_options;
  if (request.fairing) {
    options.fairing = *request.fairing;
  } else if (options.tolerance_mode()) {
    options.fairing = FairingOptions{FairingMode::kToTolerance};
  } else {
    return absl::InvalidArgumentError(
        absl::StrCat("fairing is unset and revision ", parent.number,
                     " was fitted with control counts: give a fairing weight (fairing.mode WEIGHT "
                     "with fairing.weight; CLI fair --fair LAMBDA)"));
  }
  if (options.fairing.mode == FairingMode::kOff) {
    return absl::InvalidArgumentError("fairing.mode = OFF; FairGrid needs WEIGHT or TO_TOLERANCE");
  }
  // Folds are accepted only when this request says so, not because the parent did.
  options.allow_folds = request.allow_folds;
  return options;
}

}  // namespace

absl::StatusOr<GridRevision> FitRevision(const OpsContext& context, const SourcePoints& source,
                                         const GridFitOptions& options, RevisionOrigin origin,
                                         int64_t parent, const CancelCheck& cancel) {
  // Options that do not suit the grid are refused, naming the request's field, value and limit
  // ("spec.control_counts[0] = 1000 exceeds the 113 points of block 0 in i"); nothing is
  // clamped, and nothing is stored.
  SG_RETURN_IF_ERROR(options.Validate(source.grid()), SpecField(origin, parent));
  // Working memory of a fit: about the intermediate nets, parameters, tolerances and the
  // evaluations of the deviation and quality checks, bounded by a few times the source size.
  SG_ASSIGN_OR_RETURN(MemoryReservation work,
                      context.budget.Reserve(2 * source.memory.bytes(), "the fit"));
  // The points were checked and matched when the grid arrived, not again here.
  absl::StatusOr<GridFit> fitted = FitGrid(source.checked, options, cancel);
  if (fitted.status().code() == absl::StatusCode::kFailedPrecondition) {
    // A fit that folds without options.allow_folds, or data that leave controls undetermined.
    return absl::FailedPreconditionError(
        absl::StrCat(fitted.status().message(), "; nothing was stored"));
  }
  if (fitted.status().code() == absl::StatusCode::kInvalidArgument &&
      NamesAnOption(fitted.status().message())) {
    // Options that only the grid's walls and points refuse (a first layer to hold where no
    // wall is, a tolerance below double precision); the kernel names GridFitOptions' field.
    // A refaired revision's spec cannot be changed by FairGrid: say how to get past it.
    return absl::InvalidArgumentError(absl::StrCat(
        SpecField(origin, parent), fitted.status().message(),
        origin == RevisionOrigin::kFair
            ? absl::StrCat("; FairGrid keeps revision ", parent,
                           "'s spec: fit the grid again with a spec that holds (FitGrid) and fair "
                           "that revision")
            : std::string()));
  }
  SG_ASSIGN_OR_RETURN(GridFit fit, std::move(fitted));
  GridRevision revision;
  revision.create_time = absl::Now();
  revision.origin = origin;
  revision.parent = parent;
  revision.fit_options = options;
  SG_ASSIGN_OR_RETURN(revision.memory,
                      context.budget.Reserve(RevisionBytes(fit), "the fitted revision"));
  revision.blocks = std::move(fit.blocks);
  revision.kinds = std::move(fit.kinds);
  revision.report = fit.report;
  return revision;
}

absl::StatusOr<std::shared_ptr<const GridRevision>> Fit(const OpsContext& context,
                                                        const std::string& id,
                                                        GridFitOptions options,
                                                        const CancelCheck& cancel) {
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> grid, context.store.Get(id));
  SG_RETURN_IF_ERROR(context.MayChange(grid->owner, id, "fitting"));
  // The imported file's boundary conditions are the default kinds of their faces.
  options.face_kinds =
      WithDefaultFaceKinds(std::move(options.face_kinds), grid->source->boundaries.face_kinds);
  return FitAndPublish(context, *grid, options, RevisionOrigin::kFit, 0, cancel);
}

absl::StatusOr<std::shared_ptr<const GridRevision>> Fair(const OpsContext& context,
                                                         const FairRequest& request,
                                                         const CancelCheck& cancel) {
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> grid,
                      context.store.Get(request.grid_id));
  SG_RETURN_IF_ERROR(context.MayChange(grid->owner, request.grid_id, "fairing"));
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const GridRevision> parent,
                      grid->ResolveRevision(request.revision));
  SG_RETURN_IF_ERROR(CheckFairable(*grid, *parent));
  SG_ASSIGN_OR_RETURN(const GridFitOptions options, FairOptions(*parent, request));
  // A revision fitted or faired with this very fairing: the refit is the same grid.
  if (parent->fit_options.fairing.mode != FairingMode::kOff &&
      SameFairing(parent->fit_options.fairing, options.fairing)) {
    return absl::FailedPreconditionError(absl::StrCat(
        "grids/", request.grid_id, " revision ", parent->number,
        " is faired already, as asked: fairing it again would store the same grid",
        parent->origin == RevisionOrigin::kFair
            ? absl::StrCat(" (fair revision ", parent->parent, " with another fairing instead)")
            : std::string(" (give another fairing)")));
  }
  return FitAndPublish(context, *grid, options, RevisionOrigin::kFair, parent->number, cancel);
}

}  // namespace splinegrid::server::ops
