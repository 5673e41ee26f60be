#include "server/auth/token_file.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "absl/container/flat_hash_set.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"

namespace splinegrid::server {
namespace {

constexpr size_t kMinTokenBytes = 8;
constexpr size_t kMaxTokenBytes = 512;
constexpr size_t kMaxPrincipalBytes = 128;

bool IsPrintableWord(absl::string_view word) {
  for (char c : word) {
    if (c <= 0x20 || c >= 0x7F) return false;
  }
  return true;
}

absl::StatusOr<Role> ParseRole(absl::string_view name) {
  if (name == "read") return Role::kRead;
  if (name == "write") return Role::kWrite;
  if (name == "admin") return Role::kAdmin;
  // Not quoted: in a line written in the wrong order this field is the token.
  return absl::InvalidArgumentError(
      "the third field (the role) is not read, write or admin (fields: TOKEN PRINCIPAL ROLE)");
}

// One non-comment line's three fields as an entry; errors never quote the token.
absl::StatusOr<TokenEntry> ParseLine(const std::vector<absl::string_view>& fields) {
  if (fields.size() != 3) {
    return absl::InvalidArgumentError(absl::StrCat(
        "expected 'TOKEN PRINCIPAL ROLE' (3 fields), found ", fields.size(), " fields"));
  }
  const absl::string_view token = fields[0];
  if (token.size() < kMinTokenBytes || token.size() > kMaxTokenBytes || !IsPrintableWord(token)) {
    return absl::InvalidArgumentError(
        absl::StrCat("the token must be ", kMinTokenBytes, "-", kMaxTokenBytes,
                     " printable ASCII characters (it has ", token.size(), ")"));
  }
  const absl::string_view principal = fields[1];
  if (principal.size() > kMaxPrincipalBytes || !IsPrintableWord(principal)) {
    return absl::InvalidArgumentError(absl::StrCat("the principal must be 1-", kMaxPrincipalBytes,
                                                   " printable ASCII characters"));
  }
  absl::StatusOr<Role> role = ParseRole(fields[2]);
  if (!role.ok()) return role.status();
  return TokenEntry{std::string(token), Caller{std::string(principal), *role}};
}

}  // namespace

absl::StatusOr<std::vector<TokenEntry>> ParseTokenFile(absl::string_view text,
                                                       absl::string_view source) {
  std::vector<TokenEntry> entries;
  absl::flat_hash_set<std::string> seen;
  int number = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++number;
    line = line.substr(0, line.find('#'));
    const std::vector<absl::string_view> fields =
        absl::StrSplit(line, absl::ByAnyChar(" \t\r\f\v"), absl::SkipEmpty());
    if (fields.empty()) continue;
    absl::StatusOr<TokenEntry> entry = ParseLine(fields);
    if (!entry.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat(source, ":", number, ": ", entry.status().message()));
    }
    if (!seen.insert(entry->token).second) {
      return absl::InvalidArgumentError(
          absl::StrCat(source, ":", number, ": the token is repeated from an earlier line"));
    }
    entries.push_back(*std::move(entry));
  }
  return entries;
}

absl::StatusOr<std::vector<TokenEntry>> ReadTokenFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int error = errno;
    const std::string message =
        absl::StrCat("cannot read the tokens file '", path, "': ", std::strerror(error));
    return error == EACCES ? absl::PermissionDeniedError(message) : absl::NotFoundError(message);
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad())
    return absl::DataLossError(absl::StrCat("error reading the tokens file '", path, "'"));
  return ParseTokenFile(text.str(), path);
}

}  // namespace splinegrid::server
