#include "server/ops/deform.h"

#include <bit>
#include <chrono>
#include <cmath>
#include <numbers>
#include <string>
#include <variant>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/deform/deform_quality.h"
#include "core/util/status_macros.h"

namespace splinegrid::server::ops {
namespace {

// Everything a deformer is built from, exactly (doubles by their bits), in a form where no
// encoding is the prefix of another's: the moved boundary, propagation, radii and smoothing.
std::string OptionsKey(const DeformOptions& o) {
  std::string key = absl::StrCat(static_cast<int>(o.moved.kinds), "/", o.moved.ranges.size());
  for (const FaceRange& r : o.moved.ranges) {
    absl::StrAppend(&key, "/", r.face.block, ",", r.face.normal, ",", r.face.upper ? 1 : 0);
    for (int d = 0; d < 3; ++d) absl::StrAppend(&key, ",", r.begin[d], ",", r.end[d]);
  }
  absl::StrAppend(&key, "/", static_cast<int>(o.propagation), "/",
                  std::bit_cast<uint64_t>(o.rigid_radius), "/",
                  std::bit_cast<uint64_t>(o.decay_radius), "/", o.smoothing_iterations);
  return key;
}

// The start of a deformer's cache key: the grid, the reference revision and the options.
std::string ShapeKey(const std::string& id, int64_t reference, const DeformOptions& options) {
  return absl::StrCat(DeformerKeyPrefix(id), reference, "#", OptionsKey(options), "#");
}

// The whole key: the shape key and the grid's incarnation (an id may be used again).
std::string DeformerKey(const StoredGrid& grid, int64_t reference, const DeformOptions& options) {
  return absl::StrCat(ShapeKey(grid.id, reference, options), grid.incarnation);
}

absl::Status Validate(const DeformRequest& request) {
  // The base is compared with the latest, not looked up: a stale one is ABORTED.
  if (request.base_revision < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("base_revision = ", request.base_revision, " is negative"));
  }
  if (request.check_level < 0 || request.check_level > kMaxDeformCheckLevel) {
    return absl::InvalidArgumentError(absl::StrCat("check_level = ", request.check_level,
                                                   " is outside [0, ", kMaxDeformCheckLevel, "]"));
  }
  if (request.step < 0) {  // looked up by its number later (ResolveRevision refuses < 0)
    return absl::InvalidArgumentError(
        absl::StrCat("step = ", request.step, " is negative (a time step number: 0 or more)"));
  }
  if (!std::isfinite(request.time)) {
    return absl::InvalidArgumentError(absl::StrCat("time = ", request.time, " is not finite"));
  }
  if (!(request.max_boundary_error >= 0.0) || !std::isfinite(request.max_boundary_error)) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_boundary_error = ", request.max_boundary_error,
                     " is not a finite distance >= 0 (0: default)"));
  }
  return absl::OkStatus();
}

// How far a boundary-point deformation may miss the points given by default: twice the
// tolerance the fit of the reference held the moved boundary's kind to (the fit's own
// allowance, and as much again for the motion, so that a solver sending its original wall nodes
// is not refused for the fit's deviation), the tightest kind of a selection, walls for face
// ranges; a fit without tolerances (control counts, interpolation) gets the default
// tolerances by kind in its reference length. Deformed revisions carry their fit's report
// (DeformedRevision); ones stored before that are walked back to their fit.
double DefaultMaxBoundaryError(const StoredGrid& grid, const GridRevision& reference,
                               const BoundarySelection& moved) {
  std::shared_ptr<const GridRevision> base;
  if (reference.report.reference.length <= 0.0) base = grid.DeformationBase(reference);
  const GridFitReport& report = base != nullptr ? base->report : reference.report;
  const uint8_t kinds = moved.ranges.empty() && moved.kinds != 0
                            ? moved.kinds
                            : static_cast<uint8_t>(BoundaryKind::kWall);
  const double length = report.reference.length > 0.0 ? report.reference.length : 1.0;
  const double tolerance =
      report.tolerances ? report.tolerances->For(kinds) : BoundaryTolerances().For(kinds) * length;
  return 2.0 * std::max(tolerance, 1e-12 * length);
}

