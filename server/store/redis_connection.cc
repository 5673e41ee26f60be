#include "server/store/redis_connection.h"

#include <hiredis/hiredis.h>
#include <poll.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <optional>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid::server {
namespace {

constexpr std::string_view kScheme = "redis://";

constexpr size_t kMaxPasswordFileBytes = 4096;

absl::Status BadSpec(std::string_view spec, std::string_view why) {
  return absl::InvalidArgumentError(
      absl::StrCat("--store = '", RedactRedisSpec(spec).substr(0, 200), "': ", Absl(why),
                   "; a Redis store is redis://[USER[:PASSWORD]@]HOST:PORT[/DB]"));
}

int HexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// `text` with its %XX escapes decoded; nullopt for a '%' not followed by two hex digits.
std::optional<std::string> PercentDecode(std::string_view text) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '%') {
      out.push_back(text[i]);
      continue;
    }
    const int high = i + 2 < text.size() ? HexDigit(text[i + 1]) : -1;
    const int low = i + 2 < text.size() ? HexDigit(text[i + 2]) : -1;
    if (high < 0 || low < 0) return std::nullopt;
    out.push_back(static_cast<char>(high * 16 + low));
    i += 2;
  }
  return out;
}

// The user of `address` for messages: quoted, or "the default user".
std::string UserName(const RedisAddress& address) {
  return address.user.empty() ? std::string("the default user")
                              : absl::StrCat("user '", address.user.substr(0, 64), "'");
}

// The refusal of an error reply that asks for credentials (NOAUTH) the address does not have.
absl::Status NeedsCredentials(const std::string& name, std::string_view error) {
  return absl::UnavailableError(
      absl::StrCat("Redis at ", name, " requires a password (", Absl(error.substr(0, 200)),
                   "): give it in a file with --redis_password_file, or in the URL as "
                   "redis://[USER]:PASSWORD@HOST:PORT (which process listings show)"));
}

// A decimal number of at most 10 digits (no sign, no spaces), or -1.
int64_t ParseDigits(std::string_view text) {
  if (text.empty() || text.size() > 10) return -1;
  if (!std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return -1;
  }
  int64_t value = 0;
  return absl::SimpleAtoi(Absl(text), &value) ? value : -1;
}

}  // namespace

std::string RedisAddress::ToString() const {
  const bool v6 = host.find(':') != std::string::npos;
  return absl::StrCat(v6 ? "[" : "", host, v6 ? "]" : "", ":", port,
                      db != 0 ? absl::StrCat("/", db) : "");
}

std::string RedactRedisSpec(std::string_view spec) {
  // Any SCHEME://, so that a mistyped scheme does not show the password either.
  const size_t scheme = spec.find("://");
  if (scheme == std::string_view::npos) return std::string(spec);
  const size_t at = spec.rfind('@');
  if (at == std::string_view::npos || at < scheme) return std::string(spec);
  // USER:***@, or ***@ for credentials without a colon (a user, or a password typed without the
  // colon before it: not shown either way).
  const size_t colon = spec.find(':', scheme + 3);
  const size_t keep = colon != std::string_view::npos && colon < at ? colon + 1 : scheme + 3;
  return absl::StrCat(Absl(spec.substr(0, keep)), "***", Absl(spec.substr(at)));
}

absl::StatusOr<std::string> RedisPassword(const RedisAddress& address) {
  if (address.password_file.empty()) return address.password;
  const std::string file = absl::StrCat("--redis_password_file '", address.password_file, "'");
  std::FILE* f = std::fopen(address.password_file.c_str(), "rb");
  if (f == nullptr) {
    return absl::UnavailableError(absl::StrCat("cannot read ", file, ": ", std::strerror(errno)));
  }
  std::string content(kMaxPasswordFileBytes + 1, '\0');
  content.resize(std::fread(content.data(), 1, content.size(), f));
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) return absl::UnavailableError(absl::StrCat("cannot read ", file));
  if (content.size() > kMaxPasswordFileBytes) {
    return absl::UnavailableError(
        absl::StrCat(file, " is larger than ", kMaxPasswordFileBytes, " bytes: not a password"));
  }
  content = content.substr(0, content.find('\n'));  // the first line
  if (!content.empty() && content.back() == '\r') content.pop_back();
  if (content.empty()) return absl::UnavailableError(absl::StrCat(file, " holds no password"));
  return content;
}

