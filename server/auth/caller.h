// Who is calling and what they may do. Without tokens every caller is an admin named by its
// peer address (one principal per connection); with `serve --tokens` the token names both.
#ifndef SPLINEGRID_SERVER_AUTH_CALLER_H_
#define SPLINEGRID_SERVER_AUTH_CALLER_H_

#include <string>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace splinegrid::server {

// Ordered: each role may do everything the roles before it may.
//   read:  GetGrid, ListGrids, EvaluateGrid, EvaluatePoints, GetWallCurvature, WatchGrid,
//          ExportGrid (and health, which is open to everyone).
//   write: also ImportGrid, ImportArchive and GenerateGrid (new grids, owned by the caller),
//          and FitGrid, FairGrid, DeformGrid and DeleteGrid of grids the same principal created.
//   admin: everything, including changing and deleting any grid.
enum class Role { kRead = 0, kWrite = 1, kAdmin = 2 };

// "read", "write" or "admin".
const char* RoleName(Role role);

struct Caller {
  // The token's principal, or the peer ("ipv4:127.0.0.1:40312") when the server has no tokens.
  std::string principal;
  Role role = Role::kAdmin;
  // Whether a token named the caller (else the principal is only the peer address).
  bool from_token = false;

  // What a grid this caller creates records as its owner: the principal with tokens, else "".
  std::string owner() const { return from_token ? principal : std::string(); }
};

// Whether `caller` may change (fit, fair, deform) or delete the grid `name` created by `owner`
// (StoredGrid::owner): an admin any grid, a writer only its own (a grid created without tokens
// has no owner: admin only). PERMISSION_DENIED naming the owner and `action` ("deleting",
// "deforming", ...) otherwise.
absl::Status MayChangeGrid(const Caller& caller, const std::string& owner, const std::string& name,
                           absl::string_view action);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_AUTH_CALLER_H_
