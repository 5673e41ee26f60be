#include "server/store/redis_snapshots.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"
#include "server/store/grid_archive.h"
#include "server/store/revision_codec.h"

namespace splinegrid::server {
namespace {

constexpr int64_t kChunksPerRound = 16;  // source chunks per LRANGE: 16 MiB

// The bytes the source points announced by `header` take once read (what the assembler
// charges as they arrive).
int64_t AnnouncedSourceBytes(const v1::ArchiveHeader& header) {
  int64_t bytes = 0;
  for (const v1::Extents& e : header.source_blocks()) {
    const int64_t points = int64_t{std::max(e.i(), 1)} * std::max(e.j(), 1) * std::max(e.k(), 1);
    bytes += points * header.spatial_dim() * int64_t{sizeof(double)} +
             (header.source_iblank() ? points * int64_t{sizeof(int)} : 0);
  }
  return bytes;
}

// What Redis holds that does not decode: damage (DATA_LOSS), except a budget refusal.
absl::Status Damaged(const absl::Status& status, const std::string& what) {
  if (status.ok() || status.code() == absl::StatusCode::kResourceExhausted) return status;
  return absl::DataLossError(absl::StrCat(what, " in Redis does not decode: ", status.message()));
}

absl::Status NotFound(const std::string& id, const char* how) {
  return absl::NotFoundError(absl::StrCat("grids/", id, " ", how));
}

}  // namespace

void RedisSnapshots::AppendKnown(const std::optional<RedisGridCache::Entry>& cached,
                                 std::vector<std::string>* args) {
  args->push_back(cached ? cached->gen : "");
  if (!cached) return;
  for (const auto& revision : cached->snapshot->revisions) {
    args->push_back(absl::StrCat(revision->number));
  }
}

absl::StatusOr<RedisSnapshots::Fetched> RedisSnapshots::Fetch(const std::string& id) {
  const std::optional<RedisGridCache::Entry> cached = cache_.Find(id);
  std::vector<std::string> args = {keys_->Stem(id)};
  AppendKnown(cached, &args);
  const std::string grid_key = keys_->Grid(id);
  SG_ASSIGN_OR_RETURN(
      RedisReply reply,
      pool_->Run(GetScript(), {grid_key}, std::vector<std::string_view>(args.begin(), args.end())));
  const RedisValue state = reply.value();
  if (state.is_nil()) {
    cache_.Erase(id);
    return NotFound(id, "not found");
  }
  return Assemble(id, std::string(state[0].str()), state[1], state[2], cached, nullptr);
}

absl::StatusOr<RedisSnapshots::Fetched> RedisSnapshots::Assemble(
    const std::string& id, const std::string& gen, RedisValue numbers, RedisValue values,
    const std::optional<RedisGridCache::Entry>& cached,
    const std::shared_ptr<const GridRevision>& published) {
  const std::shared_ptr<const StoredGrid> base =
      cached && cached->gen == gen ? cached->snapshot : nullptr;
  int64_t new_bytes = 0;  // of the revisions to decode
  for (size_t i = 0; i < values.size(); ++i) new_bytes += std::ssize(values[i].str());
  if (base && !published && new_bytes == 0 && numbers.size() == base->revisions.size()) {
    return Fetched{gen, base};  // nothing changed (the script sends only what is missing)
  }
  std::shared_ptr<const StoredGrid> shell = base;
  if (!shell) {
    SG_ASSIGN_OR_RETURN(shell, LoadShell(id, gen));
  }
  auto snapshot = std::make_shared<StoredGrid>();
  snapshot->id = id;
  snapshot->display_name = shell->display_name;
  snapshot->owner = shell->owner;
  snapshot->incarnation = gen;
  snapshot->create_time = shell->create_time;
  snapshot->source = shell->source;
  bool made_room = false;
  for (size_t i = 0; i < numbers.size(); ++i) {
    const int64_t number = numbers[i].AsInt().value_or(0);
    const std::string_view value = values[i].str();
    if (!value.empty()) {
      SG_ASSIGN_OR_RETURN(std::shared_ptr<const GridRevision> revision,
                          DecodeRevision(id, number, value, *shell->source, new_bytes, &made_room));
      new_bytes -= std::ssize(value);
      snapshot->revisions.push_back(std::move(revision));
      continue;
    }
    if (published && published->number == number) {
      snapshot->revisions.push_back(published);
      continue;
    }
    const auto& known = base ? base->revisions : shell->revisions;
    const auto it = std::lower_bound(
        known.begin(), known.end(), number,
        [](const std::shared_ptr<const GridRevision>& r, int64_t n) { return r->number < n; });
    if (it == known.end() || (*it)->number != number) {
      return absl::DataLossError(absl::StrCat("grids/", id, " revision ", number,
                                              " is listed in Redis but its value is missing"));
    }
    snapshot->revisions.push_back(*it);
  }
  cache_.Put(id, {gen, snapshot});
  return Fetched{gen, std::move(snapshot)};
}

absl::StatusOr<std::shared_ptr<const GridRevision>> RedisSnapshots::DecodeRevision(
    const std::string& id, int64_t number, std::string_view value, const SourcePoints& source,
    int64_t room, bool* made_room) {
  const std::string what = absl::StrCat("grids/", id, " revision ", number);
  v1::StoredRevision stored;
  if (!stored.ParseFromArray(value.data(), static_cast<int>(value.size()))) {
    return absl::DataLossError(absl::StrCat(what, " in Redis is not a StoredRevision"));
  }
  // AddRevisionScript stores the value as the client sent it, without a number (the script
  // chooses it; appending it in Lua copied the value twice more): the field is its number.
  if (stored.number() == 0) stored.set_number(number);
  absl::StatusOr<std::shared_ptr<const GridRevision>> revision = LoadRevision(stored, budget_);
  if (revision.status().code() == absl::StatusCode::kResourceExhausted && !*made_room) {
    *made_room = true;  // once per snapshot
    cache_.MakeRoom(room, id);
    revision = LoadRevision(stored, budget_);
  }
  SG_RETURN_IF_ERROR(Damaged(revision.status(), what));
  if ((*revision)->number != number) {
    return absl::DataLossError(
        absl::StrCat(what, " in Redis holds revision ", (*revision)->number));
  }
  SG_RETURN_IF_ERROR(Damaged(CheckRevisionMatchesSource(**revision, source.grid()), what));
  return revision;
}

std::shared_ptr<std::mutex> RedisSnapshots::LoaderOf(const std::string& id) {
  std::lock_guard<std::mutex> lock(loaders_mu_);
  if (loaders_.size() > 256) {
    std::erase_if(loaders_, [](const auto& entry) { return entry.second.expired(); });
  }
  std::shared_ptr<std::mutex> loader = loaders_[id].lock();
  if (!loader) {
    loader = std::make_shared<std::mutex>();
    loaders_[id] = loader;
  }
  return loader;
}

absl::StatusOr<std::shared_ptr<const StoredGrid>> RedisSnapshots::LoadShell(
    const std::string& id, const std::string& gen) {
  const std::shared_ptr<std::mutex> loader = LoaderOf(id);
  std::lock_guard<std::mutex> loading(*loader);
  // Another call may have read it while this one waited.
  if (std::optional<RedisGridCache::Entry> cached = cache_.Find(id); cached && cached->gen == gen) {
    return cached->snapshot;
  }
  SG_ASSIGN_OR_RETURN(RedisPool::Lease lease, pool_->Acquire());
  SG_ASSIGN_OR_RETURN(RedisReply reply, lease->Command({"GET", keys_->Gen(id, gen, "header")}));
  if (reply.value().is_nil()) return NotFound(id, "was deleted while it was read");
  v1::ArchiveHeader header;
  const std::string_view bytes = reply.value().str();
  if (!header.ParseFromArray(bytes.data(), static_cast<int>(bytes.size()))) {
    return absl::DataLossError(absl::StrCat("grids/", id, ": the header in Redis does not parse"));
  }
  absl::StatusOr<std::shared_ptr<const StoredGrid>> shell = ReadSource(*lease, id, gen, header);
  if (shell.status().code() == absl::StatusCode::kResourceExhausted &&
      cache_.MakeRoom(AnnouncedSourceBytes(header), id)) {
    shell = ReadSource(*lease, id, gen, header);
  }
  return shell;
}

absl::StatusOr<std::shared_ptr<const StoredGrid>> RedisSnapshots::ReadSource(
    RedisConnection& connection, const std::string& id, const std::string& gen,
    const v1::ArchiveHeader& header) {
  const std::string what = absl::StrCat("grids/", id, ": the source points");
  GridAssembler assembler(budget_, id);
  SG_RETURN_IF_ERROR(Damaged(assembler.AddHeader(header), what));
  const std::string key = keys_->Gen(id, gen, "source");
  const int64_t chunks = header.num_source_chunks();
  for (int64_t first = 0; first < chunks; first += kChunksPerRound) {
    const int64_t last = std::min(first + kChunksPerRound, chunks) - 1;
    SG_ASSIGN_OR_RETURN(RedisReply reply, connection.Command({"LRANGE", key, absl::StrCat(first),
                                                              absl::StrCat(last)}));
    const RedisValue batch = reply.value();
    if (static_cast<int64_t>(batch.size()) != last - first + 1) {
      return NotFound(id, "was deleted while it was read");
    }
    for (size_t c = 0; c < batch.size(); ++c) {
      v1::SourceChunk chunk;
      const std::string_view bytes = batch[c].str();
      if (!chunk.ParseFromArray(bytes.data(), static_cast<int>(bytes.size()))) {
        return absl::DataLossError(absl::StrCat(what, ": chunk ", first + c, " does not parse"));
      }
      SG_RETURN_IF_ERROR(Damaged(assembler.AddChunk(chunk), what));
    }
  }
  absl::StatusOr<std::shared_ptr<StoredGrid>> grid = assembler.Finish(/*check_counts=*/false);
  SG_RETURN_IF_ERROR(Damaged(grid.status(), what));
  return std::shared_ptr<const StoredGrid>(*std::move(grid));
}

}  // namespace splinegrid::server