absl::StatusOr<RedisAddress> ParseRedisSpec(std::string_view spec) {
  if (!spec.starts_with(kScheme)) return BadSpec(spec, "it does not start with redis://");
  std::string_view rest = spec.substr(kScheme.size());
  RedisAddress address;
  // Credentials: everything before the last '@' (a host, port or database has none).
  if (const size_t at = rest.rfind('@'); at != std::string_view::npos) {
    const std::string_view userinfo = rest.substr(0, at);
    rest.remove_prefix(at + 1);
    const size_t colon = userinfo.find(':');
    const std::optional<std::string> user = PercentDecode(userinfo.substr(0, colon));
    const std::optional<std::string> password =
        colon == std::string_view::npos ? std::string() : PercentDecode(userinfo.substr(colon + 1));
    if (!user || !password) {
      return BadSpec(spec, "a '%' in USER:PASSWORD@ is not followed by two hex digits");
    }
    if (colon != std::string_view::npos && password->empty()) {
      return BadSpec(spec, "the password after USER: is empty");
    }
    if (user->empty() && password->empty()) return BadSpec(spec, "the credentials are empty");
    address.user = *user;
    address.password = *password;
  }
  if (rest.find_first_of("?#") != std::string_view::npos) {
    return BadSpec(spec, "options (?...) are not supported");
  }
  if (rest.starts_with('[')) {  // [IPv6]:PORT
    const size_t close = rest.find(']');
    if (close == std::string_view::npos) return BadSpec(spec, "the IPv6 host has no closing ]");
    address.host = std::string(rest.substr(1, close - 1));
    rest.remove_prefix(close + 1);
    if (!rest.starts_with(':')) return BadSpec(spec, "there is no :PORT after the host");
  } else {
    const size_t colon = rest.find(':');
    if (colon == std::string_view::npos) return BadSpec(spec, "there is no :PORT after the host");
    address.host = std::string(rest.substr(0, colon));
    rest.remove_prefix(colon);
  }
  if (address.host.empty()) return BadSpec(spec, "the host is empty");
  rest.remove_prefix(1);  // ':'
  const size_t slash = rest.find('/');
  const std::string_view port = rest.substr(0, slash);
  const int64_t port_number = ParseDigits(port);
  if (port_number < 1 || port_number > 65535) {
    return BadSpec(spec, absl::StrCat("the port '", Absl(port.substr(0, 20)),
                                      "' is not a number in 1..65535"));
  }
  address.port = static_cast<int>(port_number);
  if (slash != std::string_view::npos) {
    const std::string_view db = rest.substr(slash + 1);
    const int64_t db_number = ParseDigits(db);
    if (db_number < 0 || db_number > 0x7fffffff) {
      return BadSpec(spec, absl::StrCat("the database '", Absl(db.substr(0, 20)),
                                        "' is not a number (0..15 unless Redis has more)"));
    }
    address.db = static_cast<int>(db_number);
  }
  return address;
}

// ---- Replies ----

bool RedisValue::is_nil() const { return reply_ == nullptr || reply_->type == REDIS_REPLY_NIL; }
bool RedisValue::is_array() const { return reply_ && reply_->type == REDIS_REPLY_ARRAY; }
bool RedisValue::is_string() const {
  return reply_ && (reply_->type == REDIS_REPLY_STRING || reply_->type == REDIS_REPLY_STATUS);
}
bool RedisValue::is_integer() const { return reply_ && reply_->type == REDIS_REPLY_INTEGER; }

std::string_view RedisValue::str() const {
  return is_string() ? std::string_view(reply_->str, reply_->len) : std::string_view();
}

