#include "server/call_log.h"

#include <cstdio>

#include "absl/status/status.h"
#include "absl/strings/str_format.h"

namespace splinegrid::server {

void CallLog::Finish(const absl::Status& status) const {
  if (!enabled_) return;
  const double ms = absl::ToDoubleMilliseconds(absl::Now() - start_);
  const std::string line = absl::StrFormat(
      "%s %s %s %s %.1f ms%s%s\n",
      absl::FormatTime("%Y-%m-%dT%H:%M:%E3SZ", absl::Now(), absl::UTCTimeZone()), method_,
      grid_.empty() ? "-" : grid_, absl::StatusCodeToString(status.code()), ms,
      status.ok() ? "" : ": ", status.ok() ? "" : std::string(status.message()));
  std::fputs(line.c_str(), stderr);
}

}  // namespace splinegrid::server
