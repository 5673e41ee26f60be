// VTK XML output for ParaView: .vts (vtkStructuredGrid) per block, .vtm (vtkMultiBlockDataSet).
//
// Files follow the VTK XML format version 1.0 (https://docs.vtk.org/en/latest/design_documents/
// VTKFileFormats.html). Points are always written with 3 components (z = 0 for 2D blocks). Data
// is either appended binary (<AppendedData encoding="raw">, byte_order of this machine), each
// array zlib-compressed in VTK's block format (compressor="vtkZLibDataCompressor", see
// vtk_compress.h; the default) or raw and preceded by its byte count as UInt64, or ASCII text
// (shortest round-trip decimals). Point data and cell data (one value per cell, cells
// numbered like points with extents n - 1) are supported.
// A block's point (i, j, k) is VTK point i + ni * (j + nj * k), the same order as
// StructuredBlock, so Extent = "0 ni-1 0 nj-1 0 nk-1".
#ifndef SPLINEGRID_CORE_IO_VTK_H_
#define SPLINEGRID_CORE_IO_VTK_H_

#include <span>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

// How the arrays of a VTK XML file are stored.
enum class VtkDataFormat {
  kAppendedRaw,  // binary after the XML; compact and fast (the default)
  kAscii,        // decimal text inside each DataArray; for tests and debugging
};

// Options of the VTK writers.
struct VtkWriteOptions {
  // Storage of the arrays.
  VtkDataFormat data_format = VtkDataFormat::kAppendedRaw;
  // Add blocks' iblank flags as an Int32 point array named "iblank" (when a block has them).
  bool write_iblank = true;
  // Compress appended data with zlib (ignored for ASCII). About 1.6x smaller for evaluated
  // grids; every VTK XML reader since VTK 5 decodes it.
  bool compress = true;
  // zlib level, 1 (fastest) to 9 (smallest).
  int compression_level = 6;
};

// Where an array's values live.
enum class VtkArrayLocation {
  kPoint,  // one tuple per point (PointData)
  kCell,   // one tuple per cell (CellData): cells of a block of extents n are max(n - 1, 1)
};

// A named point-data array: `num_components` doubles per point, point-major with the points in
// block order (i fastest), so values.size() == num_points * num_components. 1 component is a
// scalar field, 3 a vector field (the first of each becomes ParaView's active one).
struct VtkPointArray {
  std::string name;                // non-empty, unique within a block
  int num_components = 1;          // from 1 to 9
  std::span<const double> values;  // must outlive the write call
  // kCell: one tuple per cell instead (values.size() == num_cells * num_components).
  VtkArrayLocation location = VtkArrayLocation::kPoint;
};

// Cells of `block` as VTK counts them: the product of max(n - 1, 1) over the extents.
int64_t VtkNumCells(const StructuredBlock& block);

// The .vts file for `block` with point-data `arrays`. INVALID_ARGUMENT when an array's name is
// empty or repeated, its component count is outside [1, 9] or its length is not
// num_points * num_components. O(points * components).
absl::StatusOr<std::string> EncodeVts(const StructuredBlock& block,
                                      std::span<const VtkPointArray> arrays = {},
                                      const VtkWriteOptions& options = {});

// Writes EncodeVts(block, arrays, options) to `path` atomically (temporary file + rename).
absl::Status WriteVts(const std::string& path, const StructuredBlock& block,
                      std::span<const VtkPointArray> arrays = {},
                      const VtkWriteOptions& options = {});

// Writes `grid` as `path` (which must end in ".vtm", say out/name.vtm) plus the directory
// out/name/ holding name_<n>.vts for every block, referenced from the .vtm by relative paths
// "name/name_<n>.vts" in DataSets named "block_<n>", where n is block_numbers[b] (the block's
// index in the full grid when only some blocks were evaluated) or b when block_numbers is
// empty. `block_arrays` is empty or holds the arrays of every block
// (block_arrays.size() == grid.blocks.size()). Each file is written atomically, the .vtm last;
// on error some .vts files may already have been written. INVALID_ARGUMENT when block_numbers
// has the wrong size or repeats a number.
absl::Status WriteVtm(const std::string& path, const MultiBlockGrid& grid,
                      std::span<const std::vector<VtkPointArray>> block_arrays = {},
                      const VtkWriteOptions& options = {},
                      std::span<const int> block_numbers = {});

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_IO_VTK_H_