size_t RedisValue::size() const { return is_array() ? reply_->elements : 0; }

RedisValue RedisValue::operator[](size_t i) const {
  return RedisValue(i < size() ? reply_->element[i] : nullptr);
}

std::optional<int64_t> RedisValue::AsInt() const {
  if (is_integer()) return reply_->integer;
  int64_t value = 0;
  if (is_string() && absl::SimpleAtoi(Absl(str()), &value)) return value;
  return std::nullopt;
}

RedisReply::RedisReply(redisReply* reply) : reply_(reply) {}

void RedisReply::Free::operator()(redisReply* reply) const { freeReplyObject(reply); }

absl::Status MapRedisError(std::string_view error, const std::string& address) {
  const std::string message = absl::StrCat("Redis at ", address, ": ", Absl(error.substr(0, 300)));
  for (std::string_view transient :
       {"LOADING", "READONLY", "BUSY", "MISCONF", "MASTERDOWN", "TRYAGAIN", "CLUSTERDOWN"}) {
    if (error.starts_with(transient)) return absl::UnavailableError(message);
  }
  if (error.starts_with("OOM")) return absl::ResourceExhaustedError(message);
  if (error.starts_with("NOAUTH") || error.starts_with("WRONGPASS")) {
    return absl::FailedPreconditionError(absl::StrCat(
        message, " (give the password with --redis_password_file or in the --store URL)"));
  }
  return absl::InternalError(message);
}

// ---- One connection ----

absl::StatusOr<std::unique_ptr<RedisConnection>> RedisConnection::Open(
    const RedisAddress& address, const RedisConnectionOptions& options) {
  const std::string name = address.ToString();
  redisContext* context = redisConnectWithTimeout(address.host.c_str(), address.port,
                                                  absl::ToTimeval(options.connect_timeout));
  if (context == nullptr) {
    return absl::UnavailableError(absl::StrCat("Redis at ", name, ": cannot allocate a context"));
  }
  if (context->err != 0) {
    const std::string why = context->errstr;
    redisFree(context);
    return absl::UnavailableError(absl::StrCat("Redis at ", name, " is unreachable: ", why));
  }
  std::unique_ptr<RedisConnection> connection(new RedisConnection(context, name));
  if (redisSetTimeout(context, absl::ToTimeval(options.command_timeout)) != REDIS_OK) {
    return connection->IoError("setting the timeout");
  }
  std::string error;
  if (address.has_credentials()) {
    SG_ASSIGN_OR_RETURN(const std::string password, RedisPassword(address));
    std::vector<std::string_view> auth = {"AUTH"};
    if (!address.user.empty()) auth.push_back(address.user);
    auth.push_back(password);
    SG_RETURN_IF_ERROR(connection->Send(auth, &error).status());
    if (!error.empty()) {
      return absl::UnavailableError(absl::StrCat("Redis at ", name, " refuses the password of ",
                                                 UserName(address), ": ",
                                                 Absl(std::string_view(error).substr(0, 200))));
    }
  }
  if (address.db != 0) {
    const std::string db = absl::StrCat(address.db);
    SG_RETURN_IF_ERROR(connection->Send({"SELECT", db}, &error).status());
    if (error.starts_with("NOAUTH")) return NeedsCredentials(name, error);
    if (!error.empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat("Redis at ", name, " refuses database ", address.db, ": ", error));
    }
  }
  SG_RETURN_IF_ERROR(connection->Send({"PING"}, &error).status());
  if (error.starts_with("NOAUTH")) return NeedsCredentials(name, error);
  if (!error.empty()) return MapRedisError(error, name);
  return connection;
}

RedisConnection::~RedisConnection() { redisFree(context_); }

bool RedisConnection::broken() const { return context_->err != 0; }

bool RedisConnection::IdleAndOpen() const {
  if (broken()) return false;
  pollfd fd{context_->fd, POLLIN | POLLRDHUP, 0};
  return poll(&fd, 1, 0) == 0;
}

