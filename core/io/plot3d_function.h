// Plot3D function files (.f): per-point fields of a grid file, block by block, e.g. the
// derivatives of an evaluated grid.
//
// Layout (PLOT3D manual, "function file"): [nblocks], then ni nj [nk] nf for every block, then
// per block all values of function 1, then of function 2, ... (i fastest), or in the planes
// layout per k-plane all functions of that plane. The encoding, framing (Fortran records: one
// record for the count, one for all dimensions, one per block or per k-plane), precision,
// block-count line and layout follow the grid file's Plot3dFormat, so a reader that reads the
// grid file reads its function file the same way. No iblank.
#ifndef SPLINEGRID_CORE_IO_PLOT3D_FUNCTION_H_
#define SPLINEGRID_CORE_IO_PLOT3D_FUNCTION_H_

#include <span>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/grid/structured_grid.h"
#include "core/io/plot3d.h"

namespace splinegrid {

// The functions of one block: `num_functions` values per point, point-major (i fastest), so
// values[p * num_functions + f] is function f at point p.
struct Plot3dFunctionBlock {
  Extents extents = {1, 1, 1};
  int num_functions = 1;
  std::vector<double> values;
};

// The bytes of a function file of `blocks` in `format` (has_iblank is ignored; spatial_dim
// 2 writes "ni nj nf" headers and requires nk = 1). INVALID_ARGUMENT when there are no blocks,
// several blocks without a block-count line, num_functions < 1, a values array of the wrong
// size, a non-finite value, or a value that does not fit single precision when
// bytes_per_real = 4.
absl::StatusOr<std::string> EncodePlot3dFunction(std::span<const Plot3dFunctionBlock> blocks,
                                                 const Plot3dFormat& format);

// Writes EncodePlot3dFunction(blocks, format) to `path` atomically.
absl::Status WritePlot3dFunctionFile(const std::string& path,
                                     std::span<const Plot3dFunctionBlock> blocks,
                                     const Plot3dFormat& format);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_IO_PLOT3D_FUNCTION_H_
