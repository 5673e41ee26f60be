#include "server/store/redis_event_reader.h"

#include <algorithm>
#include <cstdio>
#include <set>

#include "absl/base/casts.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "core/util/status_macros.h"

namespace splinegrid::server {
namespace {

constexpr int kReadCount = 256;  // entries per stream per XREAD

std::string HubKey(const std::string& id, const std::string& gen) {
  return absl::StrCat(id, "@", gen);
}

std::string EntryId(int64_t number) { return absl::StrCat("0-", number); }

// An entry id "MS-SEQ": (0, N) is revision N, (1, 0) the deletion.
bool ParseEntryId(std::string_view id, int64_t* ms, int64_t* seq) {
  const size_t dash = id.find('-');
  return dash != std::string_view::npos && absl::SimpleAtoi(Absl(id.substr(0, dash)), ms) &&
         absl::SimpleAtoi(Absl(id.substr(dash + 1)), seq);
}

// The value of field `name` of a stream entry's [field, value, ...] array.
std::string_view FieldOf(RedisValue fields, std::string_view name) {
  for (size_t i = 0; i + 1 < fields.size(); i += 2) {
    if (fields[i].str() == name) return fields[i + 1].str();
  }
  return {};
}

}  // namespace

std::string EncodeEventSummary(const RevisionSummary& summary) {
  // The time step's double by its bits: exact, whatever it holds.
  return absl::StrCat(absl::ToUnixNanos(summary.create_time), " ", static_cast<int>(summary.origin),
                      " ", summary.parent, " ", absl::bit_cast<uint64_t>(summary.time), " ",
                      summary.step);
}

absl::StatusOr<RevisionSummary> ParseEventSummary(int64_t number, std::string_view value) {
  const std::vector<absl::string_view> parts = absl::StrSplit(Absl(value), ' ');
  RevisionSummary summary;
  summary.number = number;
  int64_t nanos = 0;
  int origin = 0;
  uint64_t time_bits = 0;
  if (parts.size() != 5 || !absl::SimpleAtoi(parts[0], &nanos) ||
      !absl::SimpleAtoi(parts[1], &origin) || origin < 0 ||
      origin > static_cast<int>(RevisionOrigin::kDeform) ||
      !absl::SimpleAtoi(parts[2], &summary.parent) || !absl::SimpleAtoi(parts[3], &time_bits) ||
      !absl::SimpleAtoi(parts[4], &summary.step)) {
    return absl::InternalError(absl::StrCat("the event of revision ", number, " is damaged: '",
                                            Absl(value.substr(0, 100)), "'"));
  }
  summary.create_time = absl::FromUnixNanos(nanos);
  summary.origin = static_cast<RevisionOrigin>(origin);
  summary.time = absl::bit_cast<double>(time_bits);
  return summary;
}

RedisEventReader::RedisEventReader(RedisAddress address, RedisConnectionOptions options,
                                   RedisKeys keys, absl::Duration block)
    : address_(std::move(address)), options_(options), keys_(std::move(keys)), block_(block) {
  thread_ = std::thread([this] { Run(); });
}

RedisEventReader::~RedisEventReader() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

absl::Status RedisEventReader::Add(const std::string& id, const std::string& gen, int64_t after,
                                   std::shared_ptr<GridSubscription> subscription) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (closed_) return absl::UnavailableError("the server is shutting down");
    pending_.push_back(Pending{HubKey(id, gen), id, gen, after, std::move(subscription)});
  }
  wake_.notify_all();
  return absl::OkStatus();
}

void RedisEventReader::Remove(const std::string& id, const GridSubscription* subscription) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    std::erase_if(pending_, [&](const Pending& p) { return p.subscription.get() == subscription; });
  }
  const std::string prefix = id + "@";
  for (const std::string& key : hub_.WatchedGrids()) {
    if (key.starts_with(prefix)) hub_.Remove(key, subscription);
  }
}

void RedisEventReader::CloseAll() {
  SubscriptionHub::Woken closed;
  {
    std::lock_guard<std::mutex> lock(mu_);
    closed_ = true;
    for (Pending& p : pending_) {
      p.subscription->Close(GridSubscription::End::kClosed);
      closed.push_back(std::move(p.subscription));
    }
    pending_.clear();
  }
  SubscriptionHub::Wake(closed);
  SubscriptionHub::Wake(hub_.CloseAll());
}

bool RedisEventReader::stopping() {
  std::lock_guard<std::mutex> lock(mu_);
  return stop_;
}

