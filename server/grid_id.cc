#include "server/grid_id.h"

#include "absl/strings/str_cat.h"
#include "core/util/quote.h"

namespace splinegrid::server {

bool IsValidGridId(const std::string& id) {
  if (id.empty() || id.size() > 63 || !(id[0] >= 'a' && id[0] <= 'z')) return false;
  for (char c : id) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-')) return false;
  }
  return true;
}

absl::Status CheckRequestedGridId(const std::string& id, const std::string& field) {
  if (id.empty() || IsValidGridId(id)) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat(field, " = ", QuoteClientString(id),
                   " is not valid: 1-63 characters of [a-z0-9-], starting with a letter"));
}

}  // namespace splinegrid::server
