// Plot3D Fortran unformatted (binary) files: record scanning, layout detection, reading; the
// binary writer (Fortran records or C stream) and the slab reader/writer both framings share.
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "core/io/plot3d_internal.h"
#include "core/util/status_macros.h"

namespace splinegrid::plot3d_internal {
namespace {

// Largest record a 4-byte marker can describe.
constexpr int64_t kMaxRecordBytes = std::numeric_limits<int32_t>::max();

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

// The error for a record that is missing or malformed where `what` was expected: the reader's
// error, or where the file ended.
absl::Status MissingRecord(const std::string& prefix, const std::string& what,
                           const RecordReader& reader) {
  return absl::InvalidArgumentError(absl::StrCat(
      prefix, what, ": ",
      reader.error().empty() ? absl::StrCat("the file ends after ", reader.records_read(),
                                            " records (byte offset ", reader.position(), ")")
                             : reader.error()));
}

// What the records before the blocks say: the block count and the dimensions record.
struct Header {
  bool has_block_count = false;
  int64_t num_blocks = 1;
  Record dims;  // the dimensions record
  int dim = 0;  // 2 or 3
};

// Reads the optional block-count record and the dimensions record, and the spatial dimension
// their lengths imply.
absl::StatusOr<Header> ReadHeader(std::string_view bytes, const ByteOrder& order,
                                  const std::string& prefix, RecordReader& reader) {
  Header header;
  Record first;
  if (!reader.Next(&first)) return MissingRecord(prefix, "the first record", reader);
  header.has_block_count = first.length == 4;
  header.dims = first;
  const int64_t num_blocks =
      header.has_block_count ? int64_t{order.Int32(bytes.data() + first.payload())} : int64_t{1};
  header.num_blocks = num_blocks;
  if (header.has_block_count) {
    if (num_blocks < 1 || num_blocks > kMaxBlocks) {
      return absl::InvalidArgumentError(absl::StrCat(prefix, "the block count ", num_blocks,
                                                     " (record 0 at byte offset 0) must be from 1 "
                                                     "to ",
                                                     kMaxBlocks));
    }
    if (!reader.Next(&header.dims)) return MissingRecord(prefix, "the dimensions record", reader);
  }
  const Record& dims = header.dims;
  if (dims.length == 12 * num_blocks) header.dim = 3;
  if (dims.length == 8 * num_blocks) header.dim = 2;
  if (header.dim == 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(prefix, "the dimensions record (record ", dims.index, " at byte offset ",
                     dims.offset, ") holds ", dims.length, " bytes; ", num_blocks, " blocks need ",
                     8 * num_blocks, " (2D) or ", 12 * num_blocks, " (3D)"));
  }
  return header;
}

// The extents and point counts of every block, from the dimensions record.
absl::Status ReadExtents(std::string_view bytes, const ByteOrder& order, const Header& header,
                         const std::string& prefix, std::vector<Extents>& extents,
                         std::vector<int64_t>& points) {
  const int64_t num_blocks = header.num_blocks;
  const int dim = header.dim;
  const Record& dims = header.dims;
  extents.assign(static_cast<size_t>(num_blocks), Extents{1, 1, 1});
  points.assign(static_cast<size_t>(num_blocks), 0);
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
  return absl::OkStatus();
}

// Precision, iblank and layout of the block records.
struct BlockEncoding {
  BinaryValues values;
  Plot3dLayout layout = Plot3dLayout::kWhole;
};

// The encoding the first block record fixes, probed from a copy of `reader` (which stays where
// it is): precision, iblank and the layout (a record of one k-plane, nk > 1, means the planes
// layout, one record per plane).
absl::StatusOr<BlockEncoding> DetectBlockEncoding(const RecordReader& reader,
                                                  const ByteOrder& order, const Header& header,
                                                  const std::vector<Extents>& extents,
                                                  const std::vector<int64_t>& points,
                                                  const std::string& prefix) {
  const int64_t num_blocks = header.num_blocks;
  const int dim = header.dim;
  BlockEncoding found{BinaryValues{order, /*bytes_per_real=*/0, /*has_iblank=*/false},
                      Plot3dLayout::kWhole};  // 0: no match yet
  BinaryValues& values = found.values;
  Record first_block;
  RecordReader probe = reader;
  if (!probe.Next(&first_block)) {
    const std::string what =
        absl::StrCat("block 0 of ", num_blocks, " (record ", reader.records_read(), ")");
    return MissingRecord(prefix, what, probe);  // its position and error describe the failure
  }
  // Whole single precision and planes double precision agree in length for nk = 2: the
  // number of records that follow decides (one per block, or one per k-plane).
  int64_t records_left = 1;
  for (Record skip; probe.Next(&skip);) ++records_left;
  const int64_t plane = int64_t{extents[0][0]} * extents[0][1];
  bool count_matches = false;
  for (Plot3dLayout candidate : {Plot3dLayout::kWhole, Plot3dLayout::kPlanes}) {
    if (candidate == Plot3dLayout::kPlanes && (dim == 2 || extents[0][2] == 1)) continue;
    const int64_t n = candidate == Plot3dLayout::kWhole ? points[0] : plane;
    int64_t slabs = 0;
    for (int64_t b = 0; b < num_blocks; ++b) {
      slabs += candidate == Plot3dLayout::kWhole ? 1 : extents[b][2];
    }
    for (int real : {4, 8}) {
      for (bool iblank : {false, true}) {
        const BinaryValues v{order, real, iblank};
        if (first_block.length != v.SlabBytes(n, dim)) continue;
        // The first match, or a later one whose record count fits where the first's did not.
        if (values.bytes_per_real == 0 || (!count_matches && slabs == records_left)) {
          values = v;
          found.layout = candidate;
          count_matches = slabs == records_left;
        }
      }
    }
  }
  if (values.bytes_per_real == 0) {
    const int64_t p = points[0];
    return absl::InvalidArgumentError(absl::StrCat(
        prefix, BlockAt(0, first_block), " holds ", first_block.length, " bytes; its ", p,
        " points need ", p * dim * 4, " (single precision), ", p * dim * 8, " (double), ",
        p * (dim * 4 + 4), " (single + iblank) or ", p * (dim * 8 + 4), " (double + iblank)",
        dim == 3 && extents[0][2] > 1
            ? absl::StrCat(", or a record per k-plane of ", plane, " points (planes layout)")
            : std::string()));
  }
  return found;
}

// The records of every block (one per block, or one per k-plane), each checked to hold the
// bytes `encoding` gives it; then that nothing follows the last.
absl::StatusOr<std::vector<std::vector<Record>>> LocateBlockRecords(
    std::string_view bytes, const Header& header, const std::vector<Extents>& extents,
    const std::vector<int64_t>& points, const BlockEncoding& encoding, const std::string& prefix,
    RecordReader& reader) {
  const int64_t num_blocks = header.num_blocks;
  const int dim = header.dim;
  const BinaryValues& values = encoding.values;
  const Plot3dLayout layout = encoding.layout;
  std::vector<std::vector<Record>> records(static_cast<size_t>(num_blocks));
  for (int64_t b = 0; b < num_blocks; ++b) {
    const int64_t n = SlabPoints(extents[b], layout);
    const int64_t slabs = points[b] / n;
    records[b].resize(static_cast<size_t>(slabs));
    for (int64_t k = 0; k < slabs; ++k) {
      Record& record = records[b][k];
      const std::string what = layout == Plot3dLayout::kWhole
                                   ? absl::StrCat("block ", b, " of ", num_blocks)
                                   : absl::StrCat("block ", b, " plane k = ", k);
      if (!reader.Next(&record)) {
        return MissingRecord(prefix, absl::StrCat(what, " (record ", reader.records_read(), ")"),
                             reader);
      }
      if (const int64_t need = values.SlabBytes(n, dim); record.length != need) {
        return absl::InvalidArgumentError(absl::StrCat(
            prefix, BlockAt(b, record), " holds ", record.length, " bytes; ",
            layout == Plot3dLayout::kWhole ? "its " : "a k-plane of its ", n, " points need ", need,
            " (", values.bytes_per_real == 4 ? "single" : "double", " precision",
            values.has_iblank ? " + iblank" : "", ", as block 0)"));
      }
    }
  }
  if (reader.position() < static_cast<int64_t>(bytes.size())) {
    return absl::InvalidArgumentError(absl::StrCat(
        prefix, static_cast<int64_t>(bytes.size()) - reader.position(),
        " unexpected bytes after the last block, from byte offset ", reader.position()));
  }
  return records;
}

// The blocks read from their located records.
absl::StatusOr<MultiBlockGrid> ReadBlocks(std::string_view bytes, std::string_view source, int dim,
                                          const std::vector<Extents>& extents,
                                          const std::vector<int64_t>& points,
                                          const BlockEncoding& encoding,
                                          const std::vector<std::vector<Record>>& records) {
  const int64_t num_blocks = static_cast<int64_t>(extents.size());
  const BinaryValues& values = encoding.values;
  MultiBlockGrid grid;
  grid.blocks.reserve(static_cast<size_t>(num_blocks));
  for (int64_t b = 0; b < num_blocks; ++b) {
    StructuredBlock block(extents[b], dim);
    if (values.has_iblank) block.iblank().resize(static_cast<size_t>(points[b]));
    const int64_t n = SlabPoints(extents[b], encoding.layout);
    for (size_t k = 0; k < records[b].size(); ++k) {
      const Record& record = records[b][k];
      SG_RETURN_IF_ERROR(ReadBinarySlab(bytes, bytes.data() + record.payload(), values, b,
                                        static_cast<int64_t>(k) * n, n, source,
                                        absl::StrCat(" (record ", record.index, ")"), &block));
    }
    grid.blocks.push_back(std::move(block));
  }
  return grid;
}

// The format a Fortran-record file was found in.
Plot3dFormat DetectedFormat(bool big_endian, const Header& header, const BlockEncoding& encoding) {
  Plot3dFormat format;
  format.encoding =
      big_endian ? Plot3dEncoding::kBinaryBigEndian : Plot3dEncoding::kBinaryLittleEndian;
  format.spatial_dim = header.dim;
  format.has_block_count = header.has_block_count;
  format.has_iblank = encoding.values.has_iblank;
  format.bytes_per_real = encoding.values.bytes_per_real;
  format.framing = Plot3dFraming::kFortranRecords;
  format.layout = encoding.layout;
  return format;
}

// Parses `bytes` as records in byte order `big_endian` (see plot3d.h).
absl::StatusOr<MultiBlockGrid> ParseWithByteOrder(std::string_view bytes, std::string_view source,
                                                  bool big_endian, const Plot3dReadOptions& options,
                                                  Plot3dFormat* detected) {
  const std::string prefix = ErrorPrefix(source);
  const ByteOrder order(big_endian);
  RecordReader reader(bytes, order);
  SG_ASSIGN_OR_RETURN(const Header header, ReadHeader(bytes, order, prefix, reader));
  std::vector<Extents> extents;
  std::vector<int64_t> points;
  SG_RETURN_IF_ERROR(ReadExtents(bytes, order, header, prefix, extents, points));
  // Validate every block record against the file before allocating anything.
  SG_ASSIGN_OR_RETURN(const BlockEncoding encoding,
                      DetectBlockEncoding(reader, order, header, extents, points, prefix));
  const int dim = header.dim;
  if (options.layout.has_value() && *options.layout != encoding.layout && dim == 3 &&
      extents[0][2] > 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        prefix, "the records hold the ", LayoutName(encoding.layout), " layout (block 0 record of ",
        encoding.values.SlabBytes(SlabPoints(extents[0], encoding.layout), dim),
        " bytes), but the ", LayoutName(*options.layout), " layout was requested"));
  }
  SG_ASSIGN_OR_RETURN(const std::vector<std::vector<Record>> records,
                      LocateBlockRecords(bytes, header, extents, points, encoding, prefix, reader));
  SG_ASSIGN_OR_RETURN(MultiBlockGrid grid,
                      ReadBlocks(bytes, source, dim, extents, points, encoding, records));
  if (detected != nullptr) *detected = DetectedFormat(big_endian, header, encoding);
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