void RedisEventReader::Run() {
  std::unique_ptr<RedisConnection> connection;
  absl::Duration backoff = absl::ZeroDuration();
  while (!stopping()) {
    if (!connection || connection->broken()) {
      connection.reset();
      absl::StatusOr<std::unique_ptr<RedisConnection>> opened =
          RedisConnection::Open(address_, options_);
      if (!opened.ok()) {
        backoff = std::clamp(2 * backoff, absl::Milliseconds(100), absl::Seconds(1));
        std::unique_lock<std::mutex> lock(mu_);
        wake_.wait_for(lock, absl::ToChronoMilliseconds(backoff), [this] { return stop_; });
        continue;
      }
      connection = *std::move(opened);
      backoff = absl::ZeroDuration();
      // Redis may have restarted meanwhile: check every stream still reaches its cursor.
      for (auto& [key, stream] : streams_) stream.checked = false;
    }
    absl::Status status = Admit(*connection);
    if (status.ok()) status = Check(*connection);
    if (status.ok()) {
      Prune();
      if (streams_.empty()) {
        std::unique_lock<std::mutex> lock(mu_);
        wake_.wait_for(lock, absl::ToChronoMilliseconds(block_),
                       [this] { return stop_ || !pending_.empty(); });
        continue;
      }
      status = ReadOnce(*connection);
    }
    if (!status.ok() && !connection->broken()) {
      // Redis answered with an error (e.g. LOADING after a restart): try again shortly.
      std::unique_lock<std::mutex> lock(mu_);
      wake_.wait_for(lock, absl::ToChronoMilliseconds(block_), [this] { return stop_; });
    }
  }
}

absl::Status RedisEventReader::Admit(RedisConnection& connection) {
  std::vector<Pending> taking;
  {
    std::lock_guard<std::mutex> lock(mu_);
    taking.swap(pending_);
  }
  for (size_t i = 0; i < taking.size(); ++i) {
    Pending& p = taking[i];
    auto it = streams_.find(p.hub_key);
    bool ended = false;
    bool pushed = false;
    if (it != streams_.end() && it->second.cursor > p.after) {
      // The stream is read past this watch's snapshot: replay (after, cursor] to it alone.
      absl::StatusOr<RedisReply> replay = connection.Command(
          {"XRANGE", it->second.key, EntryId(p.after + 1), EntryId(it->second.cursor)});
      if (!replay.ok()) {
        std::lock_guard<std::mutex> lock(mu_);
        pending_.insert(pending_.begin(), std::make_move_iterator(taking.begin() + i),
                        std::make_move_iterator(taking.end()));
        return replay.status();
      }
      int64_t expect = p.after + 1;
      const RedisValue entries = replay->value();
      for (size_t e = 0; e < entries.size() && !ended; ++e) {
        int64_t ms = 0;
        int64_t seq = 0;
        absl::StatusOr<RevisionSummary> summary =
            ParseEntryId(entries[e][0].str(), &ms, &seq) && ms == 0 && seq == expect
                ? ParseEventSummary(seq, FieldOf(entries[e][1], "s"))
                : absl::DataLossError("gap");
        ended = !summary.ok() || !p.subscription->Push(*summary);
        pushed = true;
        ++expect;
      }
      ended = ended || expect != it->second.cursor + 1;
    }
    if (ended) {  // entries missing (trimmed) or too many: the watch lags
      p.subscription->Close(GridSubscription::End::kLagged);
      p.subscription->Wake();
      continue;
    }
    if (!hub_.Add(p.hub_key, p.subscription).ok()) {
      p.subscription->Close(GridSubscription::End::kClosed);
      p.subscription->Wake();
      continue;
    }
    if (it == streams_.end()) {
      it = streams_
               .emplace(p.hub_key, Stream{p.id,
                                          p.gen,
                                          keys_.Gen(p.id, p.gen, "events"),
                                          p.after,
                                          /*checked=*/false,
                                          {}})
               .first;
    }
    it->second.subscriptions.push_back(p.subscription);
    if (pushed) p.subscription->Wake();
  }
  return absl::OkStatus();
}

