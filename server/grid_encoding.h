// Stored grids as splinegrid.v1.Grid messages.
#ifndef SPLINEGRID_SERVER_GRID_ENCODING_H_
#define SPLINEGRID_SERVER_GRID_ENCODING_H_

#include <vector>

#include "absl/status/status.h"
#include "server/grid_store.h"
#include "server/ops/wall_curvature.h"
#include "splinegrid/v1/splinegrid_service.pb.h"

namespace splinegrid::server {

// Largest message the server builds: gRPC's default 4 MiB receive limit, less headroom.
inline constexpr int64_t kMaxMessageBytes = (int64_t{4} << 20) - (64 << 10);

// Fills `out` with `grid` and its revision `revision` (0: latest; none before the first fit).
// FULL view adds knots, control points and distributions of `blocks` (empty: all);
// `with_connectivity` the source's matches (GetGrid, every view; other responses count them). A
// result over kMaxMessageBytes is RESOURCE_EXHAUSTED, naming the size and what to ask for.
absl::Status EncodeGrid(const StoredGrid& grid, int64_t revision, v1::GridView view,
                        const std::vector<int>& blocks, v1::Grid* out,
                        bool with_connectivity = false);

// One entry of a grid's revision history (time and step for deformed revisions only).
void EncodeRevisionInfo(const RevisionSummary& revision, v1::RevisionInfo* out);

// GetWallCurvature's answer: every line's samples (arc length, point, curvature) and the
// metrics over them.
void EncodeWallCurvature(const ops::WallCurvatureResult& result, v1::GetWallCurvatureResponse* out);

// A fitted revision as FitGrid reports it: number, per-block summaries, totals, report.
void EncodeFitResponse(const GridRevision& revision, v1::FitGridResponse* out);

// What a deformation's quality gate measured.
void EncodeDeformReport(const DeformSummary& deform, v1::DeformReport* out);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_GRID_ENCODING_H_
