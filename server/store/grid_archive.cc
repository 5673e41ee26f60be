#include "server/store/grid_archive.h"

#include <algorithm>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "core/util/quote.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"
#include "proto/convert/plot3d_format_convert.h"
#include "proto/convert/source_boundaries_convert.h"
#include "server/grid_id.h"
#include "server/store/revision_codec.h"

namespace splinegrid::server {
v1::ArchiveHeader EncodeGridHeader(const StoredGrid& grid, int64_t num_revisions) {
  v1::ArchiveHeader header;
  header.set_format_version(kArchiveFormatVersion);
  header.set_id(grid.id);
  header.set_display_name(grid.display_name);
  header.set_owner(grid.owner);
  header.set_incarnation(grid.incarnation);
  EncodeStoredTime(grid.create_time, header.mutable_create_time());
  const SourcePoints& source = *grid.source;
  header.set_source_format(source.format);
  if (source.plot3d.has_value()) {
    EncodePlot3dSourceFormat(*source.plot3d, header.mutable_source_plot3d());
  }
  header.set_spatial_dim(source.grid().blocks.front().spatial_dim());
  for (const StructuredBlock& block : source.grid().blocks) {
    EncodeExtents(block.extents(), header.add_source_blocks());
    if (!block.iblank().empty()) header.set_source_iblank(true);
  }
  EncodeStoredConnectivity(source.connectivity(), header.mutable_connectivity());
  if (!source.boundaries.empty()) {
    EncodeSourceBoundaries(source.boundaries, header.mutable_source_boundaries());
  }
  int64_t chunks = 0;
  // Count exactly as ForEachSourceChunk cuts (it cannot fail on a stored grid).
  ForEachSourceChunk(source.grid(), kSourceChunkValues, [&](const v1::SourceChunk&) {
    ++chunks;
    return absl::OkStatus();
  }).IgnoreError();
  header.set_num_source_chunks(chunks);
  header.set_num_revisions(num_revisions);
  return header;
}

absl::Status ForEachRecord(const StoredGrid& grid,
                           const std::function<absl::Status(const v1::ArchiveRecord&)>& emit) {
  v1::ArchiveRecord record;
  *record.mutable_header() = EncodeGridHeader(grid, static_cast<int64_t>(grid.revisions.size()));
  SG_RETURN_IF_ERROR(emit(record));
  SG_RETURN_IF_ERROR(ForEachSourceChunk(grid.source->grid(), kSourceChunkValues,
                                        [&](const v1::SourceChunk& chunk) {
                                          v1::ArchiveRecord r;
                                          *r.mutable_source() = chunk;
                                          return emit(r);
                                        }));
  for (const auto& revision : grid.revisions) {
    v1::ArchiveRecord r;
    EncodeRevision(*revision, r.mutable_revision());
    SG_RETURN_IF_ERROR(emit(r));
  }
  return absl::OkStatus();
}

GridAssembler::GridAssembler(MemoryBudget* budget, std::string id)
    : budget_(budget), id_(std::move(id)) {}

absl::Status GridAssembler::Add(const v1::ArchiveRecord& record) {
  switch (record.record_case()) {
    case v1::ArchiveRecord::kHeader:
      return AddHeader(record.header());
    case v1::ArchiveRecord::kSource:
      return AddChunk(record.source());
    case v1::ArchiveRecord::kRevision:
      return AddRevision(record.revision());
    case v1::ArchiveRecord::RECORD_NOT_SET:
      break;
  }
  return absl::InvalidArgumentError("an archive record is empty (no header, source or revision)");
}

absl::Status GridAssembler::AddHeader(const v1::ArchiveHeader& header) {
  if (header_) return absl::InvalidArgumentError("the archive has a second header");
  SG_RETURN_IF_ERROR(CheckArchiveVersion(header));
  const std::string id = id_.empty() ? header.id() : id_;
  if (!IsValidGridId(id)) {
    return absl::InvalidArgumentError(absl::StrCat("header.id = ", QuoteClientString(id),
                                                   " is not a grid id (1-63 of [a-z0-9-], a "
                                                   "letter first)"));
  }
  if (header.display_name().size() > 1024) {
    return absl::InvalidArgumentError("header.display_name is longer than 1024 bytes");
  }
  if (header.owner().size() > 1024) {
    return absl::InvalidArgumentError("header.owner is longer than 1024 bytes");
  }
  if (const std::string& incarnation = header.incarnation();
      incarnation.size() > 64 || !std::all_of(incarnation.begin(), incarnation.end(), [](char c) {
        return absl::ascii_isdigit(c) || (c >= 'a' && c <= 'f');
      })) {
    return absl::InvalidArgumentError(
        absl::StrCat("header.incarnation = ", QuoteClientString(incarnation),
                     " is not up to 64 lowercase hexadecimal digits"));
  }
  if (header.num_source_chunks() < 0 || header.num_revisions() < 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "header.num_source_chunks = ", header.num_source_chunks(),
        " and header.num_revisions = ", header.num_revisions(), " must not be negative"));
  }
  SG_ASSIGN_OR_RETURN(const absl::Time create_time,
                      ParseStoredTime(header.create_time(), "header.create_time"));
  SG_ASSIGN_OR_RETURN(SourceAssembler source, SourceAssembler::Create(header));
  source_.emplace(std::move(source));
  grid_ = std::make_shared<StoredGrid>();
  grid_->id = id;
  grid_->display_name = header.display_name();
  grid_->owner = header.owner();
  grid_->incarnation = header.incarnation();
  grid_->create_time = create_time;
  header_ = header;
  return absl::OkStatus();
}

