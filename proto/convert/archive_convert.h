// Conversions between the stored grid format (splinegrid/v1/archive.proto) and kernel types:
// one format for the .sgrid export, the directory store and the Redis store.
//
// Encode* copy every field exactly (doubles bitwise), so Parse*(Encode*(x)) == x. Parse* treat
// the message as hostile: a damaged or crafted file must give INVALID_ARGUMENT naming the field
// path and the bad value (e.g. "revision.blocks[2].spline.knots[1]: knots[5] = 0.7 is less than
// knots[4] = 0.9"), never a crash or an allocation sized by an unchecked count. Values the
// kernel computes with (knots, parameters, control points, tolerances, enums, sizes) are
// validated with the kernel's own constructors; values it only reports (seconds, deviations,
// curvature) are taken as they are, infinity and NaN included.
//
// `field` arguments are the path of the message in errors, e.g. "revision.blocks[2]".
#ifndef SPLINEGRID_PROTO_CONVERT_ARCHIVE_CONVERT_H_
#define SPLINEGRID_PROTO_CONVERT_ARCHIVE_CONVERT_H_

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/deform/deform_quality.h"
#include "core/fit/grid_fit.h"
#include "core/grid/boundary_kinds.h"
#include "core/grid/connectivity.h"
#include "core/grid/structured_grid.h"
#include "splinegrid/v1/archive.pb.h"

namespace splinegrid {

// ---- Revisions' parts ----

// A block's spline, point distribution, fit summary and report. Checks: three knot vectors
// valid for their order (KnotVector::Create) on the domain [0, 1], control count = n_i n_j n_k
// * spatial_dim with finite coordinates (TensorSpline::Create), the distribution
// (PointDistribution::Create), non-negative counts, bad cells as whole (i, j, k) triples.
void EncodeBlockFit(const BlockFit& block, v1::StoredBlockFit* out);
absl::StatusOr<BlockFit> ParseBlockFit(const v1::StoredBlockFit& stored, const std::string& field);

void EncodeFitReport(const GridFitReport& report, v1::StoredFitReport* out);
// Checks non-negative counts; the rest is reported data.
absl::StatusOr<GridFitReport> ParseFitReport(const v1::StoredFitReport& stored,
                                             const std::string& field);

void EncodeBoundaryKinds(const BoundaryKinds& kinds, v1::StoredBoundaryKinds* out);
// `blocks`: the point extents of the blocks the kinds belong to. Checks one entry per block,
// one point kind per point with only the bits wall | interface | outer, and two face kinds per
// active direction, each WALL, INTERFACE or OUTER.
absl::StatusOr<BoundaryKinds> ParseBoundaryKinds(const v1::StoredBoundaryKinds& stored,
                                                 const std::vector<Extents>& blocks,
                                                 const std::string& field);

void EncodeGridFitOptions(const GridFitOptions& options, v1::StoredFitOptions* out);
// Checks what needs no grid (GridFitOptions::Validate(grid) checks the rest at use): order in
// [2, kMaxOrder], known enums, a positive finite tolerance or valid boundary tolerances (not
// both), fairing (FairingOptions::Validate), non-negative counts and blocks, existing faces.
absl::StatusOr<GridFitOptions> ParseGridFitOptions(const v1::StoredFitOptions& stored,
                                                   const std::string& field);

void EncodeDeformationCheck(const DeformationCheck& check, v1::StoredDeformationCheck* out);
// Checks the level (0 .. kMaxRefinementLevel) and non-negative counts.
absl::StatusOr<DeformationCheck> ParseDeformationCheck(const v1::StoredDeformationCheck& stored,
                                                       const std::string& field);

// ---- Connectivity ----

void EncodeStoredConnectivity(const Connectivity& connectivity, v1::StoredConnectivity* out);
// `blocks`: the point extents of the grid's blocks (the header's source_blocks). Checks every
// match against them: blocks exist, faces are faces of active directions, ranges lie on their
// face inside the block, b_direction maps a's extended tangential directions one to one onto
// b's (never a normal), step 1 or 2, and b's range is the image of a's (so MapToB stays inside
// block b). The kernel indexes points with these ranges: unchecked, they would crash a fit.
absl::StatusOr<Connectivity> ParseStoredConnectivity(
    const v1::StoredConnectivity& stored, const std::vector<Extents>& blocks,
    const std::string& field = "header.connectivity");
// The same against the blocks of `grid` (the assembled source points).
absl::StatusOr<Connectivity> ParseStoredConnectivity(
    const v1::StoredConnectivity& stored, const MultiBlockGrid& grid,
    const std::string& field = "header.connectivity");

// ---- Archive header and source points ----

// The archive format this build writes and the highest it reads.
inline constexpr uint32_t kArchiveFormatVersion = 1;

// OK for format_version 1 .. kArchiveFormatVersion; INVALID_ARGUMENT otherwise, saying which
// version this build reads (a newer file needs a newer server).
absl::Status CheckArchiveVersion(const v1::ArchiveHeader& header);

// Emits `grid`'s points as SourceChunk messages in order: block by block, its coordinates, then
// its iblank values if it has any; at most `max_values` (>= 1) values per chunk. Stops at the
// first error `emit` returns and returns it.
absl::Status ForEachSourceChunk(const MultiBlockGrid& grid, int64_t max_values,
                                const std::function<absl::Status(const v1::SourceChunk&)>& emit);

// Rebuilds the source points from the header's block extents and the chunks in the order
// ForEachSourceChunk emits them. Memory grows with the data that arrives: a header announcing
// 4096 x 4096 x 5 points allocates nothing until data comes (each block's coordinates grow in a
// vector capped at the block's size and move into the block when it is complete: one copy).
class SourceAssembler {
 public:
  // Validates the header: format version, spatial_dim 2 or 3, 1 .. kMaxBlocks blocks with
  // extents ValidateExtents accepts. INVALID_ARGUMENT naming the field.
  static absl::StatusOr<SourceAssembler> Create(const v1::ArchiveHeader& header);

