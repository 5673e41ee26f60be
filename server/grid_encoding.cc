#include "server/grid_encoding.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"
#include "proto/convert/deform_convert.h"
#include "proto/convert/plot3d_format_convert.h"
#include "proto/convert/source_boundaries_convert.h"
#include "server/store/revision_codec.h"

namespace splinegrid::server {

void EncodeRevisionInfo(const RevisionSummary& revision, v1::RevisionInfo* out) {
  out->set_revision(revision.number);
  EncodeStoredTime(revision.create_time, out->mutable_create_time());
  out->set_origin(EncodeRevisionOrigin(revision.origin));
  out->set_parent_revision(revision.parent);
  if (revision.origin == RevisionOrigin::kDeform) {
    out->set_time(revision.time);
    out->set_step(revision.step);
  }
}

void EncodeFitResponse(const GridRevision& revision, v1::FitGridResponse* out) {
  out->set_revision(revision.number);
  for (const BlockFit& block : revision.blocks) {
    EncodeBlockFit(block, revision.fit_options.tolerance_mode(), out->add_blocks());
  }
  const GridFitReport& report = revision.report;
  out->set_num_points(report.num_points);
  out->set_num_control_points(report.num_control_points);
  out->set_compression_ratio(static_cast<double>(report.num_points) /
                             std::max<int64_t>(report.num_control_points, 1));
  out->set_max_deviation(report.max_deviation);
  out->set_seconds(report.seconds);
  EncodeFitReport(report, revision.blocks, out->mutable_report());
  out->mutable_report()->set_tolerances_given(revision.fit_options.tolerance_mode());
}

void EncodeDeformReport(const DeformSummary& deform, v1::DeformReport* out) {
  EncodeDeformationCheck(deform.check, out);
  out->set_moved_controls(deform.moved_controls);
  out->set_decay_radius(std::isfinite(deform.decay_radius) ? deform.decay_radius : 0.0);
  out->set_seconds(deform.seconds);
  out->set_boundary_error(deform.boundary_error);
}

absl::Status EncodeGrid(const StoredGrid& grid, int64_t revision, v1::GridView view,
                        const std::vector<int>& blocks, v1::Grid* out, bool with_connectivity) {
  out->set_name(absl::StrCat("grids/", grid.id));
  out->set_display_name(grid.display_name);
  out->set_owner(grid.owner);
  EncodeStoredTime(grid.create_time, out->mutable_create_time());
  const MultiBlockGrid& source = grid.source->grid();
  v1::SourceGrid* src = out->mutable_source();
  src->set_spatial_dim(source.blocks.front().spatial_dim());
  int64_t points = 0;
  for (const StructuredBlock& block : source.blocks) {
    EncodeExtents(block.extents(), src->add_blocks());
    points += block.num_points();
  }
  src->set_num_points(points);
  src->set_format(grid.source->format);
  if (grid.source->plot3d.has_value()) {
    EncodePlot3dSourceFormat(*grid.source->plot3d, src->mutable_plot3d());
  }
  const std::vector<BoundaryMatch>& matches = grid.source->connectivity().matches;
  src->set_num_matches(static_cast<int>(matches.size()));
  // GetGrid, every view: a writer of CGNS needs the connectivity without the nets.
  if (with_connectivity) {
    for (const BoundaryMatch& m : matches) EncodeBoundaryMatch(m, src->add_connectivity());
  }
  if (!grid.source->boundaries.empty()) {  // small: every view (the import notes are here)
    EncodeSourceBoundaries(grid.source->boundaries, src->mutable_boundaries());
  }
  for (const auto& r : grid.revisions) {
    EncodeRevisionInfo(RevisionSummary::Of(*r), out->add_revisions());
  }
  if (grid.revisions.empty() && revision == 0) return absl::OkStatus();  // not fitted yet
  SG_ASSIGN_OR_RETURN(const std::shared_ptr<const GridRevision> found,
                      grid.ResolveRevision(revision));
  out->set_latest_revision(grid.revisions.back()->number);
  const GridRevision& rev = *found;
  const int num_blocks = static_cast<int>(rev.blocks.size());
  for (int b : blocks) {
    if (b < 0 || b >= num_blocks) {
      return absl::InvalidArgumentError(
          absl::StrCat("blocks: ", b, " is outside [0, ", num_blocks - 1, "]"));
    }
  }
  v1::Revision* r = out->mutable_revision();
  r->set_revision(rev.number);
  EncodeStoredTime(rev.create_time, r->mutable_create_time());
  r->set_origin(EncodeRevisionOrigin(rev.origin));
  EncodeFitSpec(rev.fit_options, r->mutable_fit_spec());
  r->set_num_control_points(rev.num_control_points());
  r->set_compression_ratio(static_cast<double>(points) /
                           std::max<int64_t>(rev.num_control_points(), 1));
  r->set_max_deviation(rev.max_deviation());
  if (rev.origin != RevisionOrigin::kDeform) {
    EncodeFitReport(rev.report, rev.blocks, r->mutable_report());
    r->mutable_report()->set_tolerances_given(rev.fit_options.tolerance_mode());
  } else {
    r->set_time(rev.time);
    r->set_step(rev.step);
    EncodeDeformReport(rev.deform, r->mutable_deform_report());
  }
  r->set_parent_revision(rev.parent);
  const bool full = view == v1::GRID_VIEW_FULL;
  auto wanted = [&](int b) {
    return blocks.empty() || std::find(blocks.begin(), blocks.end(), b) != blocks.end();
  };
  if (full) {
    // Refuse before building a message that cannot be sent.
    int64_t estimate = 0;
    for (int b = 0; b < num_blocks; ++b) {
      if (wanted(b)) estimate += FittedBlockBytes(rev.blocks[b].fitted);
    }
    if (estimate > kMaxMessageBytes) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "the FULL view of grids/", grid.id, " needs about ", estimate >> 10,
          " KiB, over the 4 MiB message limit; ask for fewer blocks at a time (field blocks)"));
    }
  }
  for (int b = 0; b < num_blocks; ++b) {
    v1::SplineBlock* block = r->add_blocks();
    EncodeSplineBlock(rev.blocks[b].fitted, b, full && wanted(b), block);
    EncodeBlockFit(rev.blocks[b], rev.fit_options.tolerance_mode(), block->mutable_fit());
  }
  const int64_t bytes = static_cast<int64_t>(out->ByteSizeLong());
  if (bytes > kMaxMessageBytes) {
    return absl::ResourceExhaustedError(
        full ? absl::StrCat("the FULL view of grids/", grid.id, " is ", bytes >> 10,
                            " KiB, over the 4 MiB message limit; ask for fewer blocks at a time "
                            "(field blocks)")
             : absl::StrCat("the description of grids/", grid.id, " is ", bytes >> 10, " KiB (",
                            matches.size(), " matched boundary ranges, ", rev.blocks.size(),
                            " blocks), over the 4 MiB message limit"));
  }
  return absl::OkStatus();
}

void EncodeWallCurvature(const ops::WallCurvatureResult& result,
                         v1::GetWallCurvatureResponse* out) {
  out->set_revision(result.revision);
  out->set_spatial_dim(result.spatial_dim);
  for (const ops::WallCurvatureLine& line : result.lines) {
    EncodeWallCurvatureLine(line.line, line.samples, result.spatial_dim, out->add_lines());
  }
  EncodeCurvature(result.metrics, out->mutable_metrics());
}

}  // namespace splinegrid::server
