// The watch side of the Redis store: one thread per process reads the event streams of every
// watched grid (XREAD BLOCK on its own connection) and feeds the local subscriptions through a
// SubscriptionHub, so a watch on one replica sees the revisions published through any replica,
// in publication order, then the grid's deletion.
//
// A grid's events are a stream per generation whose entry ids the AddRevision script chooses:
// `0-N` for revision N, `1-0` for the deletion. A watch starts from its snapshot's latest
// number L: the reader reads the stream after `0-L` (for a stream it already follows at cursor
// C > L it first replays (L, C] from the stream into the new subscription alone), so nothing
// between the snapshot and the first event is missed and nothing is delivered twice. New
// watches are taken in between reads; XREAD blocks at most `block` so that happens soon.
//
// Numbers of a generation are consecutive from the snapshot on, so a missing entry (the stream
// is trimmed to about kStreamMaxLen entries) is detected and ends the watch as lagging.
//
// Outages: while Redis is away the reader reconnects with backoff and the watches wait. When it
// is back, every followed stream is checked before reading on: it must still reach the reader's
// cursor (its last entry, or the grid's latest number in the same generation). If it does not
// (Redis restarted without the data: no persistence, or `appendfsync everysec` lost the last
// second) the events between cannot be known, and the watch ends with kClosed (the service
// reports UNAVAILABLE) rather than going on with a gap.
#ifndef SPLINEGRID_SERVER_STORE_REDIS_EVENT_READER_H_
#define SPLINEGRID_SERVER_STORE_REDIS_EVENT_READER_H_

#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "server/grid_store.h"
#include "server/store/redis_connection.h"
#include "server/store/redis_scripts.h"
#include "server/store/subscription_hub.h"

namespace splinegrid::server {

// The most entries a grid's event stream keeps (XADD MAXLEN ~): a watcher more than this many
// revisions behind has lagged anyway.
inline constexpr int kStreamMaxLen = 4096;

// A revision's summary as an event's value (its number is the entry id), and back.
std::string EncodeEventSummary(const RevisionSummary& summary);
absl::StatusOr<RevisionSummary> ParseEventSummary(int64_t number, std::string_view value);

class RedisEventReader {
 public:
  // Starts the thread; it connects by itself (and reconnects with backoff).
  RedisEventReader(RedisAddress address, RedisConnectionOptions options, RedisKeys keys,
                   absl::Duration block);
  ~RedisEventReader();  // stops and joins the thread

  // Feeds `subscription` the events of grid `id`'s generation `gen` after revision `after`.
  // UNAVAILABLE after CloseAll.
  absl::Status Add(const std::string& id, const std::string& gen, int64_t after,
                   std::shared_ptr<GridSubscription> subscription);
  // Stops feeding `subscription` (a no-op when it is gone).
  void Remove(const std::string& id, const GridSubscription* subscription);
  // Ends every subscription (kClosed) and refuses new ones.
  void CloseAll();

 private:
  struct Pending {
    std::string hub_key;
    std::string id;
    std::string gen;
    int64_t after = 0;
    std::shared_ptr<GridSubscription> subscription;
  };
  // A followed stream (one generation of one grid): owned by the thread.
  struct Stream {
    std::string id;
    std::string gen;
    std::string key;     // the events stream
    int64_t cursor = 0;  // the last revision number read
    bool checked = false;
    std::vector<std::weak_ptr<GridSubscription>> subscriptions;
  };

  void Run();
  // Takes the pending subscriptions into the hub (replaying what they missed). An error means
  // the connection failed; the ones not taken stay pending.
  absl::Status Admit(RedisConnection& connection);
  // Checks the streams not checked since they were added or since the connection was made.
  absl::Status Check(RedisConnection& connection);
  // One XREAD over every followed stream, delivering what it returns.
  absl::Status ReadOnce(RedisConnection& connection);
  // Delivers one entry of `stream`; false if the stream ended (deleted or a gap).
  bool Deliver(const std::string& hub_key, Stream& stream, std::string_view entry_id,
               RedisValue fields);
  // Ends the subscriptions of `stream` with `end` and forgets it.
  void End(const std::string& hub_key, GridSubscription::End end);
  // Forgets the streams nobody watches any more.
  void Prune();
  bool stopping();

  const RedisAddress address_;
  const RedisConnectionOptions options_;
  const RedisKeys keys_;
  const absl::Duration block_;
  SubscriptionHub hub_;  // keyed "id@gen"

  std::mutex mu_;
  std::condition_variable wake_;
  bool stop_ = false;
  bool closed_ = false;
  std::vector<Pending> pending_;

  std::map<std::string, Stream> streams_;  // by hub key; the thread's
  std::thread thread_;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_STORE_REDIS_EVENT_READER_H_
