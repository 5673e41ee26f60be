#include "server/store/revision_codec.h"

#include <limits>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"
#include "proto/convert/archive_convert.h"

namespace splinegrid::server {
namespace {

constexpr int64_t kNanosPerSecond = 1000000000;

absl::StatusOr<RevisionOrigin> ParseOrigin(int value) {
  switch (value) {
    case v1::REVISION_ORIGIN_FIT:
      return RevisionOrigin::kFit;
    case v1::REVISION_ORIGIN_FAIR:
      return RevisionOrigin::kFair;
    case v1::REVISION_ORIGIN_DEFORM:
      return RevisionOrigin::kDeform;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat("revision.origin = ", value, " is not FIT, FAIR or DEFORM"));
  }
}

void EncodeDeformSummary(const DeformSummary& deform, v1::StoredDeformSummary* out) {
  EncodeDeformationCheck(deform.check, out->mutable_check());
  out->set_moved_controls(deform.moved_controls);
  out->set_decay_radius(deform.decay_radius);
  out->set_seconds(deform.seconds);
  out->set_boundary_error(deform.boundary_error);
}

absl::StatusOr<DeformSummary> ParseDeformSummary(const v1::StoredDeformSummary& stored) {
  DeformSummary deform;
  SG_ASSIGN_OR_RETURN(deform.check, ParseDeformationCheck(stored.check(), "revision.deform.check"));
  deform.moved_controls = stored.moved_controls();
  if (deform.moved_controls < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("revision.deform.moved_controls = ", deform.moved_controls, " is negative"));
  }
  deform.decay_radius = stored.decay_radius();  // +infinity: no decay
  deform.seconds = stored.seconds();
  deform.boundary_error = stored.boundary_error();
  if (!(deform.boundary_error >= 0.0) || !std::isfinite(deform.boundary_error)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "revision.deform.boundary_error = ", deform.boundary_error, " is not a finite distance"));
  }
  return deform;
}

// The point extents of a fitted block (its distribution has one parameter per grid index).
Extents PointExtents(const FittedBlock& block) {
  return {block.distribution.num_points(0), block.distribution.num_points(1),
          block.distribution.num_points(2)};
}

}  // namespace

v1::RevisionOrigin EncodeRevisionOrigin(RevisionOrigin origin) {
  switch (origin) {
    case RevisionOrigin::kFit:
      return v1::REVISION_ORIGIN_FIT;
    case RevisionOrigin::kFair:
      return v1::REVISION_ORIGIN_FAIR;
    case RevisionOrigin::kDeform:
      return v1::REVISION_ORIGIN_DEFORM;
  }
  return v1::REVISION_ORIGIN_UNSPECIFIED;
}

void EncodeStoredTime(absl::Time time, google::protobuf::Timestamp* out) {
  const int64_t nanos = absl::ToUnixNanos(time);
  // Floor division: Timestamp wants nanos in [0, 1e9) before 1970 too.
  int64_t seconds = nanos / kNanosPerSecond, rest = nanos % kNanosPerSecond;
  if (rest < 0) {
    rest += kNanosPerSecond;
    --seconds;
  }
  out->set_seconds(seconds);
  out->set_nanos(static_cast<int32_t>(rest));
}

absl::StatusOr<absl::Time> ParseStoredTime(const google::protobuf::Timestamp& time,
                                           const std::string& field) {
  constexpr int64_t kMaxSeconds = std::numeric_limits<int64_t>::max() / kNanosPerSecond - 1;
  if (time.nanos() < 0 || time.nanos() >= kNanosPerSecond) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ".nanos = ", time.nanos(), " is outside [0, 999999999]"));
  }
  if (time.seconds() < -kMaxSeconds || time.seconds() > kMaxSeconds) {
    return absl::InvalidArgumentError(absl::StrCat(field, ".seconds = ", time.seconds(),
                                                   " is outside [", -kMaxSeconds, ", ", kMaxSeconds,
                                                   "]"));
  }
  return absl::FromUnixNanos(time.seconds() * kNanosPerSecond + time.nanos());
}