absl::Status RedisConnection::IoError(const char* what) const {
  std::string why = context_->errstr;
  if (absl::StrContains(why, "temporarily unavailable") || absl::StrContains(why, "timed out")) {
    why = "no reply within the command timeout";
  }
  return absl::UnavailableError(
      absl::StrCat("Redis at ", address_, " is unreachable (", what, "): ", why));
}

absl::StatusOr<RedisReply> RedisConnection::Read(std::string* error) {
  if (broken()) return IoError("a previous command failed");
  void* raw = nullptr;
  if (redisGetReply(context_, &raw) != REDIS_OK || raw == nullptr) return IoError("reading");
  RedisReply reply(static_cast<redisReply*>(raw));
  const auto* r = static_cast<const redisReply*>(raw);
  if (r->type == REDIS_REPLY_ERROR) {
    error->assign(r->str, r->len);
    return RedisReply();
  }
  return reply;
}

absl::StatusOr<RedisReply> RedisConnection::Send(const std::vector<std::string_view>& args,
                                                 std::string* error) {
  error->clear();
  if (broken()) return IoError("a previous command failed");
  std::vector<const char*> argv;
  std::vector<size_t> lengths;
  argv.reserve(args.size());
  lengths.reserve(args.size());
  for (std::string_view arg : args) {
    argv.push_back(arg.data());
    lengths.push_back(arg.size());
  }
  if (redisAppendCommandArgv(context_, static_cast<int>(args.size()), argv.data(),
                             lengths.data()) != REDIS_OK) {
    return IoError("sending");
  }
  return Read(error);
}

absl::StatusOr<RedisReply> RedisConnection::Command(const std::vector<std::string_view>& args) {
  std::string error;
  SG_ASSIGN_OR_RETURN(RedisReply reply, Send(args, &error));
  if (!error.empty()) return MapRedisError(error, address_);
  return reply;
}

absl::StatusOr<std::vector<RedisReply>> RedisConnection::Pipeline(
    const std::vector<std::vector<std::string_view>>& commands) {
  if (broken()) return IoError("a previous command failed");
  for (const std::vector<std::string_view>& args : commands) {
    std::vector<const char*> argv;
    std::vector<size_t> lengths;
    for (std::string_view arg : args) {
      argv.push_back(arg.data());
      lengths.push_back(arg.size());
    }
    if (redisAppendCommandArgv(context_, static_cast<int>(args.size()), argv.data(),
                               lengths.data()) != REDIS_OK) {
      return IoError("sending");
    }
  }
  std::vector<RedisReply> replies;
  replies.reserve(commands.size());
  std::string first_error;
  for (size_t i = 0; i < commands.size(); ++i) {
    std::string error;
    SG_ASSIGN_OR_RETURN(RedisReply reply, Read(&error));
    if (!error.empty() && first_error.empty()) first_error = error;
    replies.push_back(std::move(reply));
  }
  if (!first_error.empty()) return MapRedisError(first_error, address_);
  return replies;
}

// ---- Scripts ----

absl::StatusOr<RedisReply> RedisScript::Run(RedisConnection& connection,
                                            const std::vector<std::string_view>& keys,
                                            const std::vector<std::string_view>& args) const {
  std::string sha;
  {
    std::lock_guard<std::mutex> lock(mu_);
    sha = sha_;
  }
  if (sha.empty()) {
    SG_ASSIGN_OR_RETURN(RedisReply loaded, connection.Command({"SCRIPT", "LOAD", body_}));
    sha = std::string(loaded.value().str());
    std::lock_guard<std::mutex> lock(mu_);
    sha_ = sha;
  }
  const std::string num_keys = absl::StrCat(keys.size());
  std::vector<std::string_view> argv = {"EVALSHA", sha, num_keys};
  argv.insert(argv.end(), keys.begin(), keys.end());
  argv.insert(argv.end(), args.begin(), args.end());
  std::string error;
  SG_ASSIGN_OR_RETURN(RedisReply reply, connection.Send(argv, &error));
  if (error.starts_with("NOSCRIPT")) {  // Redis restarted or flushed its scripts
    argv[0] = "EVAL";
    argv[1] = body_;
    SG_ASSIGN_OR_RETURN(reply, connection.Send(argv, &error));
  }
  if (!error.empty()) return MapRedisError(error, connection.address());
  return reply;
}

