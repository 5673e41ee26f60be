// Conversions between splinegrid.v1 messages and kernel types: the only code that sees both.
// Parse* functions validate what the message alone can tell and name the field and value in
// INVALID_ARGUMENT errors; checks that need the grid stay with the kernel (e.g.
// GridFitOptions::Validate).
#ifndef SPLINEGRID_PROTO_CONVERT_CONVERT_H_
#define SPLINEGRID_PROTO_CONVERT_CONVERT_H_

#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/deform/boundary_controls.h"
#include "core/deform/rigid_motion.h"
#include "core/fit/grid_fit.h"
#include "core/fit/report/wall_curvature.h"
#include "core/fit/solve/tensor_fit.h"
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

// The per-block report: summary, tolerance outcome (tolerance mode), deviation by kind and
// cell quality.
void EncodeBlockFit(const BlockFit& block, bool tolerance_mode, v1::BlockFitSummary* out);

// The grid-wide report (min Jacobian and max size ratio over `blocks`).
void EncodeFitReport(const GridFitReport& report, const std::vector<BlockFit>& blocks,
                     v1::FitReport* out);

void EncodeCurvature(const CurvatureMetrics& metrics, v1::CurvatureReport* out);

// One wall line and its curvature samples (arc length, point, curvature; `spatial_dim`
// coordinates per point).
void EncodeWallCurvatureLine(const WallLine& line, const std::vector<CurvatureSample>& samples,
                             int spatial_dim, v1::WallCurvatureLine* out);

void EncodeBoundaryMatch(const BoundaryMatch& match, v1::BoundaryMatch* out);

v1::BoundaryKind EncodeBoundaryKind(BoundaryKind kind);
// WALL, INTERFACE or OUTER; nullopt for anything else (callers name the field in their error).
std::optional<BoundaryKind> ParseBoundaryKind(int value);

v1::ReferenceLengthSource EncodeReferenceLengthSource(ReferenceLengthSource source);
// GIVEN, WALL or BOUNDING_BOX; nullopt for anything else (callers name the field).
std::optional<ReferenceLengthSource> ParseReferenceLengthSource(v1::ReferenceLengthSource source);

v1::BlockFace EncodeBlockFace(int normal, bool upper);
// Face `face` of block `block`, or INVALID_ARGUMENT naming `field`.
absl::StatusOr<Face> ParseBlockFace(int block, v1::BlockFace face, const std::string& field);

// A face range of the API as the kernel's, validated against nothing but itself (the
// kernel checks it against the grid); `field` names it in errors.
absl::StatusOr<FaceRange> ParseFaceRange(const v1::FaceRange& range, const std::string& field);
void EncodeFaceRange(const FaceRange& range, v1::FaceRange* out);

// The moved boundary of a deformation: kinds (empty: wall) or face ranges.
absl::StatusOr<BoundarySelection> ParseBoundarySelection(const v1::BoundarySelection& selection);

// A rigid motion; angles in degrees on the wire, radians in the kernel.
absl::StatusOr<RigidMotion> ParseRigidMotion(const v1::RigidMotion& motion);

// Fairing (mode and weight), validated; `field` names it in errors.
absl::StatusOr<FairingOptions> ParseFairing(const v1::Fairing& fairing, const std::string& field);
void EncodeFairing(const FairingOptions& fairing, v1::Fairing* out);

// A fitted block as a SplineBlock: always order, control counts and the fit summary; with
// `full` also knots, control points and the point distribution.
void EncodeSplineBlock(const FittedBlock& block, int index, bool full, v1::SplineBlock* out);

// The inverse of EncodeSplineBlock(full = true), validated (knots, sizes, finite values).
absl::StatusOr<FittedBlock> ParseSplineBlock(const v1::SplineBlock& block);

// The resolution of an EvaluateGrid request (level, counts, optional index box).
absl::StatusOr<Resolution> ParseResolution(const v1::EvaluateGridRequest& request);

}  // namespace splinegrid

#endif  // SPLINEGRID_PROTO_CONVERT_CONVERT_H_