void EncodeRevision(const GridRevision& revision, v1::StoredRevision* out) {
  out->set_number(revision.number);
  EncodeStoredTime(revision.create_time, out->mutable_create_time());
  out->set_origin(EncodeRevisionOrigin(revision.origin));
  EncodeGridFitOptions(revision.fit_options, out->mutable_fit_options());
  out->set_parent(revision.parent);
  out->set_time(revision.time);
  out->set_step(revision.step);
  EncodeDeformSummary(revision.deform, out->mutable_deform());
  out->mutable_blocks()->Reserve(static_cast<int>(revision.blocks.size()));
  for (const BlockFit& block : revision.blocks) EncodeBlockFit(block, out->add_blocks());
  EncodeBoundaryKinds(revision.kinds, out->mutable_kinds());
  EncodeFitReport(revision.report, out->mutable_report());
}

absl::StatusOr<GridRevision> ParseRevision(const v1::StoredRevision& stored) {
  GridRevision revision;
  revision.number = stored.number();
  if (revision.number < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("revision.number = ", revision.number, "; numbers start at 1"));
  }
  SG_ASSIGN_OR_RETURN(revision.create_time,
                      ParseStoredTime(stored.create_time(), "revision.create_time"));
  SG_ASSIGN_OR_RETURN(revision.origin, ParseOrigin(stored.origin()));
  SG_ASSIGN_OR_RETURN(revision.fit_options,
                      ParseGridFitOptions(stored.fit_options(), "revision.fit_options"));
  revision.parent = stored.parent();
  if (revision.parent < 0 || revision.parent >= revision.number) {
    return absl::InvalidArgumentError(absl::StrCat("revision.parent = ", revision.parent,
                                                   " is outside [0, ", revision.number - 1,
                                                   "] (a parent precedes its revision)"));
  }
  revision.time = stored.time();
  revision.step = stored.step();
  SG_ASSIGN_OR_RETURN(revision.deform, ParseDeformSummary(stored.deform()));
  if (stored.blocks_size() == 0) {
    return absl::InvalidArgumentError(
        "revision.blocks: none; a revision has a block per source block");
  }
  revision.blocks.reserve(stored.blocks_size());  // bounded by the data present
  std::vector<Extents> extents;
  for (int b = 0; b < stored.blocks_size(); ++b) {
    const std::string field = absl::StrCat("revision.blocks[", b, "]");
    SG_ASSIGN_OR_RETURN(BlockFit block, ParseBlockFit(stored.blocks(b), field));
    const int dim = block.fitted.spline.spatial_dim();
    if (b > 0 && dim != revision.blocks[0].fitted.spline.spatial_dim()) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".spline.spatial_dim = ", dim, " differs from block 0's ",
                       revision.blocks[0].fitted.spline.spatial_dim()));
    }
    extents.push_back(PointExtents(block.fitted));
    revision.blocks.push_back(std::move(block));
  }
  SG_ASSIGN_OR_RETURN(revision.kinds,
                      ParseBoundaryKinds(stored.kinds(), extents, "revision.kinds"));
  SG_ASSIGN_OR_RETURN(revision.report, ParseFitReport(stored.report(), "revision.report"));
  return revision;
}

absl::Status CheckRevisionMatchesSource(const GridRevision& revision,
                                        const MultiBlockGrid& source) {
  if (revision.blocks.size() != source.blocks.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("revision ", revision.number, " has ", revision.blocks.size(),
                     " blocks; the source has ", source.blocks.size()));
  }
  for (size_t b = 0; b < source.blocks.size(); ++b) {
    const FittedBlock& fitted = revision.blocks[b].fitted;
    const StructuredBlock& block = source.blocks[b];
    const Extents points = PointExtents(fitted);
    if (fitted.spline.spatial_dim() != block.spatial_dim() || points != block.extents()) {
      return absl::InvalidArgumentError(
          absl::StrCat("revision ", revision.number, " block ", b, ": ", points[0], " x ",
                       points[1], " x ", points[2], " points of ", fitted.spline.spatial_dim(),
                       " coordinates; the source block has ", block.extent(0), " x ",
                       block.extent(1), " x ", block.extent(2), " of ", block.spatial_dim()));
    }
  }
  return absl::OkStatus();
}

}  // namespace splinegrid::server