// ---- The pool ----

RedisPool::RedisPool(RedisAddress address, RedisConnectionOptions options, int max_connections)
    : address_(std::move(address)), options_(options), max_connections_(max_connections) {}

RedisPool::~RedisPool() = default;

RedisPool::Lease::Lease(Lease&& other) noexcept
    : pool_(other.pool_), connection_(std::move(other.connection_)) {}

RedisPool::Lease::~Lease() {
  if (connection_) pool_->Release(std::move(connection_));
}

absl::StatusOr<RedisPool::Lease> RedisPool::Acquire() {
  std::unique_lock<std::mutex> lock(mu_);
  const auto deadline =
      std::chrono::steady_clock::now() + absl::ToChronoMilliseconds(options_.command_timeout);
  while (idle_.empty() && open_ >= max_connections_) {
    if (released_.wait_until(lock, deadline) == std::cv_status::timeout && idle_.empty() &&
        open_ >= max_connections_) {
      return absl::UnavailableError(
          absl::StrCat("all ", max_connections_, " connections to Redis at ", address_.ToString(),
                       " stayed busy for ", absl::FormatDuration(options_.command_timeout)));
    }
  }
  while (!idle_.empty()) {
    std::unique_ptr<RedisConnection> connection = std::move(idle_.back());
    idle_.pop_back();
    if (connection->IdleAndOpen()) return Lease(this, std::move(connection));
    --open_;  // closed by Redis (e.g. it restarted): drop it, try the next one or connect
  }
  if (absl::Now() < retry_after_) return last_error_;  // fail fast while backing off
  ++open_;
  lock.unlock();
  absl::StatusOr<std::unique_ptr<RedisConnection>> connection =
      RedisConnection::Open(address_, options_);
  lock.lock();
  if (!connection.ok()) {
    --open_;
    backoff_ = std::clamp(2 * backoff_, absl::Milliseconds(100), absl::Seconds(1));
    retry_after_ = absl::Now() + backoff_;
    last_error_ = connection.status();
    released_.notify_one();
    return connection.status();
  }
  backoff_ = absl::ZeroDuration();
  retry_after_ = absl::InfinitePast();
  return Lease(this, *std::move(connection));
}

void RedisPool::Release(std::unique_ptr<RedisConnection> connection) {
  std::vector<std::unique_ptr<RedisConnection>> dropped;
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (connection->broken()) {
      // Redis probably went away: the idle connections are as dead as this one.
      dropped = std::move(idle_);
      idle_.clear();
      open_ -= static_cast<int>(dropped.size()) + 1;
      dropped.push_back(std::move(connection));
    } else {
      idle_.push_back(std::move(connection));
    }
  }
  released_.notify_all();
}

void RedisPool::DropIdle() {
  std::vector<std::unique_ptr<RedisConnection>> dropped;
  {
    std::lock_guard<std::mutex> lock(mu_);
    dropped = std::move(idle_);
    idle_.clear();
    open_ -= static_cast<int>(dropped.size());
  }
  released_.notify_all();
}

void RedisPool::ResetBackoff() {
  std::lock_guard<std::mutex> lock(mu_);
  backoff_ = absl::ZeroDuration();
  retry_after_ = absl::InfinitePast();
}

absl::StatusOr<RedisReply> RedisPool::Command(const std::vector<std::string_view>& args) {
  SG_ASSIGN_OR_RETURN(Lease lease, Acquire());
  return lease->Command(args);
}

absl::StatusOr<RedisReply> RedisPool::Run(const RedisScript& script,
                                          const std::vector<std::string_view>& keys,
                                          const std::vector<std::string_view>& args) {
  SG_ASSIGN_OR_RETURN(Lease lease, Acquire());
  return script.Run(*lease, keys, args);
}

}  // namespace splinegrid::server
