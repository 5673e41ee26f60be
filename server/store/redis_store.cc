#include "server/store/redis_store.h"

#include <algorithm>
#include <condition_variable>
#include <cstdio>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "core/util/status_macros.h"
#include "proto/convert/archive_convert.h"
#include "server/store/grid_archive.h"
#include "server/store/redis_event_reader.h"
#include "server/store/redis_scripts.h"
#include "server/store/redis_snapshots.h"
#include "server/store/revision_codec.h"

namespace splinegrid::server {
namespace {

constexpr int64_t kChunksPerRound = 16;  // source chunks per RPUSH: 16 MiB

std::string WholeSeconds(absl::Duration d) {
  return absl::StrCat(std::max<int64_t>(1, absl::ToInt64Seconds(d)));
}

std::string FormatBytes(int64_t bytes) {
  if (bytes >= (int64_t{1} << 30)) return absl::StrFormat("%.2f GiB", bytes / double(1 << 30));
  if (bytes >= (int64_t{1} << 20)) return absl::StrFormat("%.2f MiB", bytes / double(1 << 20));
  return absl::StrCat(bytes, " bytes");
}

absl::Status NotFound(const std::string& id, const char* how) {
  return absl::NotFoundError(absl::StrCat("grids/", id, " ", how));
}

// Warns on stderr (once per process and address) unless Redis persists every write before
// acknowledging it and never evicts keys.
void WarnAboutDurability(RedisConnection& connection) {
  static std::mutex mu;
  static std::set<std::string>* warned = new std::set<std::string>();
  {
    std::lock_guard<std::mutex> lock(mu);
    if (!warned->insert(connection.address()).second) return;
  }
  auto config = [&](const char* name) -> std::string {
    absl::StatusOr<RedisReply> reply = connection.Command({"CONFIG", "GET", name});
    if (!reply.ok() || reply->value().size() != 2) return "?";
    return std::string(reply->value()[1].str());
  };
  const std::string appendonly = config("appendonly");
  if (appendonly == "?") return;  // CONFIG is disabled (a managed Redis): nothing to say
  const char* address = connection.address().c_str();
  if (appendonly != "yes") {
    std::fprintf(stderr,
                 "splinegrid: Redis at %s has appendonly %s: revisions acknowledged since its "
                 "last snapshot are lost if it stops (run it with appendonly yes, appendfsync "
                 "always)\n",
                 address, appendonly.c_str());
  } else if (const std::string appendfsync = config("appendfsync"); appendfsync != "always") {
    std::fprintf(stderr,
                 "splinegrid: Redis at %s has appendfsync %s: a power loss may lose about the "
                 "last second of acknowledged revisions (appendfsync always loses none)\n",
                 address, appendfsync.c_str());
  }
  const std::string policy = config("maxmemory-policy");
  if (config("maxmemory") != "0" && policy != "noeviction") {
    std::fprintf(stderr,
                 "splinegrid: Redis at %s has maxmemory-policy %s: it may evict grids when "
                 "full (noeviction makes writes fail with RESOURCE_EXHAUSTED instead)\n",
                 address, policy.c_str());
  }
}

// Streams, ZPOPMIN and UNLINK: Redis 5 or newer.
absl::Status CheckVersion(RedisConnection& connection) {
  SG_ASSIGN_OR_RETURN(RedisReply info, connection.Command({"INFO", "server"}));
  for (absl::string_view line : absl::StrSplit(Absl(info.value().str()), "\r\n")) {
    if (!absl::StartsWith(line, "redis_version:")) continue;
    int major = 0;
    const absl::string_view version = line.substr(line.find(':') + 1);
    if (absl::SimpleAtoi(version.substr(0, version.find('.')), &major) && major < 5) {
      return absl::FailedPreconditionError(absl::StrCat("Redis at ", connection.address(),
                                                        " is version ", version,
                                                        "; the store needs 5 or newer"));
    }
  }
  return absl::OkStatus();
}

class RedisStore final : public GridStore {
 public:
  RedisStore(const RedisAddress& address, RedisStoreOptions options, MemoryBudget* budget)
      : options_(std::move(options)),
        keys_(options_.key_prefix),
        pool_(address, options_.connection, options_.max_connections),
        snapshots_(&pool_, &keys_, budget),
        events_(address, options_.connection, keys_, options_.watch_block) {
    health_ = std::thread([this] { FollowHealth(); });
  }