absl::Status RedisEventReader::Check(RedisConnection& connection) {
  std::vector<std::string> lost;
  for (auto& [hub_key, stream] : streams_) {
    if (stream.checked) continue;
    SG_ASSIGN_OR_RETURN(std::vector<RedisReply> replies,
                        connection.Pipeline({{"XREVRANGE", stream.key, "+", "-", "COUNT", "1"},
                                             {"HMGET", keys_.Grid(stream.id), "gen", "latest"}}));
    bool intact = false;
    const RedisValue last = replies[0].value();
    int64_t ms = 0;
    int64_t seq = 0;
    if (last.size() == 1 && ParseEntryId(last[0][0].str(), &ms, &seq)) {
      intact = ms > 0 || seq >= stream.cursor;
    }
    const RedisValue grid = replies[1].value();
    if (grid[0].str() == stream.gen && grid[1].AsInt().value_or(-1) >= stream.cursor) {
      intact = true;
    }
    if (intact) {
      stream.checked = true;
    } else {
      lost.push_back(hub_key);
    }
  }
  for (const std::string& hub_key : lost) {
    std::fprintf(stderr,
                 "splinegrid: Redis at %s no longer has the events of grids/%s after revision "
                 "%lld (restarted without its data?): ending its watches\n",
                 address_.ToString().c_str(), streams_[hub_key].id.c_str(),
                 static_cast<long long>(streams_[hub_key].cursor));
    End(hub_key, GridSubscription::End::kClosed);
  }
  return absl::OkStatus();
}

absl::Status RedisEventReader::ReadOnce(RedisConnection& connection) {
  std::vector<std::string> args = {
      "XREAD",
      "COUNT",
      absl::StrCat(kReadCount),
      "BLOCK",
      absl::StrCat(std::max<int64_t>(1, absl::ToInt64Milliseconds(block_))),
      "STREAMS"};
  std::map<std::string, std::string> hub_key_of;  // stream key -> hub key
  for (const auto& [hub_key, stream] : streams_) {
    args.push_back(stream.key);
    hub_key_of[stream.key] = hub_key;
  }
  for (const auto& [hub_key, stream] : streams_) args.push_back(EntryId(stream.cursor));
  SG_ASSIGN_OR_RETURN(RedisReply reply,
                      connection.Command(std::vector<std::string_view>(args.begin(), args.end())));
  const RedisValue streams = reply.value();  // nil when the block timed out
  for (size_t s = 0; s < streams.size(); ++s) {
    const auto key = hub_key_of.find(std::string(streams[s][0].str()));
    if (key == hub_key_of.end()) continue;
    const RedisValue entries = streams[s][1];
    for (size_t e = 0; e < entries.size(); ++e) {
      const auto stream = streams_.find(key->second);
      if (stream == streams_.end()) break;  // ended by a previous entry
      if (!Deliver(key->second, stream->second, entries[e][0].str(), entries[e][1])) break;
    }
  }
  return absl::OkStatus();
}

bool RedisEventReader::Deliver(const std::string& hub_key, Stream& stream,
                               std::string_view entry_id, RedisValue fields) {
  int64_t ms = 0;
  int64_t seq = 0;
  if (!ParseEntryId(entry_id, &ms, &seq)) return true;  // not ours: ignore
  if (ms == 1) {                                        // the deletion
    SubscriptionHub::Wake(hub_.EndGrid(hub_key));
    streams_.erase(hub_key);
    return false;
  }
  if (ms != 0 || seq <= stream.cursor) return true;
  if (seq != stream.cursor + 1) {  // trimmed away: the reader fell that far behind
    End(hub_key, GridSubscription::End::kLagged);
    return false;
  }
  absl::StatusOr<RevisionSummary> summary = ParseEventSummary(seq, FieldOf(fields, "s"));
  if (!summary.ok()) {
    std::fprintf(stderr, "splinegrid: grids/%s: %s: ending its watches\n", stream.id.c_str(),
                 std::string(summary.status().message()).c_str());
    End(hub_key, GridSubscription::End::kClosed);
    return false;
  }
  stream.cursor = seq;
  SubscriptionHub::Wake(hub_.Publish(hub_key, *summary));
  return true;
}

void RedisEventReader::End(const std::string& hub_key, GridSubscription::End end) {
  const auto it = streams_.find(hub_key);
  if (it == streams_.end()) return;
  SubscriptionHub::Woken ended;
  for (const std::weak_ptr<GridSubscription>& weak : it->second.subscriptions) {
    if (std::shared_ptr<GridSubscription> subscription = weak.lock()) {
      subscription->Close(end);
      hub_.Remove(hub_key, subscription.get());
      ended.push_back(std::move(subscription));
    }
  }
  streams_.erase(it);
  SubscriptionHub::Wake(ended);
}

void RedisEventReader::Prune() {
  const std::vector<std::string> watched = hub_.WatchedGrids();
  const std::set<std::string> keys(watched.begin(), watched.end());
  for (auto it = streams_.begin(); it != streams_.end();) {
    if (!keys.contains(it->first)) {
      it = streams_.erase(it);
      continue;
    }
    std::erase_if(it->second.subscriptions,
                  [](const std::weak_ptr<GridSubscription>& weak) { return weak.expired(); });
    ++it;
  }
}

}  // namespace splinegrid::server
