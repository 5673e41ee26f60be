// VTK XML output for ParaView: .vts (vtkStructuredGrid) per block, .vtm (vtkMultiBlockDataSet).
//
// Files follow the VTK XML format version 1.0 (https://docs.vtk.org/en/latest/design_documents/
// VTKFileFormats.html). Points are always written with 3 components (z = 0 for 2D blocks). Data
// is either appended raw binary (<AppendedData encoding="raw">, each array preceded by its byte
// count as UInt64, byte_order of this machine) or ASCII text (shortest round-trip decimals).
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
};

// A named point-data array: `num_components` doubles per point, point-major with the points in
// block order (i fastest), so values.size() == num_points * num_components. 1 component is a
// scalar field, 3 a vector field (the first of each becomes ParaView's active one).
struct VtkPointArray {
  std::string name;                // non-empty, unique within a block
  int num_components = 1;          // from 1 to 9
  std::span<const double> values;  // must outlive the write call
};

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
// out/name/ holding name_<b>.vts for every block b (numbered from 0), referenced from the .vtm
// by relative paths "name/name_<b>.vts". `block_arrays` is empty or holds the point arrays of
// every block (block_arrays.size() == grid.blocks.size()). Each file is written atomically, the
// .vtm last; on error some .vts files may already have been written.
absl::Status WriteVtm(const std::string& path, const MultiBlockGrid& grid,
                      std::span<const std::vector<VtkPointArray>> block_arrays = {},
                      const VtkWriteOptions& options = {});

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_IO_VTK_H_