  ~RedisStore() override {
    {
      std::lock_guard<std::mutex> lock(health_mu_);
      stopping_ = true;
    }
    health_cv_.notify_all();
    health_.join();
  }

  absl::Status Create(std::shared_ptr<const StoredGrid> grid) override;
  absl::StatusOr<std::shared_ptr<const StoredGrid>> Get(const std::string& id) override {
    SG_ASSIGN_OR_RETURN(RedisSnapshots::Fetched fetched, snapshots_.Fetch(id));
    return std::move(fetched.snapshot);
  }
  absl::StatusOr<std::shared_ptr<const StoredGrid>> GetHolding(
      const std::string& id, std::initializer_list<int64_t> numbers) override;
  absl::StatusOr<std::shared_ptr<const StoredGrid>> AddRevision(
      const std::string& id, GridRevision revision, int64_t expected_latest,
      const std::string& incarnation) override;
  absl::Status Delete(const std::string& id, const DeleteCheck& check = nullptr) override;
  absl::StatusOr<Watch> Subscribe(const std::string& id, std::weak_ptr<GridWatcher> watcher,
                                  size_t max_queued) override;
  void Unsubscribe(const std::string& id, const GridSubscription* subscription) override {
    events_.Remove(id, subscription);
  }
  void CloseSubscriptions() override { events_.CloseAll(); }
  absl::StatusOr<std::vector<std::shared_ptr<const StoredGrid>>> List(const std::string& after,
                                                                      int limit,
                                                                      bool* more) override;
  absl::StatusOr<Counts> Count() override {
    SG_ASSIGN_OR_RETURN(RedisReply reply, pool_.Command({"ZCARD", keys_.Index()}));
    return Counts{reply.value().AsInt().value_or(0), std::nullopt};
  }
  absl::Status Available() const override {
    std::lock_guard<std::mutex> lock(health_mu_);
    return available_;
  }

 private:
  // Writes `grid`'s header, chunks and `revisions` (number, value) under generation `gen`,
  // every key with the pending TTL.
  absl::Status WriteGeneration(const StoredGrid& grid, const std::string& gen,
                               const std::vector<std::pair<int64_t, std::string>>& revisions,
                               int64_t* num_chunks);
  absl::Status CheckRevisionSize(const std::string& id, int64_t number, size_t bytes) const;
  void FollowHealth();
  absl::Status Ping(std::unique_ptr<RedisConnection>& connection, bool* stale);

  const RedisStoreOptions options_;
  const RedisKeys keys_;
  RedisPool pool_;
  RedisSnapshots snapshots_;
  RedisEventReader events_;

