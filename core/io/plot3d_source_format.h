// What a grid's Plot3D source file looked like, and the grid and format that write an
// evaluation of it back the same way: encoding, framing, precision, block-count line, iblank,
// layout, and the two planes of a CFL3D-style 2D grid whose planar view was stored.
#ifndef SPLINEGRID_CORE_IO_PLOT3D_SOURCE_FORMAT_H_
#define SPLINEGRID_CORE_IO_PLOT3D_SOURCE_FORMAT_H_

#include <span>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/grid/structured_grid.h"
#include "core/io/planar_view.h"
#include "core/io/plot3d.h"

namespace splinegrid {

// How a Plot3D source was laid out (kept with the imported grid).
struct Plot3dSourceFormat {
  // The file's format as ParsePlot3d detected it (spatial_dim of the file, 3 for two planes).
  Plot3dFormat file;
  // When the planar view of a two-plane file was stored: every source block's planes, in block
  // order; empty otherwise.
  std::vector<TwoPlaneLayout> two_planes;
};

// A grid ready to write in the source's form, with the format to write it in.
struct Plot3dWriteBack {
  MultiBlockGrid grid;
  Plot3dFormat format;
};

// `evaluated` (blocks of original indices `block_indices`, one per block) as the source file
// held it: two-plane blocks restored from their planar view (TwoPlaneBlock), iblank = 1 (field
// point) for every point when the file had iblank (a spline has no blanking: the evaluated
// points are all field points), in the source's encoding unless `encoding` differs in kind:
// text stays text and binary keeps its byte order, framing and precision, but an ASCII source
// written to a binary file gets little-endian double Fortran records and a binary source
// written as text gets text. Layout and block-count line are the source's (a file without
// block count with one block evaluated stays so). INVALID_ARGUMENT when a block index is
// outside the source or the blocks do not match the source's dimension. Blocks that need no
// restoring are moved into the result (pass `evaluated` with std::move when done with it).
absl::StatusOr<Plot3dWriteBack> ToPlot3dSourceForm(MultiBlockGrid evaluated,
                                                   std::span<const int> block_indices,
                                                   const Plot3dSourceFormat& source,
                                                   Plot3dEncoding encoding);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_IO_PLOT3D_SOURCE_FORMAT_H_
