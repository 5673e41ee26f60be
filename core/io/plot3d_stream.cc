// Plot3D C-stream binary files (no record markers): layout detection by exact size, reading.
//
// Without markers nothing in the file says where the header ends or how wide a number is, so
// every hypothesis (byte order, block count, 2D/3D, precision, iblank; see plot3d.h) is tested
// by the one thing that must hold: header plus data add up to the file size exactly.
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/plot3d_internal.h"
#include "core/util/status_macros.h"

namespace splinegrid::plot3d_internal {
namespace {

// A header read under one hypothesis.
struct StreamHeader {
  bool big_endian = false;
  bool has_block_count = true;
  int spatial_dim = 3;
  std::vector<Extents> extents;
  int64_t header_bytes = 0;  // block count and dimensions
  int64_t total_points = 0;
};

// "little-endian, block count, 3D"
std::string HeaderName(bool big_endian, bool has_block_count, int dim) {
  return absl::StrCat(big_endian ? "big" : "little", "-endian, ",
                      has_block_count ? "block count" : "no block count", ", ", dim, "D");
}

// Reads the header of `bytes` under a hypothesis; an error message (no prefix) when it does not
// fit the file or holds values out of range.
absl::StatusOr<StreamHeader> ReadHeader(std::string_view bytes, bool big_endian,
                                        bool has_block_count, int dim) {
  const ByteOrder order(big_endian);
  const int64_t size = static_cast<int64_t>(bytes.size());
  const std::string name = HeaderName(big_endian, has_block_count, dim);
  StreamHeader header{big_endian, has_block_count, dim, {}, 0, 0};
  int64_t num_blocks = 1;
  if (has_block_count) {
    if (size < 4) return absl::InvalidArgumentError(absl::StrCat(name, ": no block count"));
    num_blocks = order.Int32(bytes.data());
    if (num_blocks < 1 || num_blocks > kMaxBlocks) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": block count ", num_blocks, " is not from 1 to ", kMaxBlocks));
    }
    header.header_bytes = 4;
  }
  if (header.header_bytes + 4 * dim * num_blocks > size) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": the dimensions of ", num_blocks,
                                                   " blocks need ", 4 * dim * num_blocks,
                                                   " bytes, the file ends before"));
  }
  header.extents.assign(static_cast<size_t>(num_blocks), Extents{1, 1, 1});
  for (int64_t b = 0; b < num_blocks; ++b) {
    for (int d = 0; d < dim; ++d) {
      const int64_t at = header.header_bytes + 4 * (b * dim + d);
      const int32_t n = order.Int32(bytes.data() + at);
      if (n < 1 || n > kMaxExtent) {
        return absl::InvalidArgumentError(absl::StrCat(name, ": block ", b, " ", ExtentName(d),
                                                       " = ", n, " at byte offset ", at,
                                                       " is not from 1 to ", kMaxExtent));
      }
      header.extents[b][d] = n;
    }
    const int64_t points = CheckedNumPoints(header.extents[b]);
    if (points < 0) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": block ", b, ": ", TooManyPointsMessage(header.extents[b])));
    }
    header.total_points += points;
  }
  header.header_bytes += 4 * dim * num_blocks;
  return header;
}

// Reads the blocks of `bytes` laid out as `header` says with `values` (whose sizes add up).
absl::StatusOr<MultiBlockGrid> ReadBlocks(std::string_view bytes, std::string_view source,
                                          const StreamHeader& header, const BinaryValues& values,
                                          Plot3dLayout layout) {
  MultiBlockGrid grid;
  grid.blocks.reserve(header.extents.size());
  const char* p = bytes.data() + header.header_bytes;
  for (size_t b = 0; b < header.extents.size(); ++b) {
    StructuredBlock block(header.extents[b], header.spatial_dim);
    if (values.has_iblank) block.iblank().resize(static_cast<size_t>(block.num_points()));
    const int64_t n = SlabPoints(header.extents[b], layout);
    for (int64_t first = 0; first < block.num_points(); first += n) {
      SG_RETURN_IF_ERROR(ReadBinarySlab(bytes, p, values, static_cast<int64_t>(b), first, n, source,
                                        " (C stream)", &block));
      p += values.SlabBytes(n, header.spatial_dim);
    }
    grid.blocks.push_back(std::move(block));
  }
  return grid;
}

