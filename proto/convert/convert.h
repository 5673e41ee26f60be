// Conversions between splinegrid.v1 messages and kernel types: the only code that sees both.
// Parse* functions validate what the message alone can tell and name the field and value in
// INVALID_ARGUMENT errors; checks that need the grid stay with the kernel (e.g.
// GridFitOptions::Validate).
#ifndef SPLINEGRID_PROTO_CONVERT_CONVERT_H_
#define SPLINEGRID_PROTO_CONVERT_CONVERT_H_

#include "absl/status/statusor.h"
#include "core/fit/grid_fit.h"
#include "core/fit/tensor_fit.h"
#include "core/grid/sampling.h"
#include "splinegrid/v1/grid.pb.h"
#include "splinegrid/v1/splinegrid_service.pb.h"

namespace splinegrid {

void EncodeExtents(const Extents& extents, v1::Extents* out);
Extents ParseExtents(const v1::Extents& extents);

v1::Parametrization EncodeParametrization(Parametrization p);
absl::StatusOr<Parametrization> ParseParametrization(v1::Parametrization p);

// FitSpec <-> GridFitOptions. Unset fields take the kernel defaults.
absl::StatusOr<GridFitOptions> ParseFitSpec(const v1::FitSpec& spec);
void EncodeFitSpec(const GridFitOptions& options, v1::FitSpec* out);

void EncodeFitSummary(const FitSummary& summary, v1::BlockFitSummary* out);

// A fitted block as a SplineBlock: always order, control counts and the fit summary; with
// `full` also knots, control points and the point distribution.
void EncodeSplineBlock(const FittedBlock& block, int index, bool full, v1::SplineBlock* out);

// The inverse of EncodeSplineBlock(full = true), validated (knots, sizes, finite values).
absl::StatusOr<FittedBlock> ParseSplineBlock(const v1::SplineBlock& block);

// The resolution of an EvaluateGrid request (level, counts, optional index box).
absl::StatusOr<Resolution> ParseResolution(const v1::EvaluateGridRequest& request);

}  // namespace splinegrid

#endif  // SPLINEGRID_PROTO_CONVERT_CONVERT_H_