// The refusal of boundary points the deformed boundary misses by more than `limit`.
absl::Status MissesBoundary(const BoundaryMiss& miss, double limit, bool given,
                            const std::vector<BoundaryPoints>& points) {
  const std::array<int64_t, 3>& p = miss.point;
  return absl::FailedPreconditionError(absl::StrCat(
      "the deformed boundary misses boundary_points[", miss.range, "] by ", miss.distance,
      " at point (", p[0], ", ", p[1], ", ", p[2], ") of block ",
      points[miss.range].range.face.block, " at level ", points[miss.range].level,
      ", more than max_boundary_error = ", limit,
      given ? "" : " (the default: twice the fit's tolerance of the moved boundary's kind)",
      ": the boundary's controls, fitted to the points by least squares, cannot follow a "
      "displacement that varies faster than its knot spans; nothing was stored (give smoother "
      "displacements, fit the grid with a tighter wall tolerance for more wall controls, or "
      "allow a larger max_boundary_error)"));
}

// The refusal of a deformation that folds cells, with what may avoid it. Motions are relative
// to the reference revision, so "less" is less than that, not than the last step. A rotation
// of more than half a turn is its own case: the free controls turn by a fraction of the whole
// angle (rigid_motion.h), so the interior winds around the body (a rotor cannot pass 180
// degrees in one deforming block).
absl::Status Folds(const DeformationCheck& check, const DeformMotion& motion) {
  const Extents& c = check.worst_cell;
  std::string advice =
      "move less relative to the reference revision (or deform relative to a revision nearer "
      "the target), or widen decay_radius";
  if (const auto* rigid = std::get_if<RigidMotion>(&motion);
      rigid != nullptr && std::abs(rigid->angle) > std::numbers::pi) {
    advice = absl::StrCat(
        "a rotation by ", rigid->angle * 180.0 / std::numbers::pi,
        " degrees winds the interior around the body, which turns by a fraction of the whole "
        "angle: the angle reduced into [-180, 180] reaches the same wall with the interior "
        "unwound, but a series passing 180 degrees then jumps a turn inside between steps (a "
        "rotor needs a block that rotates with it)");
  }
  return absl::FailedPreconditionError(absl::StrCat(
      "the deformation folds ", check.folded, " cells at refinement level ", check.level,
      "; the worst in block ", check.worst_block, " at cell (", c[0], ", ", c[1], ", ", c[2],
      ") with Jacobian ratio ", check.min_jacobian_ratio, "; nothing was stored (", advice, ")"));
}

// The deformed revision: the reference's blocks with the moved splines, stamped.
GridRevision DeformedRevision(const GridRevision& reference, const Deformer& deformer,
                              std::vector<FittedBlock> moved, const DeformationCheck& check,
                              const DeformRequest& request) {
  GridRevision revision;
  revision.create_time = absl::Now();
  revision.origin = RevisionOrigin::kDeform;
  revision.parent = reference.number;
  revision.time = request.time;
  revision.step = request.step;
  revision.fit_options = reference.fit_options;
  // The fit's report, as its blocks' summaries below: what the deformation started from, and
  // the tolerances its boundary points are held to (DefaultMaxBoundaryError).
  revision.report = reference.report;
  revision.kinds = reference.kinds;
  revision.blocks = reference.blocks;
  for (size_t b = 0; b < moved.size(); ++b) {
    revision.blocks[b].fitted.spline = std::move(moved[b].spline);
  }
  revision.deform.check = check;
  revision.deform.moved_controls = static_cast<int>(deformer.moved_controls().size());
  revision.deform.decay_radius = deformer.decay_radius();
  return revision;
}

}  // namespace

bool HasKeptDeformer(const OpsContext& context, const DeformRequest& request) {
  return request.reference_revision > 0 &&
         context.deformers.HasReady(
             ShapeKey(request.grid_id, request.reference_revision, request.options),
             request.check_level);
}

