// Source boundary conditions (core/grid/source_boundaries.h) <-> splinegrid.v1.SourceBoundaries,
// and the decoder's output (CgnsDecoded) <-> ImportedGrid. Parsers validate everything: the
// messages come from stores, files and a child process that read a client's file.
#ifndef SPLINEGRID_PROTO_CONVERT_SOURCE_BOUNDARIES_CONVERT_H_
#define SPLINEGRID_PROTO_CONVERT_SOURCE_BOUNDARIES_CONVERT_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/grid/source_boundaries.h"
#include "splinegrid/v1/archive.pb.h"
#include "splinegrid/v1/grid.pb.h"

namespace splinegrid {

void EncodeSourceBoundaries(const SourceBoundaries& boundaries, v1::SourceBoundaries* out);
// Validated against the source blocks' extents (ValidateSourceBoundaries); `field` names it.
absl::StatusOr<SourceBoundaries> ParseSourceBoundaries(const v1::SourceBoundaries& in,
                                                       const std::vector<Extents>& blocks,
                                                       const std::string& field);

void EncodeCgnsDecoded(const ImportedGrid& grid, v1::CgnsDecoded* out);
// INVALID_ARGUMENT naming the field unless: spatial_dim 2 or 3, at least one zone, valid
// extents, exactly spatial_dim values per point, finite coordinates, boundaries and
// connections on faces of the zones.
absl::StatusOr<ImportedGrid> ParseCgnsDecoded(const v1::CgnsDecoded& in);

}  // namespace splinegrid

#endif  // SPLINEGRID_PROTO_CONVERT_SOURCE_BOUNDARIES_CONVERT_H_
