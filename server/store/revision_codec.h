// GridRevision <-> StoredRevision (splinegrid/v1/archive.proto): the one stored form of a
// revision, shared by the .sgrid export, the directory store and the Redis store.
//
// EncodeRevision copies every field exactly, so ParseRevision(EncodeRevision(r)) equals r
// bitwise (doubles, infinities and NaN included), except the memory reservation, which is not
// stored: the loader reserves the revision's bytes (RevisionBytes) itself. ParseRevision
// treats the message as hostile (proto/convert/archive_convert.h does the parts) and names the
// field path in INVALID_ARGUMENT errors, e.g. "revision.blocks[2].spline.knots[1]: ...".
#ifndef SPLINEGRID_SERVER_STORE_REVISION_CODEC_H_
#define SPLINEGRID_SERVER_STORE_REVISION_CODEC_H_

#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "google/protobuf/timestamp.pb.h"
#include "server/grid_store.h"
#include "splinegrid/v1/archive.pb.h"

namespace splinegrid::server {

void EncodeRevision(const GridRevision& revision, v1::StoredRevision* out);

// The revision without its memory reservation (the caller reserves). Checks, besides each
// part: number >= 1, 0 <= parent < number, a known origin, at least one block, one spatial
// dimension for all blocks, boundary kinds sized by the blocks' point distributions.
absl::StatusOr<GridRevision> ParseRevision(const v1::StoredRevision& stored);

// OK if `revision` can stand on `source`: as many blocks, the same spatial dimension, and each
// block's point distribution has its source block's extents (fits, quality checks and
// deformations index the source points with it). INVALID_ARGUMENT naming the block otherwise.
absl::Status CheckRevisionMatchesSource(const GridRevision& revision, const MultiBlockGrid& source);

// Unix time with nanoseconds, exact for every absl::Time of whole nanoseconds from 1678 to 2262
// (what ToUnixNanos covers); nanos is always in [0, 1e9), also before 1970.
void EncodeStoredTime(absl::Time time, google::protobuf::Timestamp* out);

v1::RevisionOrigin EncodeRevisionOrigin(RevisionOrigin origin);
// INVALID_ARGUMENT naming `field` for nanos outside [0, 1e9) or seconds outside that range.
absl::StatusOr<absl::Time> ParseStoredTime(const google::protobuf::Timestamp& time,
                                           const std::string& field);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_STORE_REVISION_CODEC_H_
