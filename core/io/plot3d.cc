// Plot3D entry points: text/binary dispatch, format checks, files; shared message helpers.
#include "core/io/plot3d.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "core/io/file_util.h"
#include "core/io/plot3d_internal.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace plot3d_internal {

std::string ErrorPrefix(std::string_view source) {
  return absl::StrCat("plot3d '", std::string(source), "': ");
}

const char* ExtentName(int direction) {
  static constexpr const char* kNames[] = {"ni", "nj", "nk"};
  return kNames[direction];
}

int64_t CheckedNumPoints(const Extents& extents) {
  const int64_t ij = int64_t{extents[0]} * extents[1];  // <= 2^48: no overflow
  if (ij > kMaxBlockPoints || (extents[2] > 0 && ij > kMaxBlockPoints / extents[2])) return -1;
  return ij * extents[2];
}

std::string TooManyPointsMessage(const Extents& extents) {
  const double points = static_cast<double>(extents[0]) * extents[1] * extents[2];
  return absl::StrCat(extents[0], " x ", extents[1], " x ", extents[2], " = ", points,
                      " points exceeds the limit of ", kMaxBlockPoints, " points per block");
}

std::string DescribeBlockValue(const Extents& extents, int spatial_dim, int64_t index_in_block) {
  const int64_t points = NumPoints(extents);
  const int64_t section = index_in_block / points;
  const int64_t p = index_in_block % points;
  static constexpr const char* kSections[] = {"x", "y", "z"};
  const char* name = section < spatial_dim ? kSections[section] : "iblank";
  return absl::StrCat(name, " of point (", p % extents[0], ", ", (p / extents[0]) % extents[1],
                      ", ", p / (int64_t{extents[0]} * extents[1]), ")");
}

int64_t SlabPoints(const Extents& extents, Plot3dLayout layout) {
  return layout == Plot3dLayout::kPlanes ? int64_t{extents[0]} * extents[1] : NumPoints(extents);
}

int64_t WholeLayoutIndex(const Extents& extents, int values_per_point, Plot3dLayout layout,
                         int64_t index_in_block) {
  if (layout == Plot3dLayout::kWhole) return index_in_block;
  const int64_t n = SlabPoints(extents, layout);
  const int64_t slab = index_in_block / (n * values_per_point);
  const int64_t rest = index_in_block % (n * values_per_point);
  return (rest / n) * NumPoints(extents) + slab * n + rest % n;
}

const char* LayoutName(Plot3dLayout layout) {
  return layout == Plot3dLayout::kPlanes ? "planes" : "whole";
}

BlockValue LocateBlockValue(const std::vector<Extents>& extents, int values_per_point,
                            int64_t offset) {
  BlockValue located;
  for (const Extents& e : extents) {
    const int64_t size = NumPoints(e) * values_per_point;
    if (offset < size) break;
    offset -= size;
    ++located.block;
  }
  located.index_in_block = offset;
  return located;
}

}  // namespace plot3d_internal

namespace {

using plot3d_internal::ErrorPrefix;

// True for bytes a Plot3D text file may start with: printable ASCII and whitespace.
bool IsTextByte(unsigned char c) { return (c >= 0x20 && c < 0x7f) || (c >= '\t' && c <= '\r'); }

// OK when `grid` can be written in `format` (see EncodePlot3d).
absl::Status CheckWritable(const MultiBlockGrid& grid, const Plot3dFormat& format) {
  if (format.spatial_dim != 2 && format.spatial_dim != 3) {
    return absl::InvalidArgumentError(
        absl::StrCat("Plot3D format: spatial_dim must be 2 or 3, not ", format.spatial_dim));
  }
  if (format.encoding != Plot3dEncoding::kAscii && format.bytes_per_real != 4 &&
      format.bytes_per_real != 8) {
    return absl::InvalidArgumentError(
        absl::StrCat("Plot3D format: bytes_per_real must be 4 or 8, not ", format.bytes_per_real));
  }
  if (grid.blocks.empty()) return absl::InvalidArgumentError("Plot3D: the grid has no blocks");
  if (!format.has_block_count && grid.blocks.size() != 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "Plot3D: a file without block count holds one block, the grid has ", grid.blocks.size()));
  }
  for (size_t b = 0; b < grid.blocks.size(); ++b) {
    const StructuredBlock& block = grid.blocks[b];
    const std::string what = absl::StrCat("Plot3D block ", b);
    if (block.spatial_dim() != format.spatial_dim) {
      return absl::InvalidArgumentError(absl::StrCat(what, " has spatial_dim ", block.spatial_dim(),
                                                     " but the format (and every "
                                                     "block of one file) has ",
                                                     format.spatial_dim));
    }
    SG_RETURN_IF_ERROR(ValidateExtents(block.extents(), what));
    if (format.spatial_dim == 2 && block.extent(2) != 1) {
      return absl::InvalidArgumentError(
          absl::StrCat(what, ": a 2D Plot3D block must have nk = 1, not ", block.extent(2)));
    }
    if (block.coords().size() != static_cast<size_t>(block.num_points() * block.spatial_dim())) {
      return absl::InvalidArgumentError(absl::StrCat(what, ": coordinate array size mismatch"));
    }
    SG_RETURN_IF_ERROR(ValidateFinite(block, what));
    if (format.has_iblank && block.iblank().size() != static_cast<size_t>(block.num_points())) {
      return absl::InvalidArgumentError(absl::StrCat(what, " has ", block.iblank().size(),
                                                     " iblank values, the format needs one per "
                                                     "point (",
                                                     block.num_points(), ")"));
    }
  }
  return absl::OkStatus();
}

}  // namespace

