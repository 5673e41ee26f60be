// Talking to one Redis endpoint with hiredis (synchronous API): the
// `redis://[USER[:PASSWORD]@]HOST:PORT[/DB]` address, one connection with timeouts and AUTH,
// replies, a small pool of connections with reconnect backoff, and Lua scripts run by EVALSHA
// (EVAL when Redis does not know them yet).
//
// hiredis contexts are not thread safe: a RedisConnection is used by one thread at a time (the
// pool hands each out to one caller). A connection whose socket failed or timed out is broken
// for good (hiredis cannot resynchronise the protocol) and is dropped, never reused.
//
// Errors: a failed or timed-out connection is UNAVAILABLE naming Redis and the address; error
// replies map by their prefix (MapRedisError): LOADING, READONLY, BUSY, MISCONF, MASTERDOWN are
// UNAVAILABLE, OOM is RESOURCE_EXHAUSTED, NOAUTH/WRONGPASS FAILED_PRECONDITION, others INTERNAL;
// credentials that Redis refuses when a connection is opened are UNAVAILABLE (the store is
// unavailable to this process until they are mended: health turns NOT_SERVING).
#ifndef SPLINEGRID_SERVER_STORE_REDIS_CONNECTION_H_
#define SPLINEGRID_SERVER_STORE_REDIS_CONNECTION_H_

#include <condition_variable>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/time/time.h"

struct redisContext;
struct redisReply;

namespace splinegrid::server {

// This Abseil has its own string_view (not std's): the bridge for StrCat, SimpleAtoi etc.
inline absl::string_view Absl(std::string_view s) { return absl::string_view(s.data(), s.size()); }

// Where Redis is: `redis://[USER[:PASSWORD]@]HOST:PORT[/DB]`, and how to log in.
struct RedisAddress {
  std::string host;  // a name or an IPv4 address; IPv6 in brackets in the spec
  int port = 0;      // 1..65535
  int db = 0;        // SELECT index (Redis has 0..15 unless configured otherwise)
  // Credentials, sent with AUTH on every new connection: an ACL user (empty: Redis's default
  // user, as with `requirepass`) and its password, given in the spec or read from
  // `password_file` at every connect, so that a rotated secret reaches new connections without
  // a restart. At most one of password and password_file. Never printed.
  std::string user;
  std::string password;
  std::string password_file;

  bool has_credentials() const { return !password.empty() || !password_file.empty(); }
  // "host:port" or "host:port/db", for messages (no credentials).
  std::string ToString() const;
};

// Parses `redis://[USER[:PASSWORD]@]HOST:PORT[/DB]`: USER and PASSWORD percent-encoded where
// they hold '@', ':', '/' or '%' (as in any URL), PORT in 1..65535 (digits only), DB a
// non-negative number (whether Redis has that many databases is checked when connecting),
// nothing after. No TLS or query options. INVALID_ARGUMENT saying which part is wrong, quoting
// the spec without its password (RedactRedisSpec).
absl::StatusOr<RedisAddress> ParseRedisSpec(std::string_view spec);

// `spec` with the password of its SCHEME://USER:PASSWORD@ part, if any, replaced by "***" (and
// credentials without a colon, SCHEME://X@, by "***@": X may be a password typed without the
// colon): what messages and the server's banner show of a --store flag (anything else is
// returned unchanged).
std::string RedactRedisSpec(std::string_view spec);

// The password of `address`: the one given, or the first line of its password_file (at most
// 4 KiB, a trailing newline dropped; empty or unreadable is UNAVAILABLE naming the file and the
// reason, never the content).
absl::StatusOr<std::string> RedisPassword(const RedisAddress& address);

struct RedisConnectionOptions {
  absl::Duration connect_timeout = absl::Seconds(2);  // TCP connect (and name resolution)
  absl::Duration command_timeout = absl::Seconds(2);  // each command's send and reply
};

// A non-owning view of a reply (or of an element of an array reply).
class RedisValue {
 public:
  explicit RedisValue(const redisReply* reply) : reply_(reply) {}

  bool is_nil() const;
  bool is_array() const;
  bool is_string() const;  // a bulk string or a status ("OK")
  bool is_integer() const;
  std::string_view str() const;  // empty unless is_string()
  size_t size() const;           // array elements (0 unless is_array())
  RedisValue operator[](size_t i) const;
  // The integer of an integer reply or of a string holding one; nullopt otherwise.
  std::optional<int64_t> AsInt() const;

 private:
  const redisReply* reply_;
};

// An owned reply (never an error reply: those become statuses).
class RedisReply {
 public:
  RedisReply() = default;
  explicit RedisReply(redisReply* reply);
  RedisValue value() const { return RedisValue(reply_.get()); }

