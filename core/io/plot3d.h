// Plot3D grid files: reading with layout detection, and writing; function files (.f) for
// point fields such as derivatives.
//
// A Plot3D grid file holds, in order,
//   [nblocks]                      the block-count line/record (absent in "single-grid" files)
//   ni nj [nk] for every block     2D files have no nk (the block is ni x nj x 1)
//   per block, "whole" layout:     all x, all y, [all z], [all iblank], i fastest, then j, then k
//   or, 3D "planes" layout:        for k = 0 .. nk-1: x, y, z, [iblank] of plane k (i, then j)
// as formatted text, as Fortran unformatted sequential records (a 4-byte length marker before
// and after each record; records: [nblocks], [all dims], then one record per block, or per
// k-plane in the planes layout, as the PLOT3D manual's READ loops write them), or as a C stream
// (the same numbers without record markers: Pointwise "binary", cgns_to_plot3d's default).
//
// Reading detects the layout from the data:
//   * text vs binary: a file is binary when one of its first 4 bytes is not printable ASCII or
//     whitespace (a record marker of a small record always has a zero byte there).
//   * text: every number is tokenized once (whitespace/comma separated, Fortran "n*value" repeats,
//     D/d exponents, see fortran_text.h), then the 8 hypotheses {block-count line or not} x
//     {2D, 3D} x {iblank or not} are tested: the header values must be positive integer literals,
//     the header must end at a line break (unless the whole file is one line; every writer we
//     know starts the coordinates on a new line, and the rule stops a truncated file from
//     passing as a smaller one of another layout), iblank values must be integers, and the
//     number of values must match the header exactly. When several match, the first in this order
//     wins: block-count line present, then 3D, then no iblank. When none matches, the error
//     describes the best candidate (e.g. "expected 2*113*33 = 7458 coordinates after the header,
//     found 7457"). Without a block-count line a file holds exactly one block.
//   * binary: Fortran records first: the record markers fix the byte order (both markers of
//     every record must agree); a 4-byte first record is the block count; the dims record length
//     gives 2D or 3D; the first block record's length gives single/double precision and iblank,
//     and whether it holds the whole block or one k-plane (planes layout).
//     When the file is not a complete Fortran record file, it is read as a C stream: the
//     hypotheses {little, big endian} x {block count or not} x {3D, 2D} x {double, single} x
//     {no iblank, iblank} are tried in this order and the first whose header is in range and
//     whose sizes add up to the file size exactly (and whose coordinates are finite) wins;
//     otherwise INVALID_ARGUMENT says what was tried and why each record/size failed.
//   * planes vs whole in text and C-stream files: both hold the same number of values, so the
//     layout is not detected; they are read whole unless Plot3dReadOptions::layout says planes.
//   Limitation: a text file cut inside its last number, or exactly between the coordinates and the
//   iblank values, is itself a valid file and cannot be detected as truncated. A C-stream file
//   has only its size to go by: the stream hypotheses also refuse subnormal coordinates and
//   iblank values beyond +-kMaxBlocks (header integers read as reals, reals read as iblank), but
//   a file cut to exactly the size of another layout (a double file cut to the size of its
//   single-precision form) still reads as that layout. A file whose first two Fortran records
//   are well formed is never read as a C stream (a damaged Fortran file stays an error).
//
// Every error is INVALID_ARGUMENT (NOT_FOUND for a missing file) and names the source, the block
// (numbered from 0, as in MultiBlockGrid::blocks) and the position: line and column for text,
// record number and byte offset for binary. Sizes are checked against the data present before
// anything is allocated; NaN/Inf coordinates are rejected.
#ifndef SPLINEGRID_CORE_IO_PLOT3D_H_
#define SPLINEGRID_CORE_IO_PLOT3D_H_

#include <optional>
#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

// How a Plot3D file stores its numbers.
enum class Plot3dEncoding {
  kAscii,               // formatted text
  kBinaryLittleEndian,  // Fortran unformatted records, little-endian
  kBinaryBigEndian,     // Fortran unformatted records, big-endian
};

// How a binary Plot3D file frames its numbers.
enum class Plot3dFraming {
  kFortranRecords,  // 4-byte length markers around each record (Fortran unformatted sequential)
  kCStream,         // the numbers only (C fwrite, Fortran access='stream')
};

