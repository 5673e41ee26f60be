// Helpers of the archive converters (archive_*.cc): errors that name the field path.
#ifndef SPLINEGRID_PROTO_CONVERT_ARCHIVE_UTIL_H_
#define SPLINEGRID_PROTO_CONVERT_ARCHIVE_UTIL_H_

#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace splinegrid::archive_internal {

// INVALID_ARGUMENT "<field><rest...>".
template <typename... Args>
absl::Status Invalid(const std::string& field, const Args&... rest) {
  return absl::InvalidArgumentError(absl::StrCat(field, rest...));
}

// A kernel validator's error under the field path it came from.
inline absl::Status Annotate(const absl::Status& status, const std::string& field) {
  return absl::InvalidArgumentError(absl::StrCat(field, ": ", status.message()));
}

inline absl::Status CheckNonNegative(int64_t value, const std::string& field) {
  if (value < 0) return Invalid(field, " = ", value, " is negative");
  return absl::OkStatus();
}

}  // namespace splinegrid::archive_internal

#endif  // SPLINEGRID_PROTO_CONVERT_ARCHIVE_UTIL_H_
