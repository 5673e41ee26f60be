#include "server/ops/import.h"

#include "absl/strings/str_cat.h"
#include "core/io/planar_view.h"
#include "core/io/plot3d_memory.h"
#include "core/util/status_macros.h"

namespace splinegrid::server::ops {

absl::StatusOr<ImportedSource> ReadPlot3dUpload(const OpsContext& context, const std::string& bytes,
                                                const Plot3dReadOptions& options,
                                                PlanarViewChoice planar, MemoryReservation memory) {
  ImportedSource source;
  source.memory = std::move(memory);
  MemoryBudget& budget = context.budget;
  SG_RETURN_IF_ERROR(
      budget.Resize(&source.memory, Plot3dParseBytesBound(bytes), "parsing the Plot3D upload"));
  Plot3dFormat detected;
  SG_ASSIGN_OR_RETURN(MultiBlockGrid grid, ParsePlot3d(bytes, "upload", options, &detected));
  SG_RETURN_IF_ERROR(budget.Resize(&source.memory, SourceBytes(grid), "the imported grid"));
  source.imported.format = absl::StrCat("plot3d ", DescribePlot3dFormat(detected));
  source.plot3d.emplace().file = detected;  // kept so evaluations can be written back alike
  if (planar == PlanarViewChoice::kAlways ||
      (planar == PlanarViewChoice::kIfTwoPlanes && IsTwoPlaneGrid(grid))) {
    SG_RETURN_IF_ERROR(budget.Resize(&source.memory, 2 * SourceBytes(grid), "the planar view"));
    SG_ASSIGN_OR_RETURN(grid, PlanarView(grid, {}, &source.plot3d->two_planes));
    absl::StrAppend(&source.imported.format, ", planar view");
  }
  source.imported.grid = std::move(grid);
  return source;
}

absl::StatusOr<std::shared_ptr<const StoredGrid>> StoreImported(const OpsContext& context,
                                                                const ImportRequest& request,
                                                                ImportedSource source) {
  ImportedGrid& imported = source.imported;
  auto points = std::make_shared<SourcePoints>();
  const int64_t bytes = SourceBytes(imported.grid);
  SG_ASSIGN_OR_RETURN(points->checked,
                      FittableGrid::Check(std::move(imported.grid), {}, request.cancel));
  SG_RETURN_IF_ERROR(context.budget.Resize(&source.memory, bytes, "the imported grid"));
  points->memory = std::move(source.memory);
  for (std::string& note : CompareConnections(imported.connections, points->connectivity(),
                                              imported.boundaries.block_names)) {
    imported.boundaries.notes.push_back(std::move(note));
  }
  points->format = std::move(imported.format);
  points->boundaries = std::move(imported.boundaries);
  points->plot3d = std::move(source.plot3d);
  auto grid = std::make_shared<StoredGrid>();
  grid->display_name = request.display_name;
  grid->owner = request.owner;
  grid->create_time = absl::Now();
  grid->source = std::move(points);
  SG_RETURN_IF_ERROR(CreateGrid(context.store, request.grid_id, grid));
  return grid;
}

}  // namespace splinegrid::server::ops
