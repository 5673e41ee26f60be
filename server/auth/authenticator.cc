#include "server/auth/authenticator.h"

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace splinegrid::server {
namespace {

constexpr absl::string_view kBearer = "bearer ";

absl::StatusOr<int> CheckTable(const std::vector<TokenEntry>& table, const std::string& path) {
  if (table.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("the tokens file '", path,
                     "' has no tokens (lines TOKEN PRINCIPAL ROLE): every call "
                     "would be refused"));
  }
  return static_cast<int>(table.size());
}

}  // namespace

bool ConstantTimeEquals(absl::string_view a, absl::string_view b) {
  // Every byte of `b` is visited whatever `a` holds; a's bytes past its end read as 0 and the
  // length difference is folded into the result.
  volatile unsigned char diff = a.size() == b.size() ? 0 : 1;
  for (size_t i = 0; i < b.size(); ++i) {
    const unsigned char x = i < a.size() ? static_cast<unsigned char>(a[i]) : 0;
    diff = diff | (x ^ static_cast<unsigned char>(b[i]));
  }
  return diff == 0;
}

absl::StatusOr<int> Authenticator::LoadTokens(const std::string& path) {
  absl::StatusOr<Table> table = ReadTokenFile(path);
  if (!table.ok()) return table.status();
  absl::StatusOr<int> count = CheckTable(*table, path);
  if (!count.ok()) return count.status();
  absl::MutexLock lock(&mu_);
  table_ = std::make_shared<const Table>(*std::move(table));
  path_ = path;
  ++generation_;
  return count;
}

absl::StatusOr<int> Authenticator::Reload() {
  std::string path;
  {
    absl::MutexLock lock(&mu_);
    path = path_;
  }
  if (path.empty()) {
    return absl::FailedPreconditionError("the server has no tokens file to reload");
  }
  return LoadTokens(path);
}

int Authenticator::num_tokens() const {
  const std::shared_ptr<const Table> table = this->table();
  return table == nullptr ? 0 : static_cast<int>(table->size());
}

std::shared_ptr<const Authenticator::Table> Authenticator::table() const {
  absl::MutexLock lock(&mu_);
  return table_;
}

absl::StatusOr<Caller> Authenticator::Authenticate(
    const grpc::CallbackServerContext& context) const {
  std::optional<absl::string_view> authorization;
  const auto& metadata = context.client_metadata();
  if (const auto it = metadata.find(kAuthorizationHeader); it != metadata.end()) {
    authorization = absl::string_view(it->second.data(), it->second.size());
  }
  return Authenticate(authorization, Connection(context));
}

std::string Authenticator::Connection(const grpc::CallbackServerContext& context) const {
  std::optional<absl::string_view> client;
  const auto& metadata = context.client_metadata();
  if (const auto it = metadata.find(kClientAddressHeader); it != metadata.end()) {
    client = absl::string_view(it->second.data(), it->second.size());
  }
  return trusted_proxies_.CallerName(context.peer(), client);
}

absl::StatusOr<Caller> Authenticator::Authenticate(std::optional<absl::string_view> authorization,
                                                   const std::string& peer) const {
  const std::shared_ptr<const Table> table = this->table();
  if (table == nullptr) return Caller{peer, Role::kAdmin};
  if (!authorization.has_value()) {
    return absl::UnauthenticatedError(
        "this server needs a token: send the metadata 'authorization: Bearer TOKEN' (splinegrid "
        "--token or SPLINEGRID_TOKEN)");
  }
  absl::string_view value = absl::StripAsciiWhitespace(*authorization);
  if (!absl::StartsWithIgnoreCase(value, kBearer)) {
    return absl::UnauthenticatedError("the authorization metadata is not 'Bearer TOKEN'");
  }
  const absl::string_view token = absl::StripLeadingAsciiWhitespace(value.substr(kBearer.size()));
  // Compare with every entry, without stopping at a match: the time does not tell which one.
  const TokenEntry* found = nullptr;
  for (const TokenEntry& entry : *table) {
    if (ConstantTimeEquals(token, entry.token)) found = &entry;
  }
  if (found == nullptr) return absl::UnauthenticatedError("the token is not known to this server");
  Caller caller = found->caller;
  caller.from_token = true;
  return caller;
}

}  // namespace splinegrid::server