absl::StatusOr<bool> DeformIsSmall(const OpsContext& context, const DeformRequest& request) {
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> grid,
                      context.store.GetHolding(request.grid_id, {request.reference_revision}));
  SG_ASSIGN_OR_RETURN(
      const std::shared_ptr<const GridRevision> reference,
      grid->ResolveRevision(request.reference_revision, std::nullopt, "reference_revision"));
  int64_t controls = 0, cells = 0;
  for (const BlockFit& block : reference->blocks) {
    controls += block.fitted.spline.num_control_points();
    int64_t block_cells = 1;
    for (int d = 0; d < 3; ++d) {
      const int64_t points = block.fitted.distribution.num_points(d);
      if (points > 1) block_cells *= (points - 1) << std::clamp(request.check_level, 0, 8);
    }
    cells += block_cells;
  }
  const int64_t sweeps = std::max<int64_t>(request.options.smoothing_iterations, 1);
  if (controls * sweeps > kSmallDeformControlSweeps) return false;
  return context.deformers.HasReady(ShapeKey(grid->id, reference->number, request.options),
                                    request.check_level) ||
         (controls <= kSmallDeformerControls && cells <= kSmallDeformerCells);
}

absl::StatusOr<std::shared_ptr<const GridRevision>> Deform(const OpsContext& context,
                                                           const DeformRequest& request,
                                                           const CancelCheck& cancel) {
  const auto start = std::chrono::steady_clock::now();
  // The base is checked again, atomically, when the revision is added.
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> grid,
                      context.store.GetHolding(
                          request.grid_id, {request.base_revision, request.reference_revision}));
  SG_RETURN_IF_ERROR(context.MayChange(grid->owner, request.grid_id, "deforming"));
  SG_RETURN_IF_ERROR(Validate(request));
  const int64_t latest = grid->revisions.empty() ? 0 : grid->revisions.back()->number;
  if (request.base_revision != 0 && request.base_revision != latest) {
    // Ahead of the latest: not stale, but of another creation of this id or a wrong number.
    return absl::AbortedError(absl::StrCat(
        "grids/", request.grid_id, ": base_revision ", request.base_revision,
        request.base_revision < latest
            ? " is stale"
            : " is ahead of the grid (deleted and created again since, or not a revision of it)",
        "; the latest revision is ", latest));
  }
  SG_ASSIGN_OR_RETURN(
      const std::shared_ptr<const GridRevision> reference,
      grid->ResolveRevision(request.reference_revision, std::nullopt, "reference_revision"));
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const KeptDeformer> kept,
                      context.deformers.Get(DeformerKey(*grid, reference->number, request.options),
                                            [&]() -> absl::StatusOr<Deformer> {
                                              std::vector<FittedBlock> blocks;
                                              for (const BlockFit& b : reference->blocks) {
                                                blocks.push_back(b.fitted);
                                              }
                                              return Deformer::Create(std::move(blocks),
                                                                      reference->kinds,
                                                                      request.options);
                                            }));
  const Deformer& deformer = kept->deformer();
  // A control motion's errors all name its entries (DisplacementsInDeformerOrder checks the
  // values before the deformer sees them): prefixed with the request's field.
  SG_ASSIGN_OR_RETURN(std::vector<FittedBlock> moved, ApplyMotion(deformer, request.motion),
                      std::holds_alternative<std::vector<BlockControlDisplacements>>(request.motion)
                          ? "controls."
                          : "");
  // The fold gate of the reference at the check level is kept with the deformer.
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const DeformationGate> gate,
                      kept->Gate(request.check_level, context.budget, cancel));
  double boundary_error = 0.0;
  if (const auto* points = std::get_if<std::vector<BoundaryPoints>>(&request.motion)) {
    SG_ASSIGN_OR_RETURN(const BoundaryMiss miss, deformer.Miss(moved, *points));
    const bool given = request.max_boundary_error > 0.0;
    const double limit = given ? request.max_boundary_error
                               : DefaultMaxBoundaryError(*grid, *reference, request.options.moved);
    if (miss.distance > limit) return MissesBoundary(miss, limit, given, *points);
    boundary_error = miss.distance;
  }
  SG_ASSIGN_OR_RETURN(const DeformationCheck check, gate->Check(moved, cancel));
  if (!check.ok()) return Folds(check, request.motion);
  GridRevision revision = DeformedRevision(*reference, deformer, std::move(moved), check, request);
  revision.deform.boundary_error = boundary_error;
  revision.deform.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  SG_ASSIGN_OR_RETURN(revision.memory,
                      context.budget.Reserve(RevisionBytes(revision), "the deformed revision"));
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> stored,
                      context.store.AddRevision(request.grid_id, std::move(revision),
                                                request.base_revision, grid->incarnation));
  return stored->revisions.back();
}

}  // namespace splinegrid::server::ops
