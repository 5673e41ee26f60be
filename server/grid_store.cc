#include "server/grid_store.h"

#include "absl/strings/str_cat.h"

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

absl::StatusOr<std::shared_ptr<const GridRevision>> StoredGrid::FindRevision(int64_t number) const {
  if (revisions.empty()) {
    return absl::FailedPreconditionError(
        absl::StrCat("grids/", id, " has no revision yet; call FitGrid first"));
  }
  if (number == 0) return revisions.back();
  for (const auto& revision : revisions) {
    if (revision->number == number) return revision;
  }
  return absl::NotFoundError(absl::StrCat("grids/", id, " has no revision ", number, " (latest is ",
                                          revisions.back()->number, ")"));
}

absl::StatusOr<std::shared_ptr<const GridRevision>> StoredGrid::FindRevision(
    int64_t number, std::optional<int64_t> step) const {
  if (!step) return FindRevision(number);
  if (number != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("revision = ", number, " and step = ", *step, " are both given; give one"));
  }
  for (auto it = revisions.rbegin(); it != revisions.rend(); ++it) {
    if ((*it)->origin == RevisionOrigin::kDeform && (*it)->step == *step) return *it;
  }
  return absl::NotFoundError(absl::StrCat("grids/", id, " has no revision of step ", *step));
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

int64_t RevisionBytes(const GridFit& fit) {
  int64_t bytes = 0;
  for (const BlockFit& block : fit.blocks) {
    bytes += FittedBlockBytes(block.fitted) + static_cast<int64_t>(sizeof(BlockFit)) +
             static_cast<int64_t>(block.quality.bad_cells.size() * sizeof(Extents));
  }
  for (const std::vector<uint8_t>& kinds : fit.kinds.point_kinds) {
    bytes += static_cast<int64_t>(kinds.size());
  }
  return bytes;
}

absl::Status GridStore::Create(std::shared_ptr<const StoredGrid> grid) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto [it, inserted] = grids_.emplace(grid->id, grid);
  if (!inserted) {
    return absl::AlreadyExistsError(absl::StrCat("grids/", grid->id, " already exists"));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::shared_ptr<const StoredGrid>> GridStore::Get(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = grids_.find(id);
  if (it == grids_.end()) return absl::NotFoundError(absl::StrCat("grids/", id, " not found"));
  return it->second;
}

absl::StatusOr<std::shared_ptr<const StoredGrid>> GridStore::AddRevision(const std::string& id,
                                                                         GridRevision revision,
                                                                         int64_t expected_latest) {
  auto published = std::make_shared<GridRevision>(std::move(revision));
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = grids_.find(id);
  if (it == grids_.end()) {
    return absl::NotFoundError(absl::StrCat("grids/", id, " was deleted"));
  }
  const int64_t latest = it->second->revisions.empty() ? 0 : it->second->revisions.back()->number;
  if (expected_latest != 0 && latest != expected_latest) {
    return absl::AbortedError(absl::StrCat("grids/", id, ": base_revision ", expected_latest,
                                           " is stale; the latest revision is ", latest));
  }
  auto next = std::make_shared<StoredGrid>(*it->second);
  published->number = next->revisions.empty() ? 1 : next->revisions.back()->number + 1;
  next->revisions.push_back(std::move(published));
  it->second = next;
  return std::shared_ptr<const StoredGrid>(next);
}

absl::Status GridStore::Delete(const std::string& id) {
  std::shared_ptr<const StoredGrid> removed;  // released after the lock
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = grids_.find(id);
  if (it == grids_.end()) return absl::NotFoundError(absl::StrCat("grids/", id, " not found"));
  removed = std::move(it->second);
  grids_.erase(it);
  return absl::OkStatus();
}

std::vector<std::shared_ptr<const StoredGrid>> GridStore::List(const std::string& after, int limit,
                                                               bool* more) const {
  std::vector<std::shared_ptr<const StoredGrid>> page;
  std::lock_guard<std::mutex> lock(mu_);
  auto it = grids_.upper_bound(after);
  for (; it != grids_.end() && static_cast<int>(page.size()) < limit; ++it) {
    page.push_back(it->second);
  }
  *more = it != grids_.end();
  return page;
}

}  // namespace splinegrid::server
