// Pieces shared by the Plot3D text and binary readers and writers; not a public API.
#ifndef SPLINEGRID_CORE_IO_PLOT3D_INTERNAL_H_
#define SPLINEGRID_CORE_IO_PLOT3D_INTERNAL_H_

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/grid/structured_grid.h"
#include "core/io/plot3d.h"

namespace splinegrid::plot3d_internal {

// Most blocks a file may declare.
inline constexpr int64_t kMaxBlocks = int64_t{1} << 20;
// Largest extent ni, nj or nk (the default of ValidateExtents).
inline constexpr int64_t kMaxExtent = int64_t{1} << 24;
// Most points in one block (the default of ValidateExtents).
inline constexpr int64_t kMaxBlockPoints = int64_t{1} << 31;

// "plot3d 'source': ", the prefix of every error message.
std::string ErrorPrefix(std::string_view source);

// "ni", "nj" or "nk" for direction 0, 1, 2.
const char* ExtentName(int direction);

// Points of `extents` when it is at most kMaxBlockPoints (every extent must be in
// [1, kMaxExtent]); -1 when larger. Never overflows.
int64_t CheckedNumPoints(const Extents& extents);

// "ni x nj x nk = N points exceeds the limit of ..." for a block whose CheckedNumPoints is -1.
std::string TooManyPointsMessage(const Extents& extents);

// Where value `index_in_block` of a block's data lies: "y of point (3, 4, 0)" or
// "iblank of point (...)". A block's data is spatial_dim sections of num_points values, then
// (with iblank) one more section.
std::string DescribeBlockValue(const Extents& extents, int spatial_dim, int64_t index_in_block);

// The block holding value `offset` counted from the first value after the header, and the
// value's index inside that block, for blocks of `extents` with `values_per_point` values
// (spatial_dim, plus 1 with iblank) per point. Block == extents.size() when past the end.
struct BlockValue {
  int64_t block = 0;           // 0-based block index
  int64_t index_in_block = 0;  // index into that block's data
};
BlockValue LocateBlockValue(const std::vector<Extents>& extents, int values_per_point,
                            int64_t offset);

// Text reader: see the file comment of plot3d.h. `text` is the whole file.
absl::StatusOr<MultiBlockGrid> ParsePlot3dText(std::string_view text, std::string_view source,
                                               Plot3dFormat* detected);

// Binary reader: see the file comment of plot3d.h. `bytes` is the whole file.
absl::StatusOr<MultiBlockGrid> ParsePlot3dBinary(std::string_view bytes, std::string_view source,
                                                 Plot3dFormat* detected);

// Text writer. Precondition: `grid` and `format` passed the checks of EncodePlot3d.
std::string EncodePlot3dText(const MultiBlockGrid& grid, const Plot3dFormat& format);

// Binary writer. Precondition as for EncodePlot3dText; fails when a record is too large for a
// 4-byte marker or a coordinate does not fit single precision.
absl::StatusOr<std::string> EncodePlot3dBinary(const MultiBlockGrid& grid,
                                               const Plot3dFormat& format);

}  // namespace splinegrid::plot3d_internal

#endif  // SPLINEGRID_CORE_IO_PLOT3D_INTERNAL_H_