absl::Status GridAssembler::AddChunk(const v1::SourceChunk& chunk) {
  if (!header_) return absl::InvalidArgumentError("a source chunk came before the header");
  if (!source_) return absl::InvalidArgumentError("a source chunk came after the revisions");
  const int64_t before = source_->bytes();
  SG_RETURN_IF_ERROR(source_->Add(chunk));
  ++chunks_;
  return budget_->Extend(&source_memory_, source_->bytes() - before, "the archive's source points");
}

absl::Status GridAssembler::FinishSource(const std::string& event) {
  absl::Status status = AssembleSource(event);
  // Nothing can follow a source that did not assemble: later records and Finish say why.
  if (!status.ok()) source_error_ = status;
  return status;
}

absl::Status GridAssembler::AssembleSource(const std::string& event) {
  if (!source_->complete() || chunks_ != header_->num_source_chunks()) {
    return absl::InvalidArgumentError(
        absl::StrCat(event, " after ", chunks_, " of the header's ", header_->num_source_chunks(),
                     " source chunks: the source points are incomplete (truncated archive?)"));
  }
  auto points = std::make_shared<SourcePoints>();
  SG_ASSIGN_OR_RETURN(unchecked_, std::move(*source_).Finish());
  source_.reset();
  SG_ASSIGN_OR_RETURN(stated_connectivity_,
                      ParseStoredConnectivity(header_->connectivity(), unchecked_));
  points->format = header_->source_format();
  if (header_->has_source_plot3d()) {
    SG_ASSIGN_OR_RETURN(points->plot3d,
                        ParsePlot3dSourceFormat(header_->source_plot3d(),
                                                static_cast<int>(unchecked_.blocks.size()),
                                                "header.source_plot3d"));
  }
  std::vector<Extents> extents;
  for (const StructuredBlock& block : unchecked_.blocks) extents.push_back(block.extents());
  SG_ASSIGN_OR_RETURN(
      points->boundaries,
      ParseSourceBoundaries(header_->source_boundaries(), extents, "header.source_boundaries"));
  points->memory = std::move(source_memory_);
  points_ = std::move(points);
  return absl::OkStatus();
}

bool GridAssembler::has_source() const {
  return points_ != nullptr || (source_ && source_->complete());
}

absl::Status GridAssembler::AddRevision(const v1::StoredRevision& stored) {
  if (!header_) return absl::InvalidArgumentError("a revision came before the header");
  SG_RETURN_IF_ERROR(source_error_);
  if (source_) SG_RETURN_IF_ERROR(FinishSource("a revision came"));
  SG_ASSIGN_OR_RETURN(std::shared_ptr<const GridRevision> revision, LoadRevision(stored, budget_));
  if (!grid_->revisions.empty() && revision->number <= grid_->revisions.back()->number) {
    return absl::InvalidArgumentError(
        absl::StrCat("revision ", revision->number, " follows revision ",
                     grid_->revisions.back()->number, ": revisions must come in ascending order"));
  }
  SG_RETURN_IF_ERROR(CheckRevisionMatchesSource(*revision, unchecked_));
  grid_->revisions.push_back(std::move(revision));
  return absl::OkStatus();
}

absl::StatusOr<std::shared_ptr<StoredGrid>> GridAssembler::Finish(bool check_counts,
                                                                  const CancelCheck& cancel) {
  if (!header_) return absl::InvalidArgumentError("the archive is empty: no header");
  SG_RETURN_IF_ERROR(source_error_);
  if (source_) SG_RETURN_IF_ERROR(FinishSource("the archive ends"));
  // The points are checked for fitting and matched once, here (on the caller's worker, not
  // as records arrive): a block that cannot be fitted refuses the whole grid.
  SG_ASSIGN_OR_RETURN(points_->checked, FittableGrid::Check(std::move(unchecked_), {}, cancel),
                      "the archive's source points: ");
  grid_->source = std::move(points_);
  if (check_counts && static_cast<int64_t>(grid_->revisions.size()) != header_->num_revisions()) {
    return absl::InvalidArgumentError(
        absl::StrCat("the archive ends after ", grid_->revisions.size(), " of the header's ",
                     header_->num_revisions(), " revisions: it is truncated"));
  }
  return std::move(grid_);
}

absl::StatusOr<std::shared_ptr<const GridRevision>> LoadRevision(const v1::StoredRevision& stored,
                                                                 MemoryBudget* budget) {
  SG_ASSIGN_OR_RETURN(GridRevision revision, ParseRevision(stored));
  SG_ASSIGN_OR_RETURN(revision.memory, budget->Reserve(RevisionBytes(revision),
                                                       absl::StrCat("revision ", revision.number)));
  return std::make_shared<const GridRevision>(std::move(revision));
}

}  // namespace splinegrid::server
