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

absl::Status MayChangeGrid(const Caller& caller, const std::string& owner, const std::string& name,
                           absl::string_view action) {
  if (caller.role >= Role::kAdmin) return absl::OkStatus();
  if (caller.role == Role::kWrite && !owner.empty() && caller.owner() == owner) {
    return absl::OkStatus();
  }
  if (caller.role < Role::kWrite) {
    return absl::PermissionDeniedError(absl::StrCat(
        action, " ", name, " needs the role write (own grids) or admin; the caller has ",
        RoleName(caller.role)));
  }
  if (owner.empty()) {
    return absl::PermissionDeniedError(absl::StrCat(name,
                                                    " was created without a token and has no "
                                                    "owner: ",
                                                    action, " it needs the role admin"));
  }
  return absl::PermissionDeniedError(
      absl::StrCat(name, " belongs to '", owner, "': ", action,
                   " it needs the role admin; the role write changes and deletes only the "
                   "caller's own grids ('",
                   caller.principal, "')"));
}

}  // namespace splinegrid::server