// Whether the first two records of `bytes` are well formed in `order`, or the file is exactly
// one record.
bool TwoRecordsValid(std::string_view bytes, bool big_endian) {
  RecordReader reader(bytes, ByteOrder(big_endian));
  Record record;
  if (!reader.Next(&record)) return false;
  return reader.Next(&record) || reader.error().empty();
}

}  // namespace

absl::Status ReadBinarySlab(std::string_view file, const char* data, const BinaryValues& values,
                            int64_t b, int64_t first, int64_t n, std::string_view source,
                            std::string_view where, StructuredBlock* block) {
  const int dim = block->spatial_dim();
  const std::span<double> coords = block->coords();
  const int real = values.bytes_per_real;
  for (int s = 0; s < dim; ++s) {
    for (int64_t q = 0; q < n; ++q) {
      const char* at = data + (s * n + q) * real;
      const double value = real == 8 ? values.order.Float64(at) : values.order.Float32(at);
      // Subnormal as stored: in single precision test the float, not the widened double.
      const bool subnormal =
          values.reject_subnormal &&
          (real == 8 ? std::fpclassify(value) == FP_SUBNORMAL
                     : std::fpclassify(static_cast<float>(value)) == FP_SUBNORMAL);
      if (!std::isfinite(value) || subnormal) {
        const int64_t p = first + q;
        return absl::Status(
            subnormal ? absl::StatusCode::kOutOfRange : absl::StatusCode::kInvalidArgument,
            absl::StrCat(ErrorPrefix(source), "block ", b, ", ",
                         DescribeBlockValue(block->extents(), dim, s * block->num_points() + p),
                         " at byte offset ", at - file.data(), std::string(where), ": ", value,
                         subnormal ? " is subnormal (integers read as reals: not this layout)"
                                   : " is not finite"));
      }
      coords[(first + q) * dim + s] = value;
    }
  }
  if (values.has_iblank) {
    const char* iblank = data + dim * n * real;
    for (int64_t q = 0; q < n; ++q) {
      const int32_t value = values.order.Int32(iblank + 4 * q);
      // iblank is 1 (field), 0 (hole) or a block number (negative: interpolated from it).
      if (values.reject_subnormal && (value > kMaxBlocks || value < -kMaxBlocks)) {
        return absl::OutOfRangeError(
            absl::StrCat(ErrorPrefix(source), "block ", b, ", iblank of point ", first + q, " = ",
                         value, " is not a block number (reals read as iblank: not this layout)"));
      }
      block->iblank()[first + q] = value;
    }
  }
  return absl::OkStatus();
}

