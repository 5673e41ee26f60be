#include "server/ops/generate.h"

#include <chrono>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/bspline/evaluation.h"
#include "core/grid/connectivity.h"
#include "core/grid/sampling.h"
#include "core/util/status_macros.h"
#include "server/ops/generated_grid.h"

namespace splinegrid::server::ops {
namespace {

// Reverses `points` when they run clockwise (Selig order runs counter-clockwise).
void MakeCounterClockwise(StructuredBlock& points) {
  std::span<double> c = points.coords();
  const int64_t m = points.num_points();
  double area = 0.0;  // twice the signed area
  for (int64_t q = 0; q < m; ++q) {
    const int64_t r = (q + 1) % m;
    area += c[2 * q] * c[2 * r + 1] - c[2 * r] * c[2 * q + 1];
  }
  if (area >= 0.0) return;
  for (int64_t q = 0; q < m / 2; ++q) {
    std::swap(c[2 * q], c[2 * (m - 1 - q)]);
    std::swap(c[2 * q + 1], c[2 * (m - 1 - q) + 1]);
  }
}

// The wall points of block `wall.block`'s j = 0 edge of a stored revision, evaluated at the
// original resolution: the one run of points whose kind includes wall, in Selig orientation.
absl::StatusOr<ProfilePoints> StoredWallProfile(GridStore& store, const StoredWall& wall) {
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> grid, store.Get(wall.grid_id));
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const GridRevision> revision,
                      grid->ResolveRevision(wall.revision, std::nullopt, "stored_wall.revision"));
  const int num_blocks = static_cast<int>(revision->blocks.size());
  const int b = wall.block;
  if (b < 0 || b >= num_blocks) {
    return absl::InvalidArgumentError(
        absl::StrCat("stored_wall.block = ", b, " is outside [0, ", num_blocks - 1, "]"));
  }
  const StructuredBlock& source = grid->source->grid().blocks[b];
  const Extents& n = source.extents();
  if (source.spatial_dim() != 2 || n[2] != 1 || n[1] < 2) {
    return absl::InvalidArgumentError(absl::StrCat(
        "stored_wall.block = ", b, " of grids/", wall.grid_id, " is ", n[0], "x", n[1], "x", n[2],
        " with ", source.spatial_dim(), " coordinates; a wall profile needs a planar 2D block"));
  }
  const std::vector<uint8_t>& kinds = revision->kinds.point_kinds[b];
  auto is_wall = [&](int i) { return (kinds[i] & static_cast<uint8_t>(BoundaryKind::kWall)) != 0; };
  int first = -1, last = -1, runs = 0;
  for (int i = 0; i < n[0]; ++i) {
    if (!is_wall(i)) continue;
    if (i == 0 || !is_wall(i - 1)) ++runs;
    if (first < 0) first = i;
    last = i;
  }
  const std::string edge =
      absl::StrCat("grids/", wall.grid_id, " revision ", revision->number, " block ", b, " j = 0");
  if (runs == 0) {
    return absl::FailedPreconditionError(
        absl::StrCat(edge, " has no wall points (see FitSpec.face_kinds)"));
  }
  if (runs > 1) {
    return absl::FailedPreconditionError(absl::StrCat(
        edge, " has ", runs, " separate runs of wall points; a profile needs exactly one"));
  }
  Resolution resolution;  // level 0, the wall run
  resolution.box = IndexBox{{first, 0, 0}, {last, 0, 0}};
  const FittedBlock& fitted = revision->blocks[b].fitted;
  SG_ASSIGN_OR_RETURN(const auto params, SampleParameters(fitted.distribution, resolution));
  ProfilePoints out{EvaluateGrid(fitted.spline, params),
                    absl::StrCat(edge, " i = ", first, "..", last)};
  MakeCounterClockwise(out.points);
  return out;
}

// The points of the generated block: wall_points * (layers + 1), in 64 bits.
int64_t GeneratedPoints(const ProfileGridOptions& options) {
  return int64_t{options.wall_points} * (int64_t{options.layers} + 1);
}

}  // namespace

absl::StatusOr<GenerateResult> Generate(const OpsContext& context, GenerateRequest request,
                                        const CancelCheck& cancel) {
  const NewGridHeader header{request.grid_id, request.display_name, request.owner};
  const int64_t points = GeneratedPoints(request.options);
  SG_RETURN_IF_ERROR(
      CheckNewGrid(context, header, points, "wall_points * (layers + 1)", request.max_points));
  // The fit of revision 1: the request's, or else interpolation (a control point per grid
  // point, like FitGrid without a spec). The default tolerances by kind are meant for
  // chord-sized cells: a wall tolerance of 1.5e-4 against a first layer of 1e-5 folds the wall
  // cells, so a generated grid is kept exact unless the request asks for compression. Unless
  // the fit names face kinds, the O-grid's j = 0 is the wall and j = max the outer boundary
  // (the seam is an interface through the connectivity), independent of the clustering
  // heuristics.
  const GridFitOptions fit_options =
      GeneratedGridFit(request.fit, GridFitOptions(), request.allow_folds, 1, /*outward=*/1);
  const bool bare_points = std::holds_alternative<ProfilePoints>(request.profile) &&
                           std::get<ProfilePoints>(request.profile).name.empty();
  ProfilePoints profile;
  if (auto* wall = std::get_if<StoredWall>(&request.profile)) {
    SG_ASSIGN_OR_RETURN(profile, StoredWallProfile(context.store, *wall));
  } else {
    profile = std::move(std::get<ProfilePoints>(request.profile));
  }

  // The generated block, as the source points of the new grid.
  GenerateResult result;
  auto source = std::make_shared<SourcePoints>();
  SG_ASSIGN_OR_RETURN(source->memory, context.budget.Reserve(points * 2 * int64_t{sizeof(double)},
                                                             "the generated grid"));
  request.options.cancel = cancel;
  SG_ASSIGN_OR_RETURN(result.generated, GenerateProfileGrid(profile.points, request.options));
  const ProfileGrid& generated = result.generated;
  if (generated.quality.negative_cells > 0) {  // the kernel should prevent this: never store one
    return absl::FailedPreconditionError(absl::StrCat(
        "the generated ", std::string(LayerMethodName(request.options.method)), " grid has ",
        generated.quality.negative_cells, " cells of non-positive area (smallest ",
        generated.quality.min_cell_area,
        "); nothing was stored (try more wall_points, a smaller first_height or the other "
        "method)"));
  }
  const Extents n = generated.block.extents();
  source->format = absl::StrFormat("generated %s O-grid %dx%d around %s",
                                   LayerMethodName(request.options.method), n[0], n[1],
                                   bare_points ? "points" : absl::StrCat("'", profile.name, "'"));
  MultiBlockGrid generated_grid;
  generated_grid.blocks.push_back(std::move(result.generated.block));
  SG_ASSIGN_OR_RETURN(result.grid, StoreGenerated(context, header, profile.name, std::move(source),
                                                  std::move(generated_grid), fit_options, cancel));
  result.options = request.options;
  // The defaults resolved (fractions of the profile's chord).
  result.options.fit_tolerance = result.generated.fit_tolerance;
  result.options.first_height = result.generated.first_height;
  result.options.distance = result.generated.distance;
  result.options.cancel = {};
  result.profile_name = std::move(profile.name);
  result.profile_points = profile.points.num_points();
  return result;
}

}  // namespace splinegrid::server::ops
