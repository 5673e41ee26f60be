#include "server/ops/generate_volume.h"

#include <chrono>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/bspline/evaluation.h"
#include "core/grid/connectivity_edit.h"
#include "core/grid/sampling.h"
#include "core/util/status_macros.h"
#include "server/ops/generated_grid.h"

namespace splinegrid::server::ops {
namespace {

// The default fit of revision 1: interpolation with uniform parameters. Chord lengths averaged
// over each block's lines differ between two blocks along their shared face, and so would their
// face splines between the grid points; uniform parameters and one control point per point make
// both faces the interpolant of the same face points on the same knots.
GridFitOptions UniformInterpolation() {
  GridFitOptions options;
  options.parametrization = Parametrization::kUniform;
  return options;
}

// The stored surface: every block of the revision evaluated at the original resolution, and
// the grid's connectivity (of its source points, whose index space the evaluation keeps).
struct Surface {
  MultiBlockGrid grid;
  Connectivity connectivity;
  std::string name;  // "grids/{id} revision {n}"
};

absl::StatusOr<Surface> StoredSurfaceBlocks(GridStore& store, const StoredSurface& surface) {
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> grid, store.Get(surface.grid_id));
  SG_ASSIGN_OR_RETURN(
      const std::shared_ptr<const GridRevision> revision,
      grid->ResolveRevision(surface.revision, std::nullopt, "stored_surface.revision"));
  Surface out;
  out.name = absl::StrCat("grids/", surface.grid_id, " revision ", revision->number);
  for (size_t b = 0; b < revision->blocks.size(); ++b) {
    const StructuredBlock& source = grid->source->grid().blocks[b];
    const Extents& n = source.extents();
    if (source.spatial_dim() != 3 || n[2] != 1 || n[0] < 2 || n[1] < 2) {
      return absl::InvalidArgumentError(
          absl::StrCat("stored_surface.name: block ", b, " of ", out.name, " is ", n[0], "x", n[1],
                       "x", n[2], " with ", source.spatial_dim(),
                       " coordinates; layers are marched off surface blocks (ni x nj x 1 in 3D)"));
    }
    const FittedBlock& fitted = revision->blocks[b].fitted;
    SG_ASSIGN_OR_RETURN(const auto params, SampleParameters(fitted.distribution, Resolution{}));
    out.grid.blocks.push_back(EvaluateGrid(fitted.spline, params));
  }
  out.connectivity = grid->source->connectivity();
  return out;
}

// The generated points: every surface block's times (layers + 1), in 64 bits.
int64_t GeneratedPoints(const MultiBlockGrid& surface, int layers) {
  int64_t points = 0;
  for (const StructuredBlock& block : surface.blocks) points += block.num_points();
  return points * (int64_t{layers} + 1);
}

}  // namespace

absl::StatusOr<GenerateVolumeResult> GenerateVolume(const OpsContext& context,
                                                    GenerateVolumeRequest request,
                                                    const CancelCheck& cancel) {
  const NewGridHeader header{request.grid_id, request.display_name, request.owner};
  // The id and name first: a taken id needs no surface.
  SG_RETURN_IF_ERROR(CheckNewGrid(context, header, 0, "", request.max_points));
  SG_RETURN_IF_ERROR(request.options.Validate());
  SG_ASSIGN_OR_RETURN(Surface surface, StoredSurfaceBlocks(context.store, request.surface));
  const int64_t points = GeneratedPoints(surface.grid, request.options.layers);
  SG_RETURN_IF_ERROR(
      CheckNewGrid(context, header, points, "surface points * (layers + 1)", request.max_points));
  const int num_blocks = static_cast<int>(surface.grid.blocks.size());
  const GridFitOptions fit_options =
      GeneratedGridFit(request.fit, UniformInterpolation(), request.allow_folds, num_blocks,
                       /*outward=*/2);

  GenerateVolumeResult result;
  auto source = std::make_shared<SourcePoints>();
  SG_ASSIGN_OR_RETURN(source->memory, context.budget.Reserve(points * 3 * int64_t{sizeof(double)},
                                                             "the generated grid"));
  request.options.cancel = cancel;
  const auto start = std::chrono::steady_clock::now();
  SG_ASSIGN_OR_RETURN(result.generated,
                      OffsetSurfaceGrid(surface.grid, surface.connectivity, request.options));
  result.layer_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // The volume's connectivity is the surface's, extruded along k (and renumbered where i is
  // reversed): finding it again costs far more than the march on a deep stack.
  Connectivity connectivity = Extruded(surface.connectivity, request.options.layers);
  MultiBlockGrid volume;
  for (int b = 0; b < num_blocks; ++b) {
    StructuredBlock& block = result.generated.blocks[b];
    const bool reverse = result.generated.sides[b] < 0;
    result.reversed_i.push_back(reverse);
    if (reverse) {
      ReverseDirection(block, 0);
      ReverseBlockDirection(connectivity, b, 0, block.extents());
    }
    volume.blocks.push_back(std::move(block));
  }
  result.generated.blocks.clear();
  source->format = absl::StrFormat("generated volume grid of %d blocks, %d layers off %s",
                                   num_blocks, request.options.layers, surface.name);
  SG_ASSIGN_OR_RETURN(
      result.grid, StoreGenerated(context, header, surface.name, std::move(source),
                                  std::move(volume), fit_options, cancel, std::move(connectivity)));
  result.options = request.options;
  result.options.cancel = {};
  return result;
}

}  // namespace splinegrid::server::ops
