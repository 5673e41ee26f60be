// Whole-file reads and atomic whole-file writes for the readers and writers in core/io.
#ifndef SPLINEGRID_CORE_IO_FILE_UTIL_H_
#define SPLINEGRID_CORE_IO_FILE_UTIL_H_

#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace splinegrid {

// The bytes of the file at `path`. NOT_FOUND when it does not exist, INVALID_ARGUMENT when it
// is a directory, PERMISSION_DENIED / INTERNAL for other failures; every message names `path`.
absl::StatusOr<std::string> ReadFileToString(const std::string& path);

// Writes `contents` to `path` atomically: the bytes go to a new temporary file in the same
// directory, which is flushed to disk and then renamed over `path`, so readers see either the
// old file or the complete new one. The temporary file is removed on failure. Errors name `path`.
absl::Status WriteFileAtomically(const std::string& path, std::string_view contents);

// An absl::Status for the C `errno` value `error_number`, with `message` and strerror text.
absl::Status ErrnoToStatusWithMessage(int error_number, const std::string& message);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_IO_FILE_UTIL_H_