absl::Status WriteBinarySlab(const StructuredBlock& block, int64_t b, int64_t first, int64_t n,
                             const BinaryValues& values, char* out) {
  const int dim = block.spatial_dim();
  const int real = values.bytes_per_real;
  const std::span<const double> coords = block.coords();
  for (int s = 0; s < dim; ++s) {
    for (int64_t q = 0; q < n; ++q, out += real) {
      const double value = coords[(first + q) * dim + s];
      if (real == 8) {
        values.order.PutFloat64(value, out);
      } else if (std::abs(value) > std::numeric_limits<float>::max()) {
        return absl::InvalidArgumentError(absl::StrCat(
            "Plot3D block ", b, ", ",
            DescribeBlockValue(block.extents(), dim, s * block.num_points() + first + q), ": ",
            value, " does not fit single precision"));
      } else {
        values.order.PutFloat32(static_cast<float>(value), out);
      }
    }
  }
  if (values.has_iblank) {
    for (int64_t q = 0; q < n; ++q, out += 4) values.order.PutInt32(block.iblank()[first + q], out);
  }
  return absl::OkStatus();
}

absl::StatusOr<MultiBlockGrid> ParsePlot3dBinary(std::string_view bytes, std::string_view source,
                                                 const Plot3dReadOptions& options,
                                                 Plot3dFormat* detected, bool* looks_fortran) {
  *looks_fortran = false;
  // ParsePlot3d never passes empty bytes; the check keeps bytes[0] below in bounds for any caller.
  if (bytes.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(ErrorPrefix(source), "the file is empty"));
  }
  std::string little_error, big_error;
  const bool little = FirstRecordValid(bytes, false, &little_error);
  const bool big = FirstRecordValid(bytes, true, &big_error);
  if (!little && !big) {
    return absl::InvalidArgumentError(
        absl::StrCat("not a Fortran unformatted file in either byte order: little-endian ",
                     little_error, "; big-endian ", big_error));
  }
  *looks_fortran = TwoRecordsValid(bytes, false) || TwoRecordsValid(bytes, true);
  if (little && big) {  // only for contrived markers: take the first byte order that parses
    absl::StatusOr<MultiBlockGrid> grid =
        ParseWithByteOrder(bytes, source, false, options, detected);
    if (grid.ok()) return grid;
    absl::StatusOr<MultiBlockGrid> swapped =
        ParseWithByteOrder(bytes, source, true, options, detected);
    return swapped.ok() ? std::move(swapped) : std::move(grid);
  }
  return ParseWithByteOrder(bytes, source, big, options, detected);
}

