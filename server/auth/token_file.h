// The tokens file of `serve --tokens FILE`: who may call, and with which role.
//
// One token per line, three fields separated by blanks:
//
//   TOKEN PRINCIPAL ROLE      e.g.   3f9c0b7e1d2a48c6  alice  write
//
// ROLE is `read`, `write` or `admin` (server/auth/caller.h). `#` starts a comment (to the end of
// the line); blank lines are skipped. Tokens are 8-512 printable ASCII characters without blanks
// and must be unique; principals are 1-128 such characters. Errors name the file and the line
// (1-based) but never repeat a token.
#ifndef SPLINEGRID_SERVER_AUTH_TOKEN_FILE_H_
#define SPLINEGRID_SERVER_AUTH_TOKEN_FILE_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "server/auth/caller.h"

namespace splinegrid::server {

// One line of a tokens file.
struct TokenEntry {
  std::string token;
  Caller caller;  // principal and role
};

// Parses the text of a tokens file; `source` names it in errors. INVALID_ARGUMENT "SOURCE:LINE:
// what is wrong" for a malformed line, an unknown role or a repeated token. An empty table
// (only comments) is valid here; the server refuses it (it would lock everyone out).
absl::StatusOr<std::vector<TokenEntry>> ParseTokenFile(absl::string_view text,
                                                       absl::string_view source);

// Reads and parses the tokens file at `path` (NOT_FOUND / PERMISSION_DENIED naming the path when
// it cannot be read).
absl::StatusOr<std::vector<TokenEntry>> ReadTokenFile(const std::string& path);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_AUTH_TOKEN_FILE_H_