  mutable std::mutex health_mu_;
  std::condition_variable health_cv_;
  bool stopping_ = false;
  absl::Status available_;  // OpenRedisStore reached Redis
  std::thread health_;
};

absl::StatusOr<std::shared_ptr<const StoredGrid>> RedisStore::GetHolding(
    const std::string& id, std::initializer_list<int64_t> numbers) {
  const bool all_given =
      std::all_of(numbers.begin(), numbers.end(), [](int64_t n) { return n > 0; });
  if (all_given && options_.cached_read_window > absl::ZeroDuration()) {
    if (std::optional<RedisGridCache::Entry> cached =
            snapshots_.Recent(id, options_.cached_read_window)) {
      const StoredGrid& grid = *cached->snapshot;
      if (std::all_of(numbers.begin(), numbers.end(),
                      [&](int64_t n) { return grid.ResolveRevision(n).ok(); })) {
        return std::move(cached->snapshot);
      }
    }
  }
  return Get(id);
}

// ---- Writing ----

absl::Status RedisStore::CheckRevisionSize(const std::string& id, int64_t number,
                                           size_t bytes) const {
  if (static_cast<int64_t>(bytes) <= options_.max_revision_bytes) return absl::OkStatus();
  return absl::ResourceExhaustedError(absl::StrCat(
      "grids/", id, number > 0 ? absl::StrCat(" revision ", number) : " new revision", " takes ",
      FormatBytes(bytes), " (", bytes, " bytes) stored; the Redis store holds at most ",
      FormatBytes(options_.max_revision_bytes), " per revision"));
}

absl::Status RedisStore::Create(std::shared_ptr<const StoredGrid> grid) {
  grid = WithinRetention(std::move(grid), options_.max_deform_revisions);
  const std::string& id = grid->id;
  if (!grid->source || grid->source->grid().blocks.empty()) {
    return absl::InvalidArgumentError(absl::StrCat("grids/", id, " has no source points"));
  }
  const int64_t source_bytes = SourceBytes(grid->source->grid());
  if (source_bytes > options_.max_source_bytes) {
    return absl::ResourceExhaustedError(absl::StrCat(
        "grids/", id, ": the source points take ", FormatBytes(source_bytes), " (", source_bytes,
        " bytes); the Redis store holds at most ", FormatBytes(options_.max_source_bytes), " (",
        options_.max_source_bytes, " bytes) of source points per grid (use a dir: store)"));
  }
  std::vector<std::pair<int64_t, std::string>> revisions;
  for (const auto& revision : grid->revisions) {
    v1::StoredRevision stored;
    EncodeRevision(*revision, &stored);
    revisions.emplace_back(revision->number, stored.SerializeAsString());
    SG_RETURN_IF_ERROR(CheckRevisionSize(id, revision->number, revisions.back().second.size()));
  }
  // Before writing possibly a GiB: is the id taken? (The commit checks again, atomically.)
  SG_ASSIGN_OR_RETURN(RedisReply exists, pool_.Command({"EXISTS", keys_.Grid(id)}));
  if (exists.value().AsInt().value_or(0) != 0) {
    return absl::AlreadyExistsError(absl::StrCat("grids/", id, " already exists"));
  }
  const std::string gen = NewIncarnation();  // the generation
  const std::vector<std::string> gen_keys = {
      keys_.Gen(id, gen, "header"), keys_.Gen(id, gen, "source"), keys_.Gen(id, gen, "revs"),
      keys_.Gen(id, gen, "nums"), keys_.Gen(id, gen, "deforms")};
  int64_t num_chunks = 0;
  if (absl::Status written = WriteGeneration(*grid, gen, revisions, &num_chunks); !written.ok()) {
    // Not committed: nobody sees these keys, and they expire anyway.
    std::vector<std::string_view> unlink = {"UNLINK"};
    unlink.insert(unlink.end(), gen_keys.begin(), gen_keys.end());
    pool_.Command(unlink).IgnoreError();
    return written;
  }
  const std::string grid_key = keys_.Grid(id);
  const std::string index = keys_.Index();
  std::vector<std::string_view> keys = {grid_key, index};
  keys.insert(keys.end(), gen_keys.begin(), gen_keys.end());
  const std::string latest =
      absl::StrCat(grid->revisions.empty() ? 0 : grid->revisions.back()->number);
  const std::string chunks = absl::StrCat(num_chunks);
  const std::string count = absl::StrCat(revisions.size());
  // An error here leaves the outcome unknown: the keys are not removed (if not committed they
  // expire).
  SG_ASSIGN_OR_RETURN(
      RedisReply committed,
      pool_.Run(CreateScript(), keys, {id, gen, latest, chunks, count, grid->owner}));
  switch (committed.value().AsInt().value_or(-2)) {
    case 1:
      snapshots_.Put(id, {gen, WithIncarnation(*grid, gen)});
      return absl::OkStatus();
    case 0:
      return absl::AlreadyExistsError(absl::StrCat("grids/", id, " already exists"));
    default:
      return absl::AbortedError(
          absl::StrCat("grids/", id,
                       ": the data written for it expired in Redis before it was committed "
                       "(writing took longer than ",
                       absl::FormatDuration(options_.pending_ttl), "?); try again"));
  }
}

absl::Status RedisStore::WriteGeneration(
    const StoredGrid& grid, const std::string& gen,
    const std::vector<std::pair<int64_t, std::string>>& revisions, int64_t* num_chunks) {
  const std::string ttl = WholeSeconds(options_.pending_ttl);
  const std::string& id = grid.id;
  const std::string header_key = keys_.Gen(id, gen, "header");
  const std::string source_key = keys_.Gen(id, gen, "source");
  SG_ASSIGN_OR_RETURN(RedisPool::Lease lease, pool_.Acquire());
  const v1::ArchiveHeader header = EncodeGridHeader(grid, 0);
  *num_chunks = header.num_source_chunks();
  SG_RETURN_IF_ERROR(
      lease->Command({"SET", header_key, header.SerializeAsString(), "EX", ttl}).status());
  std::vector<std::string> batch;
  auto flush = [&]() -> absl::Status {
    if (batch.empty()) return absl::OkStatus();
    std::vector<std::string_view> push = {"RPUSH", source_key};
    push.insert(push.end(), batch.begin(), batch.end());
    // Refresh the TTLs: a large source may take a while.
    SG_RETURN_IF_ERROR(
        lease->Pipeline({push, {"EXPIRE", source_key, ttl}, {"EXPIRE", header_key, ttl}}).status());
    batch.clear();
    return absl::OkStatus();
  };
  SG_RETURN_IF_ERROR(ForEachSourceChunk(
      grid.source->grid(), kSourceChunkValues, [&](const v1::SourceChunk& chunk) {
        batch.push_back(chunk.SerializeAsString());
        return std::ssize(batch) == kChunksPerRound ? flush() : absl::OkStatus();
      }));
  SG_RETURN_IF_ERROR(flush());
  if (revisions.empty()) return absl::OkStatus();
  const std::string revs = keys_.Gen(id, gen, "revs");
  const std::string nums = keys_.Gen(id, gen, "nums");
  const std::string deforms = keys_.Gen(id, gen, "deforms");
  std::vector<std::string> numbers;
  numbers.reserve(revisions.size());
  for (const auto& [number, value] : revisions) numbers.push_back(absl::StrCat(number));
  std::vector<std::vector<std::string_view>> commands;
  for (size_t r = 0; r < revisions.size(); ++r) {
    commands.push_back({"HSET", revs, numbers[r], revisions[r].second});
    commands.push_back({"ZADD", nums, numbers[r], numbers[r]});
    if (grid.revisions[r]->origin == RevisionOrigin::kDeform) {
      commands.push_back({"ZADD", deforms, numbers[r], numbers[r]});
    }
  }
  for (const std::string* key : {&revs, &nums, &deforms, &header_key, &source_key}) {
    commands.push_back({"EXPIRE", *key, ttl});
  }
  return lease->Pipeline(commands).status();
}

absl::StatusOr<std::shared_ptr<const StoredGrid>> RedisStore::AddRevision(
    const std::string& id, GridRevision revision, int64_t expected_latest,
    const std::string& incarnation) {
  revision.number = 0;  // the script appends the number it assigns
  v1::StoredRevision stored;
  EncodeRevision(revision, &stored);
  const std::string body = stored.SerializeAsString();
  SG_RETURN_IF_ERROR(CheckRevisionSize(id, 0, body.size()));
  const std::optional<RedisGridCache::Entry> cached = snapshots_.Cached(id);
  std::vector<std::string> args = {keys_.Stem(id),
                                   absl::StrCat(expected_latest),
                                   body,
                                   revision.origin == RevisionOrigin::kDeform ? "1" : "0",
                                   absl::StrCat(options_.max_deform_revisions),
                                   EncodeEventSummary(RevisionSummary::Of(revision)),
                                   absl::StrCat(kStreamMaxLen),
                                   incarnation};
  RedisSnapshots::AppendKnown(cached, &args);
  const std::string grid_key = keys_.Grid(id);
  SG_ASSIGN_OR_RETURN(RedisReply reply,
                      pool_.Run(AddRevisionScript(), {grid_key},
                                std::vector<std::string_view>(args.begin(), args.end())));
  const RedisValue result = reply.value();
  switch (result[0].AsInt().value_or(0)) {
    case 1:
      break;
    case -2:
      // The revision was made from this process's snapshot of the earlier creation (possibly
      // read within cached_read_window): drop it, so that the retry reads the grid from Redis.
      snapshots_.Erase(id);
      return ReplacedMeanwhile(id);
    case -1:
      return absl::AbortedError(absl::StrCat("grids/", id, ": base_revision ", expected_latest,
                                             " is stale; the latest revision is ",
                                             result[1].AsInt().value_or(0)));
    default:
      snapshots_.Erase(id);
      return NotFound(id, "was deleted");
  }
  revision.number = result[1].AsInt().value_or(0);
  auto published = std::make_shared<const GridRevision>(std::move(revision));
  SG_ASSIGN_OR_RETURN(RedisSnapshots::Fetched fetched,
                      snapshots_.Assemble(id, std::string(result[2].str()), result[3], result[4],
                                          cached, published));
  return std::move(fetched.snapshot);
}

absl::Status RedisStore::Delete(const std::string& id, const DeleteCheck& check) {
  const std::string grid_key = keys_.Grid(id);
  const std::string index = keys_.Index();
  const std::string stem = keys_.Stem(id);
  const std::string ttl = WholeSeconds(options_.deleted_events_ttl);
  // With a check: read the owner, check it here, and let the script delete only if the owner is
  // still that one (compare and delete); if it changed meanwhile (deleted and created again),
  // check the new one. A few rounds at most: each needs another creation in between.
  for (int round = 0;; ++round) {
    std::string owner;
    if (check) {
      SG_ASSIGN_OR_RETURN(RedisReply read, pool_.Command({"HGET", grid_key, "owner"}));
      if (read.value().is_nil() && round == 0) {
        SG_ASSIGN_OR_RETURN(RedisReply exists, pool_.Command({"EXISTS", grid_key}));
        if (exists.value().AsInt().value_or(0) == 0) return NotFound(id, "not found");
      }
      owner = std::string(read.value().str());
      SG_RETURN_IF_ERROR(check(owner));
    }
    SG_ASSIGN_OR_RETURN(RedisReply reply, pool_.Run(DeleteScript(), {grid_key, index},
                                                    {stem, id, ttl, check ? "1" : "0", owner}));
    const int64_t outcome = reply.value().AsInt().value_or(0);
    if (outcome == -1 && round < 4) continue;
    if (outcome == -1) {
      return absl::AbortedError(
          absl::StrCat("grids/", id, " changed owner while it was being deleted; try again"));
    }
    snapshots_.Erase(id);
    if (outcome != 1) return NotFound(id, "not found");
    return absl::OkStatus();
  }
}

// ---- Watching and listing ----

absl::StatusOr<GridStore::Watch> RedisStore::Subscribe(const std::string& id,
                                                       std::weak_ptr<GridWatcher> watcher,
                                                       size_t max_queued) {
  SG_ASSIGN_OR_RETURN(RedisSnapshots::Fetched fetched, snapshots_.Fetch(id));
  const auto& revisions = fetched.snapshot->revisions;
  const int64_t latest = revisions.empty() ? 0 : revisions.back()->number;
  auto subscription = std::make_shared<GridSubscription>(std::move(watcher), max_queued, latest);
  SG_RETURN_IF_ERROR(events_.Add(id, fetched.gen, latest, subscription));
  return Watch{std::move(fetched.snapshot), std::move(subscription)};
}

absl::StatusOr<std::vector<std::shared_ptr<const StoredGrid>>> RedisStore::List(
    const std::string& after, int limit, bool* more) {
  limit = std::max(limit, 1);
  SG_ASSIGN_OR_RETURN(
      RedisReply reply,
      pool_.Command({"ZRANGEBYLEX", keys_.Index(), after.empty() ? "-" : absl::StrCat("(", after),
                     "+", "LIMIT", "0", absl::StrCat(limit + 1)}));
  const RedisValue ids = reply.value();
  std::vector<std::shared_ptr<const StoredGrid>> page;
  for (size_t i = 0; i < ids.size() && static_cast<int>(i) < limit; ++i) {
    absl::StatusOr<std::shared_ptr<const StoredGrid>> grid = Get(std::string(ids[i].str()));
    if (grid.status().code() == absl::StatusCode::kNotFound) continue;  // deleted meanwhile
    SG_RETURN_IF_ERROR(grid.status());
    page.push_back(*std::move(grid));
  }
  *more = static_cast<int>(ids.size()) > limit;
  return page;
}

// ---- Health ----

absl::Status RedisStore::Ping(std::unique_ptr<RedisConnection>& connection, bool* stale) {
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (!connection) {
      SG_ASSIGN_OR_RETURN(connection, RedisConnection::Open(pool_.address(), options_.connection));
    }
    const absl::Status status = connection->Command({"PING"}).status();
    if (status.ok() || !connection->broken()) return status;
    // The connection broke: Redis went away, and may be back already (try once more).
    connection.reset();
    *stale = true;
  }
  return absl::UnavailableError(
      absl::StrCat("Redis at ", pool_.address().ToString(), " keeps dropping the connection"));
}

void RedisStore::FollowHealth() {
  std::unique_ptr<RedisConnection> connection;
  std::unique_lock<std::mutex> lock(health_mu_);
  for (int64_t pings = 0; !stopping_; ++pings) {
    // With credentials, log in afresh every 20 checks (10 s by default): a connection that is
    // logged in stays so after the password changed, while new ones would be refused.
    if (pool_.address().has_credentials() && pings % 20 == 19) connection.reset();
    lock.unlock();
    bool stale = false;
    const absl::Status status = Ping(connection, &stale);
    // The pool's idle connections are from before the break: dead, even if they do not know.
    if (stale) pool_.DropIdle();
    lock.lock();
    const bool was_available = available_.ok();
    available_ = status;
    if (status.ok() && !was_available) pool_.ResetBackoff();  // reconnect at once
    health_cv_.wait_for(lock, absl::ToChronoMilliseconds(options_.health_interval),
                        [this] { return stopping_; });
  }
}

}  // namespace

