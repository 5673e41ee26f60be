// The archive header's parts (format version, connectivity) and the source points as chunks
// (archive_convert.h).
#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"
#include "proto/convert/archive_convert.h"
#include "proto/convert/archive_util.h"
#include "proto/convert/convert.h"

namespace splinegrid {
namespace {

using archive_internal::Invalid;

// `range` lies on its face inside its block: the face exists (its normal direction has more
// than one point), begin <= end inside the extents, and the normal index is the face's.
absl::Status CheckFaceRange(const FaceRange& range, const std::vector<Extents>& blocks,
                            const std::string& field) {
  const int b = range.face.block;
  if (b >= static_cast<int>(blocks.size())) {
    return Invalid(field, ".block = ", b, " is outside [0, ", blocks.size() - 1, "]");
  }
  const Extents& n = blocks[b];
  const int normal = range.face.normal;
  if (n[normal] == 1) {
    return Invalid(field, ".face: block ", b, " has one point in direction ",
                   std::string(1, "ijk"[normal]), ", so no face ", FaceName(range.face));
  }
  for (int d = 0; d < 3; ++d) {
    if (range.begin[d] < 0 || range.begin[d] > range.end[d] || range.end[d] >= n[d]) {
      return Invalid(field, ": ", std::string(1, "ijk"[d]), " range [", range.begin[d], ", ",
                     range.end[d], "] is not inside [0, ", n[d] - 1, "]");
    }
  }
  const int on_face = range.face.upper ? n[normal] - 1 : 0;
  if (range.begin[normal] != on_face || range.end[normal] != on_face) {
    return Invalid(field, ": ", std::string(1, "ijk"[normal]), " range [", range.begin[normal],
                   ", ", range.end[normal], "] is not on face ", FaceName(range.face));
  }
  return absl::OkStatus();
}

absl::StatusOr<BoundaryMatch> ParseMatch(const v1::BoundaryMatch& stored,
                                         const std::vector<Extents>& blocks,
                                         const std::string& field) {
  BoundaryMatch match;
  SG_ASSIGN_OR_RETURN(match.a, ParseFaceRange(stored.a(), field + ".a"));
  SG_ASSIGN_OR_RETURN(match.b, ParseFaceRange(stored.b(), field + ".b"));
  SG_RETURN_IF_ERROR(CheckFaceRange(match.a, blocks, field + ".a"));
  SG_RETURN_IF_ERROR(CheckFaceRange(match.b, blocks, field + ".b"));
  if (stored.b_direction_size() != 3 || stored.reversed_size() != 3) {
    return Invalid(field, ": ", stored.b_direction_size(), " b_direction and ",
                   stored.reversed_size(), " reversed entries; exactly 3 of each are needed");
  }
  match.step = stored.step();
  if (match.step != 1 && match.step != 2) {
    return Invalid(field, ".step = ", match.step, " is not 1 or 2");
  }
  std::array<bool, 3> mapped = {false, false, false};  // directions of b that a's run along
  for (int d = 0; d < 3; ++d) {
    const int e = stored.b_direction(d);
    const std::string at = absl::StrCat(field, ".b_direction[", d, "]");
    match.b_direction[d] = e;
    match.reversed[d] = stored.reversed(d);
    if (e < -1 || e > 2) return Invalid(at, " = ", e, " is outside [-1, 2]");
    if (e == -1) {
      if (match.a.end[d] > match.a.begin[d]) {
        return Invalid(at, " = -1, but range a extends along ", std::string(1, "ijk"[d]));
      }
      continue;
    }
    if (d == match.a.face.normal || e == match.b.face.normal || mapped[e]) {
      return Invalid(at, " = ", e, " maps a normal or an already mapped direction");
    }
    mapped[e] = true;
    // b's range must be the image of a's: then MapToB stays inside it.
    if (match.b.end[e] - match.b.begin[e] != match.step * (match.a.end[d] - match.a.begin[d])) {
      return Invalid(at, " = ", e, ": range b spans ", match.b.end[e] - match.b.begin[e],
                     " along it, range a ", match.a.end[d] - match.a.begin[d], " (step ",
                     match.step, ")");
    }
  }
  for (int e = 0; e < 3; ++e) {
    if (!mapped[e] && match.b.begin[e] != match.b.end[e]) {
      return Invalid(field, ".b: extends along ", std::string(1, "ijk"[e]),
                     ", which no direction of a maps to");
    }
  }
  return match;
}

// Appends `values` to `into`, growing the capacity geometrically but never past `limit`
// elements, so memory follows the data and stops at the block's size.
template <typename T, typename Values>
void AppendCapped(const Values& values, size_t limit, std::vector<T>& into) {
  const size_t needed = into.size() + values.size();
  if (needed > into.capacity())
    into.reserve(std::min(limit, std::max(needed, 2 * into.capacity())));
  into.insert(into.end(), values.begin(), values.end());
}

}  // namespace

// ---- Header ----

absl::Status CheckArchiveVersion(const v1::ArchiveHeader& header) {
  const uint32_t version = header.format_version();
  if (version < 1 || version > kArchiveFormatVersion) {
    return Invalid("header.format_version = ", version, ": this build reads archive format ",
                   kArchiveFormatVersion == 1 ? "1" : absl::StrCat("1 to ", kArchiveFormatVersion),
                   version > kArchiveFormatVersion ? " (the file is from a newer splinegrid)" : "");
  }
  return absl::OkStatus();
}

void EncodeStoredConnectivity(const Connectivity& connectivity, v1::StoredConnectivity* out) {
  for (const BoundaryMatch& match : connectivity.matches) {
    EncodeBoundaryMatch(match, out->add_matches());  // every field exact, plus a description
  }
}

absl::StatusOr<Connectivity> ParseStoredConnectivity(const v1::StoredConnectivity& stored,
                                                     const std::vector<Extents>& blocks,
                                                     const std::string& field) {
  Connectivity connectivity;
  connectivity.matches.reserve(stored.matches_size());  // bounded by the data present
  for (int m = 0; m < stored.matches_size(); ++m) {
    SG_ASSIGN_OR_RETURN(BoundaryMatch match, ParseMatch(stored.matches(m), blocks,
                                                        absl::StrCat(field, ".matches[", m, "]")));
    connectivity.matches.push_back(match);
  }
  return connectivity;
}

absl::StatusOr<Connectivity> ParseStoredConnectivity(const v1::StoredConnectivity& stored,
                                                     const MultiBlockGrid& grid,
                                                     const std::string& field) {
  std::vector<Extents> blocks;
  blocks.reserve(grid.blocks.size());
  for (const StructuredBlock& block : grid.blocks) blocks.push_back(block.extents());
  return ParseStoredConnectivity(stored, blocks, field);
}

// ---- Source points ----

absl::Status ForEachSourceChunk(const MultiBlockGrid& grid, int64_t max_values,
                                const std::function<absl::Status(const v1::SourceChunk&)>& emit) {
  if (max_values < 1) return Invalid("max_values = ", max_values, "; must be at least 1");
  const bool iblank = !grid.blocks.empty() && !grid.blocks[0].iblank().empty();
  v1::SourceChunk chunk;  // reused: its repeated fields keep their capacity
  for (size_t b = 0; b < grid.blocks.size(); ++b) {
    const StructuredBlock& block = grid.blocks[b];
    // The header has one iblank flag for the grid: every block has iblank or none has.
    if (static_cast<int64_t>(block.iblank().size()) != (iblank ? block.num_points() : 0)) {
      return Invalid("block ", b, " has ", block.iblank().size(), " iblank values; ",
                     iblank ? "block 0 has iblank, so it needs one per point" : "block 0 has none");
    }
    const std::span<const double> coords = block.coords();
    for (size_t first = 0; first < coords.size(); first += max_values) {
      const size_t count = std::min<size_t>(max_values, coords.size() - first);
      chunk.Clear();
      chunk.set_block(static_cast<int>(b));
      chunk.set_first(static_cast<int64_t>(first));
      chunk.mutable_coords()->Assign(coords.begin() + first, coords.begin() + first + count);
      SG_RETURN_IF_ERROR(emit(chunk));
    }
    const std::vector<int>& flags = block.iblank();
    for (size_t first = 0; first < flags.size(); first += max_values) {
      const size_t count = std::min<size_t>(max_values, flags.size() - first);
      chunk.Clear();
      chunk.set_block(static_cast<int>(b));
      chunk.set_first(static_cast<int64_t>(first));
      chunk.mutable_iblank()->Assign(flags.begin() + first, flags.begin() + first + count);
      SG_RETURN_IF_ERROR(emit(chunk));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<SourceAssembler> SourceAssembler::Create(const v1::ArchiveHeader& header) {
  SG_RETURN_IF_ERROR(CheckArchiveVersion(header));
  const int s = header.spatial_dim();
  if (s != 2 && s != 3) return Invalid("header.spatial_dim = ", s, "; must be 2 or 3");
  const int num_blocks = header.source_blocks_size();
  if (num_blocks < 1 || num_blocks > kMaxBlocks) {
    return Invalid("header.source_blocks: ", num_blocks, " blocks; must be 1 to ", kMaxBlocks);
  }
  std::vector<Extents> extents(num_blocks);  // one entry per block present in the message
  for (int b = 0; b < num_blocks; ++b) {
    extents[b] = ParseExtents(header.source_blocks(b));
    SG_RETURN_IF_ERROR(ValidateExtents(extents[b], absl::StrCat("header.source_blocks[", b, "]")));
  }
  return SourceAssembler(std::move(extents), s, header.source_iblank());
}

absl::Status SourceAssembler::Add(const v1::SourceChunk& chunk) {
  if (complete()) {
    return Invalid("source chunk for block ", chunk.block(), " at ", chunk.first(),
                   " after every block is complete");
  }
  if (chunk.block() != block_) {
    return Invalid("source chunk for block ", chunk.block(), " while block ", block_,
                   " is incomplete (chunks come block by block, in order)");
  }
  const bool has_coords = chunk.coords_size() > 0, has_iblank = chunk.iblank_size() > 0;
  if (has_coords == has_iblank) {
    return Invalid("source chunk for block ", block_, " at ", chunk.first(), " has ",
                   has_coords ? "both coords and iblank" : "neither coords nor iblank");
  }
  return has_coords ? AddCoords(chunk) : AddIblank(chunk);
}

absl::Status SourceAssembler::AddCoords(const v1::SourceChunk& chunk) {
  const Extents& n = extents_[block_];
  const int64_t total = spatial_dim_ * NumPoints(n);
  const int64_t filled = static_cast<int64_t>(coords_.size());
  const std::string at = absl::StrCat("source chunk for block ", block_, " at ", chunk.first());
  if (filled == total) return Invalid(at, ": coords after the block's coordinates are complete");
  if (chunk.first() != filled) {
    return Invalid(at, ": out of order or overlapping; the next coordinate is ", filled);
  }
  if (chunk.coords_size() > total - filled) {
    return Invalid(at, ": ", chunk.coords_size(), " coordinates, but the block has ",
                   total - filled, " left of ", total);
  }
  for (int c = 0; c < chunk.coords_size(); ++c) {
    if (!std::isfinite(chunk.coords(c))) {
      const int64_t value = filled + c, p = value / spatial_dim_;
      return Invalid(at, ": point (", p % n[0], ", ", (p / n[0]) % n[1], ", ",
                     p / (int64_t{n[0]} * n[1]), ") coordinate ",
                     std::string(1, "xyz"[value % spatial_dim_]), " is ", chunk.coords(c),
                     "; coordinates must be finite");
    }
  }
  const int64_t before = static_cast<int64_t>(coords_.capacity());
  AppendCapped(chunk.coords(), static_cast<size_t>(total), coords_);
  bytes_ += (static_cast<int64_t>(coords_.capacity()) - before) * int64_t{sizeof(double)};
  if (static_cast<int64_t>(coords_.size()) == total && !iblank_) CompleteBlock();
  return absl::OkStatus();
}

absl::Status SourceAssembler::AddIblank(const v1::SourceChunk& chunk) {
  const int64_t points = NumPoints(extents_[block_]);
  const int64_t filled = static_cast<int64_t>(iblank_values_.size());
  const std::string at = absl::StrCat("source chunk for block ", block_, " at ", chunk.first());
  if (!iblank_) return Invalid(at, ": iblank values, but header.source_iblank is false");
  if (static_cast<int64_t>(coords_.size()) != spatial_dim_ * points) {
    return Invalid(at, ": iblank values before the block's coordinates are complete");
  }
  if (chunk.first() != filled) {
    return Invalid(at, ": out of order or overlapping; the next iblank value is ", filled);
  }
  if (chunk.iblank_size() > points - filled) {
    return Invalid(at, ": ", chunk.iblank_size(), " iblank values, but the block has ",
                   points - filled, " left of ", points);
  }
  const int64_t before = static_cast<int64_t>(iblank_values_.capacity());
  AppendCapped(chunk.iblank(), static_cast<size_t>(points), iblank_values_);
  bytes_ += (static_cast<int64_t>(iblank_values_.capacity()) - before) * int64_t{sizeof(int)};
  if (static_cast<int64_t>(iblank_values_.size()) == points) CompleteBlock();
  return absl::OkStatus();
}

void SourceAssembler::CompleteBlock() {
  // StructuredBlock allocates its own coordinates, so the values are copied once more here
  // (briefly twice this block's size); the iblank vector moves.
  StructuredBlock block(extents_[block_], spatial_dim_);
  std::copy(coords_.begin(), coords_.end(), block.coords().begin());
  bytes_ -= static_cast<int64_t>(coords_.capacity() * sizeof(double) +
                                 iblank_values_.capacity() * sizeof(int));
  bytes_ +=
      static_cast<int64_t>(coords_.size() * sizeof(double) + iblank_values_.size() * sizeof(int));
  coords_ = std::vector<double>();
  block.iblank() = std::move(iblank_values_);
  iblank_values_ = std::vector<int>();
  grid_.blocks.push_back(std::move(block));
  ++block_;
}

absl::StatusOr<MultiBlockGrid> SourceAssembler::Finish() && {
  if (!complete()) {
    const int64_t points = NumPoints(extents_[block_]);
    return Invalid(
        "source points incomplete: block ", block_, " of ", extents_.size(), " has ",
        coords_.size(), " of ", spatial_dim_ * points, " coordinates",
        iblank_ ? absl::StrCat(" and ", iblank_values_.size(), " of ", points, " iblank values")
                : "");
  }
  return std::move(grid_);
}

}  // namespace splinegrid
