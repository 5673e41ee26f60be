// Conversions of GenerateGrid: the request's layer parameters and profile points to the
// kernel's (core/generate/profile_grid.h), and a ProfileGrid to the GenerationReport.
#ifndef SPLINEGRID_PROTO_CONVERT_GENERATE_CONVERT_H_
#define SPLINEGRID_PROTO_CONVERT_GENERATE_CONVERT_H_

#include <string>

#include "absl/status/statusor.h"
#include "core/generate/profile_grid.h"
#include "core/generate/surface_offset.h"
#include "core/grid/structured_grid.h"
#include "splinegrid/v1/splinegrid_service.pb.h"

namespace splinegrid {

// The layer parameters of `request` (method, wall_points, layers, first_height, distance,
// orthogonalize, fit_tolerance): unset fields keep the kernel's defaults, set ones are taken as
// given; validated by ProfileGridOptions::Validate (INVALID_ARGUMENT naming the field, also for
// a field of surfaces only: side, normal_smoothing, symmetry_planes).
absl::StatusOr<ProfileGridOptions> ParseProfileGridOptions(const v1::GenerateGridRequest& request);

// The parameters actually used, as the request fields (every layer field set; fit_tolerance
// only when `options` has one: GenerateProfileGrid resolves the default).
void EncodeProfileGridOptions(const ProfileGridOptions& options, v1::GenerateGridRequest* out);

// ProfilePoints as an n x 1 x 1 curve with spatial_dim 2; INVALID_ARGUMENT naming
// `field`.xy for an odd count, fewer than 5 points or a non-finite value.
absl::StatusOr<StructuredBlock> ParseProfilePoints(const v1::ProfilePoints& points,
                                                   const std::string& field);

// The report of a generated grid of `extents` (`grid`'s block, which may have been moved on),
// apart from `parameters` and `seconds`.
void EncodeGenerationReport(const ProfileGrid& grid, const Extents& extents, int64_t profile_points,
                            v1::GenerationReport* out);

// The march parameters of a stored_surface request (layers, first_height, distance, side,
// normal_smoothing, symmetry_planes): unset fields keep the kernel's defaults; INVALID_ARGUMENT
// naming the field for a bad value or a field that applies to profiles only (method other than
// OFFSETS, wall_points, orthogonalize, fit_tolerance).
absl::StatusOr<SurfaceOffsetOptions> ParseSurfaceOffsetOptions(
    const v1::GenerateGridRequest& request);

// The march parameters actually used, as the request fields.
void EncodeSurfaceOffsetOptions(const SurfaceOffsetOptions& options, v1::GenerateGridRequest* out);

// The march's report (`grid`'s blocks may have been moved on: their extents are `extents`).
void EncodeVolumeReport(const SurfaceOffsetGrid& grid, const std::vector<Extents>& extents,
                        const std::vector<bool>& reversed_i, v1::VolumeReport* out);

}  // namespace splinegrid

#endif  // SPLINEGRID_PROTO_CONVERT_GENERATE_CONVERT_H_
