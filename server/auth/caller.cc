#include "server/auth/caller.h"

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

}  // namespace splinegrid::server
