// The `redis://HOST:PORT[/DB]` backend: grids in one Redis server, shared by any number of
// server processes (replicas), every replica answering every call on every grid.
//
// Key layout (prefix `splinegrid:`, so deployments can share a Redis by DB or prefix; grid
// ids are [a-z0-9-], generations 16 hex digits; redis_scripts.h has the details):
//   grids                       sorted set of the visible grids' ids (ListGrids pages by id)
//   grid:{id}                   hash: gen (the grid's current generation), latest (its highest
//                               revision number ever): the grid is visible iff this exists
//   grid:{id}:{gen}:header      the ArchiveHeader (name, time, block extents, connectivity)
//   grid:{id}:{gen}:source      list of SourceChunk records (kSourceChunkValues doubles each)
//   grid:{id}:{gen}:revs        hash: revision number -> StoredRevision (revision_codec.h)
//   grid:{id}:{gen}:nums        sorted set of the numbers in revs
//   grid:{id}:{gen}:deforms     sorted set of the deformed ones (retention)
//   grid:{id}:{gen}:events      stream: `0-N` per published revision N, `1-0` for the deletion
// A generation is a random 64-bit id drawn by each Create (the grid's incarnation), so a grid
// deleted and created again under the same id shares no key with its predecessor, and a
// creation's keys are private.
//
// Atomicity. Every change that must be atomic across replicas is one Lua script (EVALSHA),
// which Redis runs without interleaving any other command:
//  - Create writes the header, chunks and revisions under its new generation first, each key
//    with a TTL (pending_ttl, refreshed as chunks are written), then one script checks that
//    grid:{id} is absent and that everything arrived, removes the TTLs and writes grid:{id} and
//    the index entry. So a half-written grid is never visible, two creations of one id give
//    exactly one success (the other ALREADY_EXISTS), and a crashed writer's keys are private to
//    its generation and expire by themselves: they never block a later Create.
//  - AddRevision's script checks the generation (ABORTED if it is not the one the revision was
//    made from), reads `latest`, checks the base (ABORTED if expected_latest is set and
//    stale), assigns latest + 1, stores the revision, drops the oldest deformed revisions
//    beyond max_deform_revisions (the same rule as DeformRevisionsBeyond) and appends the event,
//    in one step: of two replicas deforming from the same base exactly one succeeds. `latest`
//    only grows, so numbers are never reused, even after retention.
//  - Delete's script removes grid:{id}, the index entry and the generation's keys (UNLINK:
//    freed in the background) and appends the deletion event; the event stream alone stays, for
//    deleted_events_ttl, so that watchers on other replicas see the deletion.
//
// Reading (redis_snapshots.h). Each process caches a decoded snapshot per grid. Get is one
// script round trip: it sends the cached generation and revision numbers and receives the
// grid's generation, its numbers and the values of only the revisions the process lacks; so it
// reflects every revision published through any replica, decodes a revision once per process,
// and the snapshot is consistent (read in one step). A cache miss on the source (first Get, or
// a new generation) reads the header and then the chunks, 16 per round trip. AddRevision's
// script returns the same as Get, so its snapshot needs no further round trip. Memory is
// charged to the MemoryBudget; when a reservation fails the least recently used grids'
// snapshots leave the cache (redis_grid_cache.h) and the load is retried once.
//
// Watching (redis_event_reader.h): one thread per process reads the watched grids' event
// streams with XREAD BLOCK (100 ms) on its own connection and feeds a SubscriptionHub. A watch
// takes the snapshot first and is fed the stream from after the snapshot's latest number L
// (`after` = L): the stream is persistent and addressed by revision number, so nothing between
// the snapshot and the first event is lost, and nothing is delivered twice. (Registering
// first, as the memory store does under its lock, is not needed: the stream can be replayed.)
//
// Availability. hiredis connections are not thread safe: calls take one from a pool (at most
// max_connections), each command with a timeout (connection.command_timeout, 2 s). A call
// that cannot reach Redis is UNAVAILABLE naming Redis and its address. A thread PINGs Redis
// every health_interval (500 ms) on its own connection and keeps Available() current (the
// server turns gRPC health NOT_SERVING on it); when Redis answers again the pool reconnects
// at once (otherwise with backoff up to 1 s), so the store recovers by itself. Watches wait
// through an outage and resume from their last number if Redis kept its data; if it did not,
// they end (kClosed: the service answers UNAVAILABLE) instead of silently missing events.
//
// Size limit: the source points of one grid may take at most kMaxRedisSourceBytes (1 GiB) and
// one stored revision at most kMaxRedisRevisionBytes (256 MiB); beyond them Create and
// AddRevision fail with RESOURCE_EXHAUSTED naming the size and the limit.
//
// Durability: an acknowledged revision survives a Redis crash or power loss only if Redis runs
// with `appendonly yes` and `appendfsync always` (every write is fsynced before Redis replies).
// With `appendfsync everysec` (Redis's default once AOF is on) a power loss or kernel crash loses
// up to about one second of acknowledged revisions (a Redis process crash alone loses
// nothing); with RDB snapshots only, everything since the last snapshot. Redis must also not
// evict keys (`maxmemory-policy noeviction`, the default; a full Redis then refuses writes:
// RESOURCE_EXHAUSTED). OpenRedisStore warns on stderr when Redis is configured otherwise.
//
// Single Redis endpoint only: no Sentinel, no Cluster (the scripts touch keys they compute,
// and a failover to an asynchronous replica may lose acknowledged writes); no AUTH or TLS.
#ifndef SPLINEGRID_SERVER_STORE_REDIS_STORE_H_
#define SPLINEGRID_SERVER_STORE_REDIS_STORE_H_

