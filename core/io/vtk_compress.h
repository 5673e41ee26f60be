// VTK's compressed binary data blocks (vtkZLibDataCompressor), as VTK XML readers expect them.
//
// An array's data are cut into blocks of kVtkCompressionBlockBytes uncompressed bytes, each
// compressed on its own with zlib (RFC 1950). Header (UInt64 with header_type="UInt64"):
//   [number of blocks][uncompressed block size][uncompressed size of the last block, 0 when
//   it is full][compressed size of block 0] ... [compressed size of block n-1]
// followed by the compressed blocks back to back (VTK File Formats, "Compressed Data"; the
// layout of vtkXMLWriter::WriteBinaryDataInternal). The file's VTKFile element carries
// compressor="vtkZLibDataCompressor". Cost: zlib's, O(bytes).
#ifndef SPLINEGRID_CORE_IO_VTK_COMPRESS_H_
#define SPLINEGRID_CORE_IO_VTK_COMPRESS_H_

#include <cstdint>
#include <string>
#include <string_view>

#include "absl/status/statusor.h"

namespace splinegrid {

// Uncompressed bytes per block (vtkDataCompressor's default).
inline constexpr int64_t kVtkCompressionBlockBytes = 32768;

// Appends the header and compressed blocks of `raw` to `out` at zlib `level` (1 fastest to 9
// smallest). O(raw.size()).
void AppendVtkZlibBlocks(std::string_view raw, int level, std::string* out);

// The raw bytes of compressed data starting at `data` (header then blocks), as a VTK reader
// decodes them; `*consumed` receives the bytes read. INVALID_ARGUMENT for a truncated or
// corrupt header or block. For tests and tools.
absl::StatusOr<std::string> DecodeVtkZlibBlocks(std::string_view data, int64_t* consumed);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_IO_VTK_COMPRESS_H_