absl::StatusOr<std::unique_ptr<GridStore>> OpenRedisStore(const std::string& spec,
                                                          const RedisStoreOptions& options,
                                                          MemoryBudget* budget) {
  SG_ASSIGN_OR_RETURN(RedisAddress address, ParseRedisSpec(spec));
  if (!options.password_file.empty()) {
    if (!address.password.empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat("--store = '", RedactRedisSpec(spec),
                       "' has a password and --redis_password_file gives one too: give it once"));
    }
    address.password_file = options.password_file;
  }
  if (!address.user.empty() && !address.has_credentials()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--store = '", RedactRedisSpec(spec),
                     "' names a user without a password: give it with --redis_password_file or as "
                     "USER:PASSWORD@"));
  }
  if (options.max_deform_revisions < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "max_deform_revisions = ", options.max_deform_revisions, " must be at least 1"));
  }
  if (options.key_prefix.empty()) return absl::InvalidArgumentError("key_prefix is empty");
  SG_ASSIGN_OR_RETURN(const std::unique_ptr<RedisConnection> first,
                      RedisConnection::Open(address, options.connection),
                      "--store=", RedactRedisSpec(spec), ": ");
  SG_RETURN_IF_ERROR(CheckVersion(*first));
  WarnAboutDurability(*first);
  return std::make_unique<RedisStore>(address, options, budget);
}

absl::StatusOr<std::unique_ptr<GridStore>> OpenRedisStore(const std::string& spec,
                                                          const ServerOptions& options,
                                                          MemoryBudget* budget) {
  RedisStoreOptions redis;
  redis.max_deform_revisions = options.max_deform_revisions;
  redis.password_file = options.redis_password_file;
  return OpenRedisStore(spec, redis, budget);
}

}  // namespace splinegrid::server
