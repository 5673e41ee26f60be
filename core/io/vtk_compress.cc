#include "core/io/vtk_compress.h"

#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "absl/strings/str_cat.h"

namespace splinegrid {
namespace {

void AppendUInt64(uint64_t value, std::string* out) {
  out->append(reinterpret_cast<const char*>(&value), sizeof(value));
}

uint64_t ReadUInt64(const char* p) {
  uint64_t value;
  std::memcpy(&value, p, sizeof(value));
  return value;
}

}  // namespace

void AppendVtkZlibBlocks(std::string_view raw, int level, std::string* out) {
  const uint64_t size = raw.size();
  const uint64_t blocks = (size + kVtkCompressionBlockBytes - 1) / kVtkCompressionBlockBytes;
  AppendUInt64(blocks, out);
  AppendUInt64(kVtkCompressionBlockBytes, out);
  AppendUInt64(size % kVtkCompressionBlockBytes, out);
  const size_t sizes_at = out->size();
  for (uint64_t b = 0; b < blocks; ++b) AppendUInt64(0, out);  // filled in below
  for (uint64_t b = 0; b < blocks; ++b) {
    const uint64_t begin = b * kVtkCompressionBlockBytes;
    const uLong length =
        static_cast<uLong>(std::min<uint64_t>(kVtkCompressionBlockBytes, size - begin));
    uLongf compressed = compressBound(length);
    const size_t at = out->size();
    out->resize(at + compressed);
    // compress2 cannot fail with a large enough destination, a valid level and memory.
    const int result = compress2(reinterpret_cast<Bytef*>(out->data() + at), &compressed,
                                 reinterpret_cast<const Bytef*>(raw.data() + begin), length, level);
    (void)result;
    out->resize(at + compressed);
    const uint64_t stored = compressed;
    std::memcpy(out->data() + sizes_at + 8 * b, &stored, sizeof(stored));
  }
}

absl::StatusOr<std::string> DecodeVtkZlibBlocks(std::string_view data, int64_t* consumed) {
  if (data.size() < 24) {
    return absl::InvalidArgumentError("VTK zlib data: fewer than 24 bytes of header");
  }
  const uint64_t blocks = ReadUInt64(data.data());
  const uint64_t block_size = ReadUInt64(data.data() + 8);
  const uint64_t last = ReadUInt64(data.data() + 16);
  if (blocks > (data.size() - 24) / 8 || block_size == 0 || block_size > (uint64_t{1} << 30) ||
      last >= block_size) {
    return absl::InvalidArgumentError(absl::StrCat(
        "VTK zlib data: bad header (", blocks, " blocks of ", block_size, ", last ", last, ")"));
  }
  uint64_t at = 24 + 8 * blocks;
  std::string raw;
  for (uint64_t b = 0; b < blocks; ++b) {
    const uint64_t compressed = ReadUInt64(data.data() + 24 + 8 * b);
    if (compressed > data.size() - at) {
      return absl::InvalidArgumentError(
          absl::StrCat("VTK zlib data: block ", b, " of ", compressed, " bytes is truncated"));
    }
    uLongf length = (b + 1 == blocks && last != 0) ? last : block_size;
    const size_t start = raw.size();
    raw.resize(start + length);
    const uLongf expected = length;
    if (uncompress(reinterpret_cast<Bytef*>(raw.data() + start), &length,
                   reinterpret_cast<const Bytef*>(data.data() + at), compressed) != Z_OK ||
        length != expected) {
      return absl::InvalidArgumentError(absl::StrCat("VTK zlib data: block ", b, " is corrupt"));
    }
    at += compressed;
  }
  *consumed = static_cast<int64_t>(at);
  return raw;
}

}  // namespace splinegrid