#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "server/grid_store.h"
#include "server/memory_budget.h"
#include "server/server_options.h"
#include "server/store/redis_connection.h"

namespace splinegrid::server {

// The most source points (bytes of coordinates and iblank) one grid may have in Redis: 1 GiB.
// Every replica that serves the grid holds them in memory and reads them whole on a cache miss
// (a second or more at loopback speed per GiB), and Redis keeps them in RAM; grids beyond this
// belong in a dir: store.
inline constexpr int64_t kMaxRedisSourceBytes = int64_t{1} << 30;
// The most bytes one stored revision may take: one hash value, below Redis's 512 MiB limit
// for a value with room to spare (control nets are a fraction of their source).
inline constexpr int64_t kMaxRedisRevisionBytes = int64_t{256} << 20;

struct RedisStoreOptions {
  // Deformed revisions kept per grid (ServerOptions::max_deform_revisions); at least 1.
  int max_deform_revisions = 0;
  // Prefix of every key (non-empty).
  std::string key_prefix = "splinegrid:";
  // Size limits (bytes), see above.
  int64_t max_source_bytes = kMaxRedisSourceBytes;
  int64_t max_revision_bytes = kMaxRedisRevisionBytes;
  // Timeouts of every connection.
  RedisConnectionOptions connection;
  // A file whose first line is the Redis password (ServerOptions::redis_password_file), read
  // at every new connection; empty: the spec's password, if any.
  std::string password_file;
  // Connections the calls share.
  int max_connections = 8;
  // How often Available() is brought up to date (PING).
  absl::Duration health_interval = absl::Milliseconds(500);
  // The longest a watch reader's XREAD blocks (new watches are taken in between).
  absl::Duration watch_block = absl::Milliseconds(100);
  // Lifetime of the keys of a creation not yet committed (refreshed while chunks are written).
  absl::Duration pending_ttl = absl::Minutes(10);
  // How long a deleted grid's event stream stays for the watchers of other replicas.
  absl::Duration deleted_events_ttl = absl::Minutes(5);
  // GetHolding answers from this process's snapshot of a grid when Redis confirmed it within
  // this window: a grid deleted (or a revision dropped) through another replica can still be
  // read here for at most this long. Zero: every call asks Redis.
  absl::Duration cached_read_window = absl::Seconds(1);
};

// Opens the store at `spec` (`redis://[USER[:PASSWORD]@]HOST:PORT[/DB]`): INVALID_ARGUMENT for
// a bad spec, a password given twice (in the spec and as a file), a user without a password or
// a database Redis does not have; UNAVAILABLE naming the address if Redis cannot be reached,
// refuses the credentials or wants some (and the password file's problem if it cannot be read).
absl::StatusOr<std::unique_ptr<GridStore>> OpenRedisStore(const std::string& spec,
                                                          const RedisStoreOptions& options,
                                                          MemoryBudget* budget);
// The same with the server's options (max_deform_revisions; the rest as defaulted above).
absl::StatusOr<std::unique_ptr<GridStore>> OpenRedisStore(const std::string& spec,
                                                          const ServerOptions& options,
                                                          MemoryBudget* budget);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_STORE_REDIS_STORE_H_