// "1064 points need 12768 (single), 25536 (double), 17024 (single + iblank) or 29792 (double
// + iblank) bytes after the 36-byte header, the file has 12000".
std::string SizeMessage(const StreamHeader& header, int64_t size) {
  const int64_t p = header.total_points;
  const int dim = header.spatial_dim;
  std::string extents;
  for (size_t b = 0; b < header.extents.size() && b < 4; ++b) {
    absl::StrAppend(&extents, b == 0 ? "" : ", ", header.extents[b][0], " x ",
                    header.extents[b][1]);
    if (dim == 3) absl::StrAppend(&extents, " x ", header.extents[b][2]);
  }
  if (header.extents.size() > 4) absl::StrAppend(&extents, ", ...");
  return absl::StrCat(HeaderName(header.big_endian, header.has_block_count, dim), " (",
                      header.extents.size(), " block(s): ", extents, "): ", p, " points need ",
                      p * dim * 4, " (single), ", p * dim * 8, " (double), ", p * (dim * 4 + 4),
                      " (single + iblank) or ", p * (dim * 8 + 4),
                      " (double + iblank) bytes after the ", header.header_bytes,
                      "-byte header, the file has ", size - header.header_bytes);
}

}  // namespace

absl::StatusOr<MultiBlockGrid> ParsePlot3dStream(std::string_view bytes, std::string_view source,
                                                 const Plot3dReadOptions& options,
                                                 Plot3dFormat* detected, bool* layout_found) {
  *layout_found = false;
  const int64_t size = static_cast<int64_t>(bytes.size());
  std::string size_message;    // the first hypothesis whose header was valid
  std::string header_message;  // else the first header error
  absl::Status first_data_error;
  for (bool big_endian : {false, true}) {
    for (bool has_block_count : {true, false}) {
      for (int dim : {3, 2}) {
        absl::StatusOr<StreamHeader> header = ReadHeader(bytes, big_endian, has_block_count, dim);
        if (!header.ok()) {
          if (header_message.empty()) header_message = std::string(header.status().message());
          continue;
        }
        if (size_message.empty()) size_message = SizeMessage(*header, size);
        const Plot3dLayout layout =
            dim == 3 ? options.layout.value_or(Plot3dLayout::kWhole) : Plot3dLayout::kWhole;
        for (int real : {8, 4}) {
          for (bool iblank : {false, true}) {
            const BinaryValues values{ByteOrder(big_endian), real, iblank,
                                      /*reject_subnormal=*/true};
            if (header->header_bytes + values.SlabBytes(header->total_points, dim) != size) {
              continue;
            }
            absl::StatusOr<MultiBlockGrid> grid =
                ReadBlocks(bytes, source, *header, values, layout);
            if (!grid.ok()) {
              // Non-finite values are the file's fault (INVALID_ARGUMENT); subnormal ones
              // (OUT_OF_RANGE from ReadBinarySlab) mean a wrong guess.
              const bool wrong_guess = absl::IsOutOfRange(grid.status());
              if (!wrong_guess && !*layout_found) {
                *layout_found = true;
                first_data_error = grid.status();
              } else if (first_data_error.ok()) {
                first_data_error = absl::InvalidArgumentError(grid.status().message());
              }
              continue;
            }
            *layout_found = true;
            if (detected != nullptr) {
              Plot3dFormat format;
              format.encoding = big_endian ? Plot3dEncoding::kBinaryBigEndian
                                           : Plot3dEncoding::kBinaryLittleEndian;
              format.spatial_dim = dim;
              format.has_block_count = has_block_count;
              format.has_iblank = iblank;
              format.bytes_per_real = real;
              format.framing = Plot3dFraming::kCStream;
              format.layout = layout;
              *detected = format;
            }
            return grid;
          }
        }
      }
    }
  }
  if (*layout_found) return first_data_error;
  return absl::InvalidArgumentError(absl::StrCat(
      "no combination of byte order, block count, 2D/3D, single/double precision and iblank "
      "adds up to the file's ",
      size, " bytes; ",
      size_message.empty() ? absl::StrCat("no header is valid (first: ", header_message, ")")
                           : absl::StrCat("closest: ", size_message),
      first_data_error.ok()
          ? ""
          : absl::StrCat("; a layout that adds up was refused: ", first_data_error.message())));
}

}  // namespace splinegrid::plot3d_internal
