#include "server/grid_store.h"

#include <algorithm>
#include <optional>
#include <random>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace splinegrid::server {

int64_t GridRevision::num_control_points() const {
  int64_t n = 0;
  for (const BlockFit& b : blocks) n += b.fitted.summary.num_control_points;
  return n;
}

double GridRevision::max_deviation() const {
  double m = 0.0;
  for (const BlockFit& b : blocks) m = std::max(m, b.fitted.summary.deviation.max);
  return m;
}

RevisionSummary RevisionSummary::Of(const GridRevision& revision) {
  RevisionSummary s;
  s.number = revision.number;
  s.create_time = revision.create_time;
  s.origin = revision.origin;
  s.parent = revision.parent;
  s.time = revision.time;
  s.step = revision.step;
  return s;
}

namespace {

// Whether retention dropped revisions of `grid`: numbers are consecutive from 1 and the latest
// is never dropped, so fewer revisions than the latest number means some were.
bool DroppedSome(const StoredGrid& grid) {
  return !grid.revisions.empty() &&
         static_cast<int64_t>(grid.revisions.size()) < grid.revisions.back()->number;
}

}  // namespace

std::shared_ptr<const GridRevision> StoredGrid::DeformationBase(
    const GridRevision& revision) const {
  if (revision.origin != RevisionOrigin::kDeform) return nullptr;
  // Parents have smaller numbers: at most as many hops as revisions.
  int64_t next = revision.parent;
  for (size_t hops = 0; hops <= revisions.size() && next > 0; ++hops) {
    absl::StatusOr<std::shared_ptr<const GridRevision>> up = ResolveRevision(next);
    if (!up.ok()) return nullptr;
    if ((*up)->origin != RevisionOrigin::kDeform) return *std::move(up);
    next = (*up)->parent;
  }
  return nullptr;
}

absl::StatusOr<std::shared_ptr<const GridRevision>> StoredGrid::ResolveRevision(
    int64_t number, std::optional<int64_t> step, const char* field) const {
  if (number < 0) {
    return absl::InvalidArgumentError(absl::StrCat(field, " = ", number, " is negative"));
  }
  if (step) {
    if (*step < 0) {
      return absl::InvalidArgumentError(absl::StrCat("step = ", *step, " is negative"));
    }
    if (number != 0) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, " = ", number, " and step = ", *step, " are both given; give one"));
    }
    std::optional<int64_t> newest_step, oldest_step;  // of the deformed revisions kept
    for (auto it = revisions.rbegin(); it != revisions.rend(); ++it) {
      if ((*it)->origin != RevisionOrigin::kDeform) continue;
      if ((*it)->step == *step) return *it;
      newest_step = std::max(newest_step.value_or((*it)->step), (*it)->step);
      oldest_step = std::min(oldest_step.value_or((*it)->step), (*it)->step);
    }
    // Say why only as far as it is known: a step beyond every kept one was never stored (as far
    // as this grid knows); one between kept ones was not stored either (retention drops the
    // oldest); one below them may have been dropped by retention.
    std::string why;
    if (newest_step && *step > *newest_step) {
      why = absl::StrCat(" (the newest step stored is ", *newest_step, ")");
    } else if (oldest_step && *step > *oldest_step) {
      why = absl::StrCat(" (none was stored for it; the deformed revisions kept range from step ",
                         *oldest_step, " to ", *newest_step, ")");
    } else if (DroppedSome(*this)) {
      why = " (older deformed revisions were dropped by retention)";
    } else if (!newest_step) {
      why = " (it has no deformed revision)";
    }
    if (!damaged_revisions.empty()) {
      absl::StrAppend(&why, "; ", damaged_revisions.size(),
                      " of its revisions were damaged on disk and set aside, their steps unknown");
    }
    return absl::NotFoundError(absl::StrCat("grids/", id, " has no revision of step ", *step, why));
  }
  if (revisions.empty()) {
    return absl::FailedPreconditionError(
        absl::StrCat("grids/", id, " has no revision yet; call FitGrid first"));
  }
  if (number == 0) return revisions.back();
  const auto it = std::lower_bound(
      revisions.begin(), revisions.end(), number,
      [](const std::shared_ptr<const GridRevision>& r, int64_t n) { return r->number < n; });
  if (it != revisions.end() && (*it)->number == number) return *it;
  if (std::binary_search(damaged_revisions.begin(), damaged_revisions.end(), number)) {
    return absl::DataLossError(absl::StrCat(
        "grids/", id, " revision ", number,
        " was damaged on disk: the server set it aside at a start (its log names the file in "
        "the store's corrupt/ directory)"));
  }
  const int64_t latest = revisions.back()->number;
  if (number < latest) {
    return absl::NotFoundError(absl::StrCat(
        "grids/", id, " revision ", number,
        " was dropped by retention: a grid keeps its fitted and faired revisions and only its "
        "newest deformed ones (server flag --keep_revisions); the latest is ",
        latest));
  }
  return absl::NotFoundError(
      absl::StrCat("grids/", id, " has no revision ", number, " (latest is ", latest, ")"));
}

