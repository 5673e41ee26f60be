// Plot3D Fortran unformatted (binary) files: record scanning, layout detection, reading, writing.
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "absl/strings/str_cat.h"
#include "core/io/plot3d_internal.h"

namespace splinegrid::plot3d_internal {
namespace {

// Largest record a 4-byte marker can describe.
constexpr int64_t kMaxRecordBytes = std::numeric_limits<int32_t>::max();

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

// A Fortran record: payload bytes [offset + 4, offset + 4 + length).
struct Record {
  int64_t index = 0;   // 0-based record number
  int64_t offset = 0;  // byte offset of the leading marker
  int64_t length = 0;  // payload bytes
  // Byte offset of the payload.
  int64_t payload() const { return offset + 4; }
};

// Walks the records of a file, checking both markers of each.
class RecordReader {
 public:
  // Reads `bytes` (which must outlive the reader) in `order`.
  RecordReader(std::string_view bytes, ByteOrder order) : bytes_(bytes), order_(order) {}

  // The next record into `*record`; false at the end of the file or at a malformed record, in
  // which case error() says what is wrong (empty at a clean end).
  bool Next(Record* record) {
    const int64_t size = static_cast<int64_t>(bytes_.size());
    if (pos_ >= size) return false;
    const int64_t left = size - pos_;
    const std::string where = absl::StrCat("record ", index_, " at byte offset ", pos_);
    if (left < 4) {
      error_ =
          absl::StrCat(where, ": the file ends inside the record marker (", left, " bytes left)");
      return false;
    }
    const int32_t length = order_.Int32(bytes_.data() + pos_);
    if (length < 0) {
      error_ = absl::StrCat(where, ": the record marker holds a negative length ", length,
                            " (sub-records of records over 2 GiB are not supported)");
      return false;
    }
    if (length > left - 8) {
      error_ =
          absl::StrCat(where, ": the record marker says ", length, " bytes but only ", left - 4,
                       " bytes follow it (the file is truncated or this is not a "
                       "record marker)");
      return false;
    }
    const int64_t trailer = pos_ + 4 + length;
    const int32_t trailing = order_.Int32(bytes_.data() + trailer);
    if (trailing != length) {
      error_ =
          absl::StrCat(where, ": the leading record marker says ", length,
                       " bytes, the trailing marker at byte offset ", trailer, " says ", trailing);
      return false;
    }
    *record = Record{index_++, pos_, length};
    pos_ = trailer + 4;
    return true;
  }

  // Why the last Next() returned false; empty when the file simply ended.
  const std::string& error() const { return error_; }
  // Byte offset of the next record.
  int64_t position() const { return pos_; }
  // Number of records read.
  int64_t records_read() const { return index_; }