absl::StatusOr<std::string> EncodePlot3dBinary(const MultiBlockGrid& grid,
                                               const Plot3dFormat& format) {
  const BinaryValues values{ByteOrder(format.encoding == Plot3dEncoding::kBinaryBigEndian),
                            format.bytes_per_real, format.has_iblank};
  const bool records = format.framing == Plot3dFraming::kFortranRecords;
  const int64_t marker_bytes = records ? 8 : 0;  // per record
  const int dim = format.spatial_dim;
  const Plot3dLayout layout = dim == 3 ? format.layout : Plot3dLayout::kWhole;
  const int64_t num_blocks = static_cast<int64_t>(grid.blocks.size());
  if (records && 4 * dim * num_blocks > kMaxRecordBytes) {
    return absl::InvalidArgumentError(
        absl::StrCat("Plot3D: the dimensions record of ", num_blocks,
                     " blocks exceeds what a 4-byte Fortran record marker can describe"));
  }
  int64_t total =
      (format.has_block_count ? 4 + marker_bytes : 0) + marker_bytes + 4 * dim * num_blocks;
  for (int64_t b = 0; b < num_blocks; ++b) {
    const int64_t n = SlabPoints(grid.blocks[b].extents(), layout);
    const int64_t length = values.SlabBytes(n, dim);
    if (records && length > kMaxRecordBytes) {
      return absl::InvalidArgumentError(
          absl::StrCat("Plot3D block ", b, ": its record of ", length,
                       " bytes exceeds what a 4-byte Fortran record marker can describe"));
    }
    total += (length + marker_bytes) * (grid.blocks[b].num_points() / n);
  }
  std::string out(static_cast<size_t>(total), '\0');
  char* p = out.data();
  // Starts a record of `length` payload bytes at p (markers only with Fortran records); returns
  // where the next record starts and leaves p at the payload.
  auto begin_record = [&](int64_t length) {
    if (!records) return p + length;
    values.order.PutInt32(static_cast<int32_t>(length), p);
    values.order.PutInt32(static_cast<int32_t>(length), p + 4 + length);
    p += 4;
    return p + length + 4;
  };
  if (format.has_block_count) {
    char* next = begin_record(4);
    values.order.PutInt32(static_cast<int32_t>(num_blocks), p);
    p = next;
  }
  char* next = begin_record(4 * dim * num_blocks);
  for (const StructuredBlock& block : grid.blocks) {
    for (int d = 0; d < dim; ++d, p += 4) values.order.PutInt32(block.extent(d), p);
  }
  p = next;
  for (int64_t b = 0; b < num_blocks; ++b) {
    const StructuredBlock& block = grid.blocks[b];
    const int64_t n = SlabPoints(block.extents(), layout);
    for (int64_t first = 0; first < block.num_points(); first += n) {
      next = begin_record(values.SlabBytes(n, dim));
      SG_RETURN_IF_ERROR(WriteBinarySlab(block, b, first, n, values, p));
      p = next;
    }
  }
  return out;
}

}  // namespace splinegrid::plot3d_internal