bool GridSubscription::Next(RevisionSummary* revision, End* end) {
  std::lock_guard<std::mutex> lock(mu_);
  if (end_ == End::kLagged || end_ == End::kClosed || queue_.empty()) {
    *end = end_;
    return false;
  }
  *revision = queue_.front();
  queue_.pop_front();
  return true;
}

bool GridSubscription::Push(const RevisionSummary& revision) {
  std::lock_guard<std::mutex> lock(mu_);
  if (end_ != End::kOpen) return false;
  if (revision.number <= after_) return true;  // in the watcher's snapshot, or queued already
  if (queue_.size() >= max_queued_) {
    end_ = End::kLagged;
    queue_.clear();
    return false;
  }
  queue_.push_back(revision);
  after_ = revision.number;
  return true;
}

void GridSubscription::Close(End end) {
  std::lock_guard<std::mutex> lock(mu_);
  if (end_ != End::kOpen) return;
  end_ = end;
  if (end != End::kGridDeleted) queue_.clear();
}

void GridSubscription::Wake() const {
  if (const std::shared_ptr<GridWatcher> watcher = watcher_.lock()) watcher->Wake();
}

int64_t FittedBlockBytes(const FittedBlock& block) {
  int64_t bytes = static_cast<int64_t>(block.spline.control().size()) * sizeof(double);
  for (int d = 0; d < 3; ++d) {
    bytes += static_cast<int64_t>(block.spline.knots(d).knots().size() +
                                  2 * block.distribution.params(d).size()) *
             sizeof(double);
  }
  return bytes + static_cast<int64_t>(sizeof(FittedBlock));
}

namespace {

int64_t BlocksAndKindsBytes(const std::vector<BlockFit>& blocks, const BoundaryKinds& kinds) {
  int64_t bytes = 0;
  for (const BlockFit& block : blocks) {
    bytes += FittedBlockBytes(block.fitted) + static_cast<int64_t>(sizeof(BlockFit)) +
             static_cast<int64_t>(block.quality.bad_cells.size() * sizeof(Extents));
  }
  for (const std::vector<uint8_t>& point_kinds : kinds.point_kinds) {
    bytes += static_cast<int64_t>(point_kinds.size());
  }
  return bytes;
}

}  // namespace

int64_t RevisionBytes(const GridFit& fit) { return BlocksAndKindsBytes(fit.blocks, fit.kinds); }

int64_t RevisionBytes(const GridRevision& revision) {
  return BlocksAndKindsBytes(revision.blocks, revision.kinds);
}

int64_t SourceBytes(const MultiBlockGrid& source) {
  int64_t bytes = 0;
  for (const StructuredBlock& block : source.blocks) {
    bytes += static_cast<int64_t>(block.coords().size() * sizeof(double) +
                                  block.iblank().size() * sizeof(int));
  }
  return bytes;
}

std::shared_ptr<const StoredGrid> WithinRetention(std::shared_ptr<const StoredGrid> grid,
                                                  int max_deform_revisions) {
  const std::vector<int64_t> dropped = DeformRevisionsBeyond(grid->revisions, max_deform_revisions);
  if (dropped.empty()) return grid;
  auto kept = std::make_shared<StoredGrid>(*grid);
  std::erase_if(kept->revisions, [&](const std::shared_ptr<const GridRevision>& r) {
    return std::binary_search(dropped.begin(), dropped.end(), r->number);
  });
  return kept;
}

std::vector<int64_t> DeformRevisionsBeyond(
    const std::vector<std::shared_ptr<const GridRevision>>& revisions, int max_deform_revisions) {
  int64_t excess = -max_deform_revisions;
  for (const auto& r : revisions) excess += r->origin == RevisionOrigin::kDeform;
  std::vector<int64_t> dropped;
  for (const auto& r : revisions) {
    if (excess <= 0) break;
    if (r->origin == RevisionOrigin::kDeform) {
      dropped.push_back(r->number);
      --excess;
    }
  }
  return dropped;
}

std::string NewIncarnation() {
  std::random_device random;
  const uint64_t bits = (uint64_t{random()} << 32) ^ random();
  return absl::StrFormat("%016x", bits);
}

std::shared_ptr<const StoredGrid> WithIncarnation(const StoredGrid& grid, std::string incarnation) {
  auto created = std::make_shared<StoredGrid>(grid);
  created->incarnation = std::move(incarnation);
  return created;
}

absl::Status ReplacedMeanwhile(const std::string& id) {
  return absl::AbortedError(absl::StrCat(
      "grids/", id,
      " was deleted and created again while this call ran: its revision was made from the "
      "earlier grid and is not stored; read the grid again and repeat the call"));
}

absl::Status CreateGrid(GridStore& store, const std::string& requested_id,
                        const std::shared_ptr<StoredGrid>& grid) {
  std::mt19937_64 random(std::random_device{}());
  for (int attempt = 0;; ++attempt) {
    grid->id = requested_id.empty() ? absl::StrFormat("grid-%08x", static_cast<uint32_t>(random()))
                                    : requested_id;
    const absl::Status created = store.Create(grid);
    if (created.ok() || !requested_id.empty() || attempt == 8) return created;
  }
}

}  // namespace splinegrid::server
