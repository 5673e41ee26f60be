// The layout of a Plot3D source file (core/io/plot3d_source_format.h) <->
// splinegrid.v1.Plot3dFileFormat, and the import's layout choice. The parser validates
// everything: the message comes from stores, archives and servers.
#ifndef SPLINEGRID_PROTO_CONVERT_PLOT3D_FORMAT_CONVERT_H_
#define SPLINEGRID_PROTO_CONVERT_PLOT3D_FORMAT_CONVERT_H_

#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "core/io/plot3d.h"
#include "core/io/plot3d_source_format.h"
#include "splinegrid/v1/grid.pb.h"

namespace splinegrid {

void EncodePlot3dSourceFormat(const Plot3dSourceFormat& format, v1::Plot3dFileFormat* out);

// INVALID_ARGUMENT naming `field` unless the encoding is given, spatial_dim is 2 or 3,
// bytes_per_real 4 or 8, and two_planes is empty or has `num_blocks` entries (3D files only)
// with directions and coordinates from 0 to 2 and finite, distinct plane values.
absl::StatusOr<Plot3dSourceFormat> ParsePlot3dSourceFormat(const v1::Plot3dFileFormat& in,
                                                           int num_blocks,
                                                           const std::string& field);

// The read option of Plot3dSource.layout (UNSPECIFIED: detect).
std::optional<Plot3dLayout> Plot3dLayoutFromProto(v1::Plot3dLayout layout);
v1::Plot3dLayout Plot3dLayoutToProto(Plot3dLayout layout);

}  // namespace splinegrid

#endif  // SPLINEGRID_PROTO_CONVERT_PLOT3D_FORMAT_CONVERT_H_
