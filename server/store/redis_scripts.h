// The Redis store's keys and the Lua scripts that change them atomically (the layout and the
// argument for atomicity are in redis_store.h). Every script is one EVALSHA: Redis runs it to
// the end before any other command, so what it reads and what it writes form one step for
// every replica. Scripts compute the generation's key names from the grid's record, which is
// fine on one Redis server and is one reason Redis Cluster is not supported.
#ifndef SPLINEGRID_SERVER_STORE_REDIS_SCRIPTS_H_
#define SPLINEGRID_SERVER_STORE_REDIS_SCRIPTS_H_

#include <string>

#include "server/store/redis_connection.h"

namespace splinegrid::server {

// Key names under a prefix (e.g. "splinegrid:"), for grid ids of [a-z0-9-] and generations of
// hex digits, so ':' separates the parts unambiguously.
class RedisKeys {
 public:
  explicit RedisKeys(std::string prefix) : prefix_(std::move(prefix)) {}

  // Sorted set (every score 0, so ordered by id) of the ids of the visible grids.
  std::string Index() const { return prefix_ + "grids"; }
  // Hash of a visible grid: gen (its generation), latest (its highest revision number).
  std::string Grid(const std::string& id) const { return prefix_ + "grid:" + id; }
  // What the scripts put a generation and ":part" after.
  std::string Stem(const std::string& id) const { return Grid(id) + ":"; }
  // The keys of one generation (one creation) of a grid:
  //   header   string: the ArchiveHeader
  //   source   list: the SourceChunk records, in ForEachSourceChunk order
  //   revs     hash: revision number -> StoredRevision
  //   nums     sorted set: the numbers in revs (score = number)
  //   deforms  sorted set: the deformed ones among them (retention)
  //   events   stream: entry 0-N per published revision N, then 1-0 for the deletion
  std::string Gen(const std::string& id, const std::string& gen, const char* part) const {
    return Stem(id) + gen + ":" + part;
  }

 private:
  std::string prefix_;
};

// Commits a creation whose keys were written (with a TTL) under a new generation.
// KEYS: grid, index, then the generation's header, source, revs, nums, deforms.
// ARGV: id, gen, latest, the number of source chunks, the number of revisions, the owner
// (kept in the grid's record, for DeleteScript's check).
// Returns 1 (created), 0 (the id is taken: the generation's keys are removed) or -1 (the
// written keys are incomplete, e.g. they expired: removed too).
const RedisScript& CreateScript();

// Publishes a revision: checks the generation and the base, assigns latest + 1, stores it,
// applies retention and appends the event.
// KEYS: grid. ARGV: the grid's Stem, expected_latest (0: any), the StoredRevision without its
// number, "1" if deformed, max_deform_revisions, the event's summary, the stream's max length,
// the expected generation ("": any), then as for GetScript the caller's cached generation and
// numbers.
// Returns {0} (no such grid), {-2} (another generation: the grid was deleted and created again),
// {-1, latest} (stale base) or {1, number, gen, {numbers}, {values}}: the grid right after the
// change, as GetScript would return it (the new revision's value "" too: the caller has it).
const RedisScript& AddRevisionScript();

// A grid's state for a reader that has some of it cached.
// KEYS: grid. ARGV: the grid's Stem, the cached generation ("" if none), the cached numbers.
// Returns nil (no such grid) or {gen, {numbers}, {values}}: values[i] is the StoredRevision
// of numbers[i], or "" when the caller has it (same generation and number cached).
const RedisScript& GetScript();

// Deletes a grid: its record, index entry and generation keys; appends the deletion event and
// lets the event stream expire after a while (watchers on other replicas read it meanwhile).
// KEYS: grid, index. ARGV: the grid's Stem, id, seconds the event stream is kept, "1" to delete
// only if the owner is ARGV[5] (compare and delete), the owner.
// Returns 1 (deleted), 0 (no such grid) or -1 (the owner is another one: nothing deleted).
const RedisScript& DeleteScript();

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_STORE_REDIS_SCRIPTS_H_
