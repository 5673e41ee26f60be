#include "core/io/plot3d_function.h"

#include <charconv>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "core/io/file_util.h"
#include "core/io/plot3d_internal.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

using plot3d_internal::ByteOrder;
using plot3d_internal::SlabPoints;

absl::Status CheckBlocks(std::span<const Plot3dFunctionBlock> blocks, const Plot3dFormat& format) {
  if (blocks.empty()) return absl::InvalidArgumentError("Plot3D function file: no blocks");
  if (!format.has_block_count && blocks.size() != 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "Plot3D function file: a file without block count holds one block, not ", blocks.size()));
  }
  for (size_t b = 0; b < blocks.size(); ++b) {
    const Plot3dFunctionBlock& block = blocks[b];
    const std::string what = absl::StrCat("Plot3D function file block ", b);
    SG_RETURN_IF_ERROR(ValidateExtents(block.extents, what));
    if (format.spatial_dim == 2 && block.extents[2] != 1) {
      return absl::InvalidArgumentError(
          absl::StrCat(what, ": a 2D file needs nk = 1, not ", block.extents[2]));
    }
    if (block.num_functions < 1) {
      return absl::InvalidArgumentError(
          absl::StrCat(what, ": num_functions = ", block.num_functions, " must be at least 1"));
    }
    const int64_t need = NumPoints(block.extents) * block.num_functions;
    if (static_cast<int64_t>(block.values.size()) != need) {
      return absl::InvalidArgumentError(absl::StrCat(
          what, " has ", block.values.size(), " values; its points x functions need ", need));
    }
    for (size_t i = 0; i < block.values.size(); ++i) {
      const double v = block.values[i];
      if (!std::isfinite(v) ||
          (format.encoding != Plot3dEncoding::kAscii && format.bytes_per_real == 4 &&
           std::abs(v) > std::numeric_limits<float>::max())) {
        return absl::InvalidArgumentError(absl::StrCat(
            what, ": function ", i % block.num_functions, " at point ", i / block.num_functions,
            " = ", v,
            format.bytes_per_real == 4 ? " is not finite in single precision" : " is not finite"));
      }
    }
  }
  return absl::OkStatus();
}

// Calls emit(block, value) for every value in file order (after the header).
template <typename Emit>
void ForEachValue(std::span<const Plot3dFunctionBlock> blocks, Plot3dLayout layout, Emit emit) {
  for (size_t b = 0; b < blocks.size(); ++b) {
    const Plot3dFunctionBlock& block = blocks[b];
    const int64_t n = SlabPoints(block.extents, layout);
    const int nf = block.num_functions;
    for (int64_t first = 0; first < NumPoints(block.extents); first += n) {
      for (int f = 0; f < nf; ++f) {
        for (int64_t p = first; p < first + n; ++p) emit(b, block.values[p * nf + f]);
      }
    }
  }
}

std::string EncodeText(std::span<const Plot3dFunctionBlock> blocks, const Plot3dFormat& format,
                       Plot3dLayout layout) {
  std::string out;
  if (format.has_block_count) absl::StrAppend(&out, blocks.size(), "\n");
  for (const Plot3dFunctionBlock& block : blocks) {
    absl::StrAppend(&out, block.extents[0], " ", block.extents[1]);
    if (format.spatial_dim == 3) absl::StrAppend(&out, " ", block.extents[2]);
    absl::StrAppend(&out, " ", block.num_functions, "\n");
  }
  int64_t count = 0;
  char buffer[40];
  ForEachValue(blocks, layout, [&](size_t, double value) {
    char* end = std::to_chars(buffer, buffer + sizeof(buffer), value).ptr;
    out.append(buffer, static_cast<size_t>(end - buffer));
    out.push_back(++count % 4 == 0 ? '\n' : ' ');
  });
  if (out.empty() || out.back() != '\n') out.push_back('\n');
  return out;
}

}  // namespace

absl::StatusOr<std::string> EncodePlot3dFunction(std::span<const Plot3dFunctionBlock> blocks,
                                                 const Plot3dFormat& format) {
  if (format.spatial_dim != 2 && format.spatial_dim != 3) {
    return absl::InvalidArgumentError(
        absl::StrCat("Plot3D function file: spatial_dim must be 2 or 3, not ", format.spatial_dim));
  }
  SG_RETURN_IF_ERROR(CheckBlocks(blocks, format));
  const Plot3dLayout layout = format.spatial_dim == 3 ? format.layout : Plot3dLayout::kWhole;
  if (format.encoding == Plot3dEncoding::kAscii) return EncodeText(blocks, format, layout);
  const ByteOrder order(format.encoding == Plot3dEncoding::kBinaryBigEndian);
  const bool records = format.framing == Plot3dFraming::kFortranRecords;
  const int real = format.bytes_per_real == 4 ? 4 : 8;
  constexpr int64_t kMaxRecord = std::numeric_limits<int32_t>::max();
  const int header_ints = format.spatial_dim + 1;
  std::string out;
  auto put_int = [&](int64_t value) {
    char bytes[4];
    order.PutInt32(static_cast<int32_t>(value), bytes);
    out.append(bytes, 4);
  };
  auto marker = [&](int64_t length) {
    if (records) put_int(length);
  };
  if (4 * header_ints * static_cast<int64_t>(blocks.size()) > kMaxRecord) {
    return absl::InvalidArgumentError("Plot3D function file: too many blocks for one record");
  }
  if (format.has_block_count) {
    marker(4);
    put_int(static_cast<int64_t>(blocks.size()));
    marker(4);
  }
  marker(4 * header_ints * static_cast<int64_t>(blocks.size()));
  for (const Plot3dFunctionBlock& block : blocks) {
    for (int d = 0; d < format.spatial_dim; ++d) put_int(block.extents[d]);
    put_int(block.num_functions);
  }
  marker(4 * header_ints * static_cast<int64_t>(blocks.size()));
  for (size_t b = 0; b < blocks.size(); ++b) {
    const Plot3dFunctionBlock& block = blocks[b];
    const int64_t n = SlabPoints(block.extents, layout);
    const int64_t length = n * block.num_functions * real;
    if (records && length > kMaxRecord) {
      return absl::InvalidArgumentError(
          absl::StrCat("Plot3D function file block ", b, ": its record of ", length,
                       " bytes exceeds what a 4-byte Fortran record marker can describe"));
    }
    for (int64_t first = 0; first < NumPoints(block.extents); first += n) {
      marker(length);
      const size_t start = out.size();
      out.resize(start + length);
      char* p = out.data() + start;
      for (int f = 0; f < block.num_functions; ++f) {
        for (int64_t q = first; q < first + n; ++q, p += real) {
          const double value = block.values[q * block.num_functions + f];
          if (real == 8) {
            order.PutFloat64(value, p);
          } else {
            order.PutFloat32(static_cast<float>(value), p);
          }
        }
      }
      marker(length);
    }
  }
  return out;
}

absl::Status WritePlot3dFunctionFile(const std::string& path,
                                     std::span<const Plot3dFunctionBlock> blocks,
                                     const Plot3dFormat& format) {
  SG_ASSIGN_OR_RETURN(const std::string bytes, EncodePlot3dFunction(blocks, format), "writing '",
                      path, "': ");
  return WriteFileAtomically(path, bytes);
}

}  // namespace splinegrid
