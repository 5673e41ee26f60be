// Pieces shared by the Plot3D text and binary readers and writers; not a public API.
#ifndef SPLINEGRID_CORE_IO_PLOT3D_INTERNAL_H_
#define SPLINEGRID_CORE_IO_PLOT3D_INTERNAL_H_

#include <bit>
#include <cstdint>
#include <cstring>
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

// Points per slab of a block: a slab is what the layout stores together, the whole block
// (kWhole, and every 2D block) or one k-plane of ni * nj points (kPlanes). A block has
// num_points / SlabPoints slabs; slab k holds points [k * SlabPoints, (k + 1) * SlabPoints).
int64_t SlabPoints(const Extents& extents, Plot3dLayout layout);

// The whole-layout index (section * points + point, as DescribeBlockValue takes it) of value
// `index_in_block` of a block stored in `layout` with `values_per_point` values per point.
int64_t WholeLayoutIndex(const Extents& extents, int values_per_point, Plot3dLayout layout,
                         int64_t index_in_block);

// "whole" or "planes".
const char* LayoutName(Plot3dLayout layout);

// Reads and writes fixed-size numbers in one byte order.
class ByteOrder {
 public:
  // Numbers stored big-endian when `big_endian`, else little-endian.
  explicit ByteOrder(bool big_endian)
      : swap_(big_endian != (std::endian::native == std::endian::big)) {}

  // The int32 at `p`.
  int32_t Int32(const char* p) const { return static_cast<int32_t>(Load32(p)); }
  // The float (as double) at `p`.
  double Float32(const char* p) const { return std::bit_cast<float>(Load32(p)); }
  // The double at `p`.
  double Float64(const char* p) const {
    uint64_t bits;
    std::memcpy(&bits, p, 8);
    return std::bit_cast<double>(swap_ ? __builtin_bswap64(bits) : bits);
  }
  // Stores `value` at `p`.
  void PutInt32(int32_t value, char* p) const { Store32(static_cast<uint32_t>(value), p); }
  // Stores `value` at `p`.
  void PutFloat32(float value, char* p) const { Store32(std::bit_cast<uint32_t>(value), p); }
  // Stores `value` at `p`.
  void PutFloat64(double value, char* p) const {
    uint64_t bits = std::bit_cast<uint64_t>(value);
    if (swap_) bits = __builtin_bswap64(bits);
    std::memcpy(p, &bits, 8);
  }

 private:
  // The 4 bytes at `p` in native order.
  uint32_t Load32(const char* p) const {
    uint32_t bits;
    std::memcpy(&bits, p, 4);
    return swap_ ? __builtin_bswap32(bits) : bits;
  }
  // Stores the 4 bytes of `bits` at `p`.
  void Store32(uint32_t bits, char* p) const {
    if (swap_) bits = __builtin_bswap32(bits);
    std::memcpy(p, &bits, 4);
  }

  bool swap_;
};

// How the values of a binary block are stored.
struct BinaryValues {
  ByteOrder order{false};
  int bytes_per_real = 8;  // 4 or 8
  bool has_iblank = false;
  // Refuse subnormal coordinates and iblank values beyond +-kMaxBlocks (C-stream detection: no
  // grid has them, but integers of a header read as reals, or reals read as iblank, do, so a
  // hypothesis that reads them is the wrong one).
  bool reject_subnormal = false;
  // Bytes of a slab of `n` points with `dim` coordinates.
  int64_t SlabBytes(int64_t n, int dim) const {
    return n * (dim * bytes_per_real + (has_iblank ? 4 : 0));
  }
};

// Reads the slab of `block` (spatial_dim sections of n reals, then n int32 iblank values when
// values.has_iblank) starting at point `first` from `data` (a pointer into `file`); `n` is
// SlabPoints. Block data are allocated by the caller (iblank too). INVALID_ARGUMENT for a
// non-finite coordinate, naming source, block `b`, the point, the byte offset and `where`;
// OUT_OF_RANGE for a subnormal one or an iblank beyond +-kMaxBlocks when
// values.reject_subnormal.
absl::Status ReadBinarySlab(std::string_view file, const char* data, const BinaryValues& values,
                            int64_t b, int64_t first, int64_t n, std::string_view source,
                            std::string_view where, StructuredBlock* block);

// Writes the slab of `block` starting at point `first` with `n` points to `out` (SlabBytes
// bytes). INVALID_ARGUMENT (naming block `b`) when a coordinate does not fit single precision.
absl::Status WriteBinarySlab(const StructuredBlock& block, int64_t b, int64_t first, int64_t n,
                             const BinaryValues& values, char* out);

// Text reader: see the file comment of plot3d.h. `text` is the whole file.
absl::StatusOr<MultiBlockGrid> ParsePlot3dText(std::string_view text, std::string_view source,
                                               const Plot3dReadOptions& options,
                                               Plot3dFormat* detected);

// Fortran record reader: see the file comment of plot3d.h. `bytes` is the whole file.
// `*looks_fortran` says whether the first two records' markers are valid in some byte order (a
// file that fails later is then a damaged Fortran file, never read as a C stream: a cut
// Fortran file could otherwise add up as some stream layout).
absl::StatusOr<MultiBlockGrid> ParsePlot3dBinary(std::string_view bytes, std::string_view source,
                                                 const Plot3dReadOptions& options,
                                                 Plot3dFormat* detected, bool* looks_fortran);

// C-stream reader: see the file comment of plot3d.h. `*layout_found` says whether some
// hypothesis added up (then the error is about the data, with the source prefix); otherwise
// the error has no prefix and says what was tried (ParsePlot3d combines it with the Fortran
// reader's).
absl::StatusOr<MultiBlockGrid> ParsePlot3dStream(std::string_view bytes, std::string_view source,
                                                 const Plot3dReadOptions& options,
                                                 Plot3dFormat* detected, bool* layout_found);

// Text writer. Precondition: `grid` and `format` passed the checks of EncodePlot3d.
std::string EncodePlot3dText(const MultiBlockGrid& grid, const Plot3dFormat& format);

// Binary writer. Precondition as for EncodePlot3dText; fails when a record is too large for a
// 4-byte marker or a coordinate does not fit single precision.
absl::StatusOr<std::string> EncodePlot3dBinary(const MultiBlockGrid& grid,
                                               const Plot3dFormat& format);

}  // namespace splinegrid::plot3d_internal

#endif  // SPLINEGRID_CORE_IO_PLOT3D_INTERNAL_H_