// The order of a 3D block's values (see the file comment). 2D files are always whole.
enum class Plot3dLayout {
  kWhole,   // all x, all y, all z, [all iblank]
  kPlanes,  // per k-plane: x, y, z, [iblank] of that plane
};

// The layout of a Plot3D file: what ParsePlot3d detected, or what EncodePlot3d writes.
struct Plot3dFormat {
  // Text or binary, and the byte order of binary files.
  Plot3dEncoding encoding = Plot3dEncoding::kAscii;
  // 2 (ni nj; x, y) or 3 (ni nj nk; x, y, z). Must equal every block's spatial_dim when writing.
  int spatial_dim = 3;
  // Whether the file starts with the number of blocks. False means a single-block file.
  bool has_block_count = true;
  // Whether every block ends with one integer iblank per point. When writing, true requires
  // every block to have iblank; false writes no iblank even when blocks have it.
  bool has_iblank = false;
  // Bytes per coordinate in binary files: 4 (single) or 8 (double). Text: 8 when read, ignored
  // when written (text is always written with round-trip precision).
  int bytes_per_real = 8;
  // Binary files: with or without Fortran record markers. Ignored for text.
  Plot3dFraming framing = Plot3dFraming::kFortranRecords;
  // Value order of 3D blocks; kWhole for 2D files.
  Plot3dLayout layout = Plot3dLayout::kWhole;
};

// Choices ParsePlot3d cannot make from the data alone.
struct Plot3dReadOptions {
  // kPlanes reads text and C-stream 3D files in the planes layout. Fortran record files are
  // detected from their records whatever this says (an explicit kWhole/kPlanes that
  // contradicts the records is an error).
  std::optional<Plot3dLayout> layout;
};

// "ASCII 3D, block-count line, no iblank" style summary of `format`, for messages and logs.
std::string DescribePlot3dFormat(const Plot3dFormat& format);

// The natural format for writing `grid` with `encoding`: its spatial_dim, block count present,
// iblank when every block has it, double precision.
Plot3dFormat DefaultPlot3dFormat(const MultiBlockGrid& grid, Plot3dEncoding encoding);

// Parses the Plot3D grid in `bytes` (the whole file), detecting the layout as described in the
// file comment; `source_name` (usually the path) prefixes error messages. When `detected` is not
// null it receives the layout found. Blocks of 2D files have spatial_dim 2 and extents
// (ni, nj, 1). O(size of bytes); the only allocations besides the grid are 8 bytes per text
// token.
absl::StatusOr<MultiBlockGrid> ParsePlot3d(std::string_view bytes, std::string_view source_name,
                                           Plot3dFormat* detected = nullptr);
// The same with read options.
absl::StatusOr<MultiBlockGrid> ParsePlot3d(std::string_view bytes, std::string_view source_name,
                                           const Plot3dReadOptions& options,
                                           Plot3dFormat* detected = nullptr);

// Reads and parses the Plot3D grid file at `path` (see ParsePlot3d); NOT_FOUND if it is missing.
absl::StatusOr<MultiBlockGrid> ReadPlot3dFile(const std::string& path,
                                              Plot3dFormat* detected = nullptr);
// The same with read options.
absl::StatusOr<MultiBlockGrid> ReadPlot3dFile(const std::string& path,
                                              const Plot3dReadOptions& options,
                                              Plot3dFormat* detected = nullptr);

// The bytes of `grid` as a Plot3D file in `format`. Text uses the shortest decimal form that
// reads back to the same double (std::to_chars), 4 numbers per line, each section (x, y, z,
// iblank) starting on a new line; binary writes 4-byte record markers in the chosen byte order.
// Reading the result with ParsePlot3d gives back bit-identical coordinates (for
// bytes_per_real = 8). INVALID_ARGUMENT when the grid is empty, a block's spatial_dim differs
// from format.spatial_dim, a 2D block has nk > 1, coordinates are not finite, iblank is missing
// or has the wrong size, a file without block count would hold several blocks, or a binary record
// would exceed 2^31 - 1 bytes.
absl::StatusOr<std::string> EncodePlot3d(const MultiBlockGrid& grid, const Plot3dFormat& format);

// Writes `grid` to `path` as EncodePlot3d does, atomically (temporary file + rename).
absl::Status WritePlot3dFile(const std::string& path, const MultiBlockGrid& grid,
                             const Plot3dFormat& format);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_IO_PLOT3D_H_