  // Takes the next chunk. INVALID_ARGUMENT (naming the chunk's block and offset) for a chunk
  // of another block than the one being filled, out of order or overlapping (`first` is not
  // where the previous chunk ended), more values than the block has left, iblank for a header
  // without it or before the block's coordinates are complete, both or neither of coords and
  // iblank, non-finite coordinates, or a chunk after the last block.
  absl::Status Add(const v1::SourceChunk& chunk);

  // Bytes held so far (capacity of the partial block plus the completed blocks).
  int64_t bytes() const { return bytes_; }
  // Every value of every block has arrived.
  bool complete() const { return block_ == static_cast<int>(extents_.size()); }
  // The grid; INVALID_ARGUMENT naming the first block whose data is incomplete.
  absl::StatusOr<MultiBlockGrid> Finish() &&;

  // Most blocks a header may announce.
  static constexpr int kMaxBlocks = 1 << 20;

 private:
  SourceAssembler(std::vector<Extents> extents, int spatial_dim, bool iblank)
      : extents_(std::move(extents)), spatial_dim_(spatial_dim), iblank_(iblank) {}
  absl::Status AddCoords(const v1::SourceChunk& chunk);
  absl::Status AddIblank(const v1::SourceChunk& chunk);
  // Moves the filled values of the current block into grid_ and starts the next block.
  void CompleteBlock();

  std::vector<Extents> extents_;
  int spatial_dim_;
  bool iblank_;
  MultiBlockGrid grid_;             // the completed blocks
  int block_ = 0;                   // the block being filled
  std::vector<double> coords_;      // its coordinates so far
  std::vector<int> iblank_values_;  // its iblank values so far (after all its coordinates)
  int64_t bytes_ = 0;
};

}  // namespace splinegrid

#endif  // SPLINEGRID_PROTO_CONVERT_ARCHIVE_CONVERT_H_
