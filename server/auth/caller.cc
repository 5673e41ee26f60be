#include "server/auth/caller.h"

#include "absl/strings/str_cat.h"

namespace splinegrid::server {

const char* RoleName(Role role) {
  switch (role) {
    case Role::kRead:
      return "read";
    case Role::kWrite:
      return "write";
    case Role::kAdmin:
      return "admin";
  }
  return "unknown";
}

absl::Status MayDeleteGrid(const Caller& caller, const std::string& owner,
                           const std::string& name) {
  if (caller.role >= Role::kAdmin) return absl::OkStatus();
  if (caller.role == Role::kWrite && !owner.empty() && caller.owner() == owner) {
    return absl::OkStatus();
  }
  if (caller.role < Role::kWrite) {
    return absl::PermissionDeniedError(absl::StrCat(
        "deleting ", name, " needs the role write (own grids) or admin; the caller has ",
        RoleName(caller.role)));
  }
  if (owner.empty()) {
    return absl::PermissionDeniedError(absl::StrCat(
        name, " was created without a token and has no owner: only an admin may delete it"));
  }
  return absl::PermissionDeniedError(absl::StrCat(
      name, " belongs to '", owner, "': the role write deletes only the caller's own grids ('",
      caller.principal, "'); an admin may delete any"));
}

}  // namespace splinegrid::server