 private:
  std::string_view bytes_;
  ByteOrder order_;
  int64_t pos_ = 0;
  int64_t index_ = 0;
  std::string error_;
};

// "block 2 (record 4 at byte offset 96)".
std::string BlockAt(int64_t block, const Record& record) {
  return absl::StrCat("block ", block, " (record ", record.index, " at byte offset ", record.offset,
                      ")");
}

// Parses `bytes` as records in byte order `big_endian` (see plot3d.h).
absl::StatusOr<MultiBlockGrid> ParseWithByteOrder(std::string_view bytes, std::string_view source,
                                                  bool big_endian, Plot3dFormat* detected) {
  const std::string prefix = ErrorPrefix(source);
  const ByteOrder order(big_endian);
  RecordReader reader(bytes, order);
  auto missing = [&](const std::string& what) {
    return absl::InvalidArgumentError(absl::StrCat(
        prefix, what, ": ",
        reader.error().empty() ? absl::StrCat("the file ends after ", reader.records_read(),
                                              " records (byte offset ", reader.position(), ")")
                               : reader.error()));
  };
  Record first;
  if (!reader.Next(&first)) return missing("the first record");
  const bool has_block_count = first.length == 4;
  int64_t num_blocks = 1;
  Record dims = first;
  if (has_block_count) {
    num_blocks = order.Int32(bytes.data() + first.payload());
    if (num_blocks < 1 || num_blocks > kMaxBlocks) {
      return absl::InvalidArgumentError(absl::StrCat(prefix, "the block count ", num_blocks,
                                                     " (record 0 at byte offset 0) must be from 1 "
                                                     "to ",
                                                     kMaxBlocks));
    }
    if (!reader.Next(&dims)) return missing("the dimensions record");
  }
  int dim = 0;
  if (dims.length == 12 * num_blocks) dim = 3;
  if (dims.length == 8 * num_blocks) dim = 2;
  if (dim == 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(prefix, "the dimensions record (record ", dims.index, " at byte offset ",
                     dims.offset, ") holds ", dims.length, " bytes; ", num_blocks, " blocks need ",
                     8 * num_blocks, " (2D) or ", 12 * num_blocks, " (3D)"));
  }
  std::vector<Extents> extents(static_cast<size_t>(num_blocks), Extents{1, 1, 1});
  std::vector<int64_t> points(static_cast<size_t>(num_blocks));
  for (int64_t b = 0; b < num_blocks; ++b) {
    for (int d = 0; d < dim; ++d) {
      const int64_t at = dims.payload() + 4 * (b * dim + d);
      const int32_t n = order.Int32(bytes.data() + at);
      if (n < 1 || n > kMaxExtent) {
        return absl::InvalidArgumentError(
            absl::StrCat(prefix, "block ", b, ": ", ExtentName(d), " = ", n, " at byte offset ", at,
                         " (record ", dims.index, ") must be from 1 to ", kMaxExtent));
      }
      extents[b][d] = n;
    }
    points[b] = CheckedNumPoints(extents[b]);
    if (points[b] < 0) {
      return absl::InvalidArgumentError(
          absl::StrCat(prefix, "block ", b, ": ", TooManyPointsMessage(extents[b])));
    }
  }
  // Validate every block record against the file before allocating anything.
  std::vector<Record> records(static_cast<size_t>(num_blocks));
  int bytes_per_real = 0;
  bool has_iblank = false;
  for (int64_t b = 0; b < num_blocks; ++b) {
    Record& record = records[b];
    if (!reader.Next(&record)) {
      return missing(
          absl::StrCat("block ", b, " of ", num_blocks, " (record ", reader.records_read(), ")"));
    }
    if (b == 0) {
      for (int real : {4, 8}) {
        for (bool iblank : {false, true}) {
          if (record.length == points[0] * (dim * real + (iblank ? 4 : 0))) {
            bytes_per_real = real;
            has_iblank = iblank;
          }
        }
      }
      if (bytes_per_real == 0) {
        return absl::InvalidArgumentError(absl::StrCat(
            prefix, BlockAt(b, record), " holds ", record.length, " bytes; its ", points[0],
            " points need ", points[0] * dim * 4, " (single precision), ", points[0] * dim * 8,
            " (double), ", points[0] * (dim * 4 + 4), " (single + iblank) or ",
            points[0] * (dim * 8 + 4), " (double + iblank)"));
      }
    } else if (const int64_t need = points[b] * (dim * bytes_per_real + (has_iblank ? 4 : 0));
               record.length != need) {
      return absl::InvalidArgumentError(absl::StrCat(
          prefix, BlockAt(b, record), " holds ", record.length, " bytes; its ", points[b],
          " points need ", need, " (", bytes_per_real == 4 ? "single" : "double", " precision",
          has_iblank ? " + iblank" : "", ", as block 0)"));
    }
  }
  if (reader.position() < static_cast<int64_t>(bytes.size())) {
    return absl::InvalidArgumentError(absl::StrCat(
        prefix, static_cast<int64_t>(bytes.size()) - reader.position(),
        " unexpected bytes after the last block, from byte offset ", reader.position()));
  }
  MultiBlockGrid grid;
  grid.blocks.reserve(static_cast<size_t>(num_blocks));
  for (int64_t b = 0; b < num_blocks; ++b) {
    StructuredBlock block(extents[b], dim);
    const std::span<double> coords = block.coords();
    const char* data = bytes.data() + records[b].payload();
    for (int s = 0; s < dim; ++s) {
      for (int64_t p = 0; p < points[b]; ++p) {
        const int64_t k = s * points[b] + p;
        const char* at = data + k * bytes_per_real;
        const double value = bytes_per_real == 8 ? order.Float64(at) : order.Float32(at);
        if (!std::isfinite(value)) {
          return absl::InvalidArgumentError(absl::StrCat(
              prefix, "block ", b, ", ", DescribeBlockValue(extents[b], dim, k), " at byte offset ",
              at - bytes.data(), " (record ", records[b].index, "): ", value, " is not finite"));
        }
        coords[p * dim + s] = value;
      }
    }
    if (has_iblank) {
      const char* iblank = data + dim * points[b] * bytes_per_real;
      block.iblank().resize(static_cast<size_t>(points[b]));
      for (int64_t p = 0; p < points[b]; ++p) block.iblank()[p] = order.Int32(iblank + 4 * p);
    }
    grid.blocks.push_back(std::move(block));
  }
  if (detected != nullptr) {
    *detected = Plot3dFormat{
        big_endian ? Plot3dEncoding::kBinaryBigEndian : Plot3dEncoding::kBinaryLittleEndian, dim,
        has_block_count, has_iblank, bytes_per_real};
  }
  return grid;
}

// Whether the first record of `bytes` is well formed in `order` (error() says why not).
bool FirstRecordValid(std::string_view bytes, bool big_endian, std::string* error) {
  RecordReader reader(bytes, ByteOrder(big_endian));
  Record record;
  if (reader.Next(&record)) return true;
  *error = reader.error();
  return false;
}

}  // namespace