 private:
  struct Free {
    void operator()(redisReply* reply) const;
  };
  std::unique_ptr<redisReply, Free> reply_;
};

// The status of an error reply `error` (e.g. "OOM command not allowed ...") from `address`.
absl::Status MapRedisError(std::string_view error, const std::string& address);

// One connection (one hiredis context) with the options' timeouts, on the address's database.
class RedisConnection {
 public:
  // Connects, logs in (AUTH, when the address has credentials), SELECTs the database and PINGs.
  // UNAVAILABLE if Redis cannot be reached, refuses the credentials or wants some that were not
  // given (saying how to give them); INVALID_ARGUMENT if it refuses the database index.
  static absl::StatusOr<std::unique_ptr<RedisConnection>> Open(
      const RedisAddress& address, const RedisConnectionOptions& options);
  ~RedisConnection();
  RedisConnection(const RedisConnection&) = delete;
  RedisConnection& operator=(const RedisConnection&) = delete;

  // Sends one command (binary-safe arguments) and returns its reply.
  absl::StatusOr<RedisReply> Command(const std::vector<std::string_view>& args);
  // The same, leaving an error reply's text in `*error` (empty if none) instead of a status.
  absl::StatusOr<RedisReply> Send(const std::vector<std::string_view>& args, std::string* error);
  absl::StatusOr<RedisReply> Command(std::initializer_list<std::string_view> args) {
    return Command(std::vector<std::string_view>(args));
  }
  // Sends every command, then reads every reply (one round trip); the first error if any
  // (every reply is read either way, so the connection stays usable).
  absl::StatusOr<std::vector<RedisReply>> Pipeline(
      const std::vector<std::vector<std::string_view>>& commands);

  // The socket failed or timed out: the connection must be dropped.
  bool broken() const;
  // False if the idle connection has something to read: Redis closed it (restarted) or sent
  // what nobody asked for. One poll(2), no round trip.
  bool IdleAndOpen() const;
  const std::string& address() const { return address_; }

 private:
  RedisConnection(redisContext* context, std::string address)
      : context_(context), address_(std::move(address)) {}
  // Reads one reply; error replies stay replies (`*error` set) so a pipeline reads them all.
  absl::StatusOr<RedisReply> Read(std::string* error);
  absl::Status IoError(const char* what) const;

  redisContext* context_;
  const std::string address_;
};

// A Lua script run with EVALSHA, falling back to EVAL when Redis does not know it (after a
// restart or SCRIPT FLUSH). The SHA1 is learnt with SCRIPT LOAD on first use.
class RedisScript {
 public:
  explicit RedisScript(std::string body) : body_(std::move(body)) {}

  absl::StatusOr<RedisReply> Run(RedisConnection& connection,
                                 const std::vector<std::string_view>& keys,
                                 const std::vector<std::string_view>& args) const;

 private:
  const std::string body_;
  mutable std::mutex mu_;
  mutable std::string sha_;
};

// Up to `max_connections` connections, opened when needed. After a failed connect, further
// connects wait out a backoff (100 ms doubling to 1 s), failing fast with the last error
// meanwhile, until ResetBackoff (the health check reached Redis again).
class RedisPool {
 public:
  RedisPool(RedisAddress address, RedisConnectionOptions options, int max_connections);
  ~RedisPool();

  // A connection lent to one caller; back to the pool when the lease ends, unless broken.
  class Lease {
   public:
    Lease(Lease&& other) noexcept;
    Lease& operator=(Lease&&) = delete;
    ~Lease();
    RedisConnection* operator->() const { return connection_.get(); }
    RedisConnection& operator*() const { return *connection_; }

   private:
    friend class RedisPool;
    Lease(RedisPool* pool, std::unique_ptr<RedisConnection> connection)
        : pool_(pool), connection_(std::move(connection)) {}
    RedisPool* pool_;
    std::unique_ptr<RedisConnection> connection_;
  };

  // An idle connection or a new one; UNAVAILABLE if Redis cannot be reached (or every
  // connection stays busy for a command timeout).
  absl::StatusOr<Lease> Acquire();
  // One command on a pooled connection.
  absl::StatusOr<RedisReply> Command(const std::vector<std::string_view>& args);
  // One script on a pooled connection.
  absl::StatusOr<RedisReply> Run(const RedisScript& script,
                                 const std::vector<std::string_view>& keys,
                                 const std::vector<std::string_view>& args);

  void ResetBackoff();
  // Closes the idle connections (Redis went away: they are dead even if they do not know it).
  void DropIdle();
  const RedisAddress& address() const { return address_; }
  const RedisConnectionOptions& options() const { return options_; }

 private:
  void Release(std::unique_ptr<RedisConnection> connection);

  const RedisAddress address_;
  const RedisConnectionOptions options_;
  const int max_connections_;
  std::mutex mu_;
  std::condition_variable released_;
  std::vector<std::unique_ptr<RedisConnection>> idle_;
  int open_ = 0;  // idle and lent
  absl::Duration backoff_ = absl::ZeroDuration();
  absl::Time retry_after_ = absl::InfinitePast();
  absl::Status last_error_;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_STORE_REDIS_CONNECTION_H_