std::string DescribePlot3dFormat(const Plot3dFormat& format) {
  std::string encoding;
  switch (format.encoding) {
    case Plot3dEncoding::kAscii:
      encoding = "ASCII";
      break;
    case Plot3dEncoding::kBinaryLittleEndian:
      encoding = "binary little-endian";
      break;
    case Plot3dEncoding::kBinaryBigEndian:
      encoding = "binary big-endian";
      break;
  }
  if (format.encoding != Plot3dEncoding::kAscii) {
    if (format.framing == Plot3dFraming::kCStream) absl::StrAppend(&encoding, " C-stream");
    absl::StrAppend(&encoding, format.bytes_per_real == 4 ? " single" : " double", " precision");
  }
  return absl::StrCat(
      encoding, " ", format.spatial_dim, "D, ",
      format.has_block_count ? "block-count line" : "no block-count line", ", ",
      format.has_iblank ? "iblank" : "no iblank",
      format.spatial_dim == 3 && format.layout == Plot3dLayout::kPlanes ? ", planes layout" : "");
}

Plot3dFormat DefaultPlot3dFormat(const MultiBlockGrid& grid, Plot3dEncoding encoding) {
  Plot3dFormat format;
  format.encoding = encoding;
  format.spatial_dim = grid.blocks.empty() ? 3 : grid.blocks.front().spatial_dim();
  format.has_block_count = true;
  format.has_iblank =
      !grid.blocks.empty() &&
      std::all_of(grid.blocks.begin(), grid.blocks.end(), [](const StructuredBlock& block) {
        return block.iblank().size() == static_cast<size_t>(block.num_points());
      });
  format.bytes_per_real = 8;
  return format;
}

absl::StatusOr<MultiBlockGrid> ParsePlot3d(std::string_view bytes, std::string_view source_name,
                                           Plot3dFormat* detected) {
  return ParsePlot3d(bytes, source_name, Plot3dReadOptions(), detected);
}

absl::StatusOr<MultiBlockGrid> ParsePlot3d(std::string_view bytes, std::string_view source_name,
                                           const Plot3dReadOptions& options,
                                           Plot3dFormat* detected) {
  if (bytes.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(ErrorPrefix(source_name), "the file is empty"));
  }
  const size_t probe = std::min<size_t>(bytes.size(), 4);
  const bool binary = !std::all_of(bytes.begin(), bytes.begin() + probe, [](char c) {
    return IsTextByte(static_cast<unsigned char>(c));
  });
  if (!binary) return plot3d_internal::ParsePlot3dText(bytes, source_name, options, detected);
  // Fortran records first (their markers make the layout explicit), then a C stream.
  bool looks_fortran = false;
  absl::StatusOr<MultiBlockGrid> fortran =
      plot3d_internal::ParsePlot3dBinary(bytes, source_name, options, detected, &looks_fortran);
  if (fortran.ok()) return fortran;
  // Two well-formed records: a damaged Fortran file (reading it as a stream could find a
  // layout that adds up by chance, e.g. a cut file).
  if (looks_fortran) return fortran.status();
  bool layout_found = false;
  absl::StatusOr<MultiBlockGrid> stream =
      plot3d_internal::ParsePlot3dStream(bytes, source_name, options, detected, &layout_found);
  // A stream layout adding up to the file size exactly is the file's layout; its error (a
  // non-finite coordinate) is the file's fault.
  if (stream.ok() || layout_found) return stream;
  return absl::InvalidArgumentError(absl::StrCat(
      ErrorPrefix(source_name), "not a Plot3D text file (byte 0x",
      absl::Hex(static_cast<unsigned char>(bytes[0]), absl::kZeroPad2), " at the start), ",
      fortran.status().message(), ", and not a C-stream file: ", stream.status().message()));
}

absl::StatusOr<MultiBlockGrid> ReadPlot3dFile(const std::string& path, Plot3dFormat* detected) {
  return ReadPlot3dFile(path, Plot3dReadOptions(), detected);
}

absl::StatusOr<MultiBlockGrid> ReadPlot3dFile(const std::string& path,
                                              const Plot3dReadOptions& options,
                                              Plot3dFormat* detected) {
  SG_ASSIGN_OR_RETURN(const std::string bytes, ReadFileToString(path));
  return ParsePlot3d(bytes, path, options, detected);
}

absl::StatusOr<std::string> EncodePlot3d(const MultiBlockGrid& grid, const Plot3dFormat& format) {
  SG_RETURN_IF_ERROR(CheckWritable(grid, format));
  if (format.encoding == Plot3dEncoding::kAscii) {
    return plot3d_internal::EncodePlot3dText(grid, format);
  }
  return plot3d_internal::EncodePlot3dBinary(grid, format);
}

absl::Status WritePlot3dFile(const std::string& path, const MultiBlockGrid& grid,
                             const Plot3dFormat& format) {
  SG_ASSIGN_OR_RETURN(const std::string bytes, EncodePlot3d(grid, format), "writing '", path,
                      "': ");
  return WriteFileAtomically(path, bytes);
}

}  // namespace splinegrid