absl::StatusOr<MultiBlockGrid> ParsePlot3dBinary(std::string_view bytes, std::string_view source,
                                                 Plot3dFormat* detected) {
  // ParsePlot3d never passes empty bytes; the check keeps bytes[0] below in bounds for any caller.
  if (bytes.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(ErrorPrefix(source), "the file is empty"));
  }
  std::string little_error, big_error;
  const bool little = FirstRecordValid(bytes, false, &little_error);
  const bool big = FirstRecordValid(bytes, true, &big_error);
  if (!little && !big) {
    return absl::InvalidArgumentError(absl::StrCat(
        ErrorPrefix(source), "not a Plot3D text file (byte 0x",
        absl::Hex(static_cast<unsigned char>(bytes[0]), absl::kZeroPad2),
        " at the start) and not a Fortran unformatted file in either byte order: little-endian ",
        little_error, "; big-endian ", big_error));
  }
  if (little && big) {  // only for contrived markers: take the first byte order that parses
    absl::StatusOr<MultiBlockGrid> grid = ParseWithByteOrder(bytes, source, false, detected);
    if (grid.ok()) return grid;
    absl::StatusOr<MultiBlockGrid> swapped = ParseWithByteOrder(bytes, source, true, detected);
    return swapped.ok() ? std::move(swapped) : std::move(grid);
  }
  return ParseWithByteOrder(bytes, source, big, detected);
}

absl::StatusOr<std::string> EncodePlot3dBinary(const MultiBlockGrid& grid,
                                               const Plot3dFormat& format) {
  const ByteOrder order(format.encoding == Plot3dEncoding::kBinaryBigEndian);
  const int dim = format.spatial_dim;
  const int real = format.bytes_per_real;
  const int64_t num_blocks = static_cast<int64_t>(grid.blocks.size());
  int64_t total = (format.has_block_count ? 12 : 0) + 8 + 4 * dim * num_blocks;
  for (int64_t b = 0; b < num_blocks; ++b) {
    const int64_t length = grid.blocks[b].num_points() * (dim * real + (format.has_iblank ? 4 : 0));
    if (length > kMaxRecordBytes || 4 * dim * num_blocks > kMaxRecordBytes) {
      return absl::InvalidArgumentError(
          absl::StrCat("Plot3D block ", b, ": its record of ", length,
                       " bytes exceeds what a 4-byte Fortran record marker can describe"));
    }
    total += length + 8;
  }
  std::string out(static_cast<size_t>(total), '\0');
  char* p = out.data();
  auto begin_record = [&](int64_t length) {
    order.PutInt32(static_cast<int32_t>(length), p);
    order.PutInt32(static_cast<int32_t>(length), p + 4 + length);
    p += 4;
    return p + length + 4;  // where the next record starts
  };
  if (format.has_block_count) {
    char* next = begin_record(4);
    order.PutInt32(static_cast<int32_t>(num_blocks), p);
    p = next;
  }
  char* next = begin_record(4 * dim * num_blocks);
  for (const StructuredBlock& block : grid.blocks) {
    for (int d = 0; d < dim; ++d, p += 4) order.PutInt32(block.extent(d), p);
  }
  p = next;
  for (int64_t b = 0; b < num_blocks; ++b) {
    const StructuredBlock& block = grid.blocks[b];
    const int64_t points = block.num_points();
    next = begin_record(points * (dim * real + (format.has_iblank ? 4 : 0)));
    const std::span<const double> coords = block.coords();
    for (int s = 0; s < dim; ++s) {
      for (int64_t i = 0; i < points; ++i, p += real) {
        const double value = coords[i * dim + s];
        if (real == 8) {
          order.PutFloat64(value, p);
        } else if (std::abs(value) > std::numeric_limits<float>::max()) {
          return absl::InvalidArgumentError(absl::StrCat(
              "Plot3D block ", b, ", ", DescribeBlockValue(block.extents(), dim, s * points + i),
              ": ", value, " does not fit single precision"));
        } else {
          order.PutFloat32(static_cast<float>(value), p);
        }
      }
    }
    if (format.has_iblank) {
      for (int64_t i = 0; i < points; ++i, p += 4) order.PutInt32(block.iblank()[i], p);
    }
    p = next;
  }
  return out;
}

}  // namespace splinegrid::plot3d_internal
