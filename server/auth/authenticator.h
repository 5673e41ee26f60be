// Turns a call's credentials into a Caller.
//
// Without tokens every caller is an admin named by its peer address (or, behind a trusted
// proxy, by the client connection the proxy names: trusted_proxies.h). With a tokens file
// (token_file.h) a call must carry the metadata `authorization: Bearer TOKEN`; the token's line
// gives the principal and the role. The table can be reloaded while calls run (SIGHUP): readers
// take a snapshot (shared_ptr) under a mutex, a reload swaps it; a bad file keeps the old table.
// Tokens are compared in constant time and never appear in errors.
#ifndef SPLINEGRID_SERVER_AUTH_AUTHENTICATOR_H_
#define SPLINEGRID_SERVER_AUTH_AUTHENTICATOR_H_

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/synchronization/mutex.h"
#include "grpcpp/grpcpp.h"
#include "server/auth/caller.h"
#include "server/auth/token_file.h"
#include "server/auth/trusted_proxies.h"

namespace splinegrid::server {

// The metadata key of the bearer token (gRPC keys are lower case).
inline constexpr char kAuthorizationHeader[] = "authorization";

// Whether `a` and `b` are equal, in a time that depends on their lengths only, not on where
// they first differ.
bool ConstantTimeEquals(absl::string_view a, absl::string_view b);

class Authenticator {
 public:
  Authenticator() = default;

  // Reads the tokens file at `path` (ReadTokenFile) and from now on requires tokens; the path
  // is kept for Reload. INVALID_ARGUMENT for a file without tokens. On error nothing changes.
  // Returns the number of tokens.
  absl::StatusOr<int> LoadTokens(const std::string& path);

  // Reads the file of LoadTokens again and swaps the table in; on error keeps the old one.
  // FAILED_PRECONDITION without a previous LoadTokens.
  absl::StatusOr<int> Reload();

  // The number of tokens in the table; 0: no tokens, calls need none.
  int num_tokens() const;

  // Counts the tables loaded: a call that authenticated under an older one checks its token
  // again (a reload may have removed it or lowered its role).
  int64_t generation() const { return generation_.load(); }

  // Proxies whose `x-client-address` names the caller when there are no tokens
  // (trusted_proxies.h). Set before serving; none by default.
  void SetTrustedProxies(TrustedProxies proxies) { trusted_proxies_ = std::move(proxies); }

  // The connection `context` came from: its peer, or the client a trusted proxy names
  // (ipv4:192.0.2.7:51234). The caller's principal without tokens; what the log names for a
  // call that failed to authenticate.
  std::string Connection(const grpc::CallbackServerContext& context) const;

  // The caller of `context`, or UNAUTHENTICATED. Without tokens, its Connection.
  absl::StatusOr<Caller> Authenticate(const grpc::CallbackServerContext& context) const;

  // The caller with the `authorization` metadata value `authorization` (nullopt: none sent)
  // from `peer`: without tokens {peer, admin}; else the token's entry, or UNAUTHENTICATED.
  absl::StatusOr<Caller> Authenticate(std::optional<absl::string_view> authorization,
                                      const std::string& peer) const;

 private:
  using Table = std::vector<TokenEntry>;

  std::shared_ptr<const Table> table() const;

  mutable absl::Mutex mu_;
  std::shared_ptr<const Table> table_ ABSL_GUARDED_BY(mu_);  // null: no tokens
  std::string path_ ABSL_GUARDED_BY(mu_);
  std::atomic<int64_t> generation_{0};
  TrustedProxies trusted_proxies_;  // immutable while serving
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_AUTH_AUTHENTICATOR_H_
