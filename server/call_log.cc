#include "server/call_log.h"

#include <cstdio>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/util/quote.h"
#include "server/call_metrics.h"

namespace splinegrid::server {
namespace {

// Longest status message in a log line, in characters.
constexpr size_t kMaxLoggedMessage = 1000;

// A field of a text line: as it is when it is one plain word, else quoted and escaped.
std::string TextField(const std::string& value) {
  if (value.empty()) return "-";
  bool plain = value.size() <= kMaxQuotedChars;
  for (const char c : value) {
    plain = plain && c > ' ' && c < 0x7f && c != '\'' && c != '\\';
  }
  return plain ? value : QuoteClientString(value);
}

// `text` (already escaped to printable ASCII) as a JSON string.
std::string JsonString(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') out.push_back('\\');
    out.push_back(c);
  }
  return out + "\"";
}

}  // namespace

std::string CallLog::Line(const absl::Status& status, absl::Time now) const {
  const double ms = absl::ToDoubleMilliseconds(now - start_);
  const std::string time = absl::FormatTime("%Y-%m-%dT%H:%M:%E3SZ", now, absl::UTCTimeZone());
  const std::string code = absl::StatusCodeToString(status.code());
  const std::string message = EscapeForLog(status.message(), kMaxLoggedMessage);
  if (format_ == LogFormat::kJson) {
    return absl::StrFormat(
        "{\"time\":\"%s\",\"method\":%s,\"grid\":%s,\"principal\":%s,\"status\":\"%s\","
        "\"ms\":%.3f,\"message\":%s}\n",
        time, JsonString(EscapeForLog(method_, kMaxQuotedChars)),
        JsonString(EscapeForLog(grid_, kMaxQuotedChars)),
        JsonString(EscapeForLog(principal_, kMaxQuotedChars)), code, ms, JsonString(message));
  }
  const std::string by = principal_.empty() ? "" : " by " + TextField(principal_);
  return absl::StrFormat("%s %s %s %s %.1f ms%s%s%s\n", time, TextField(method_), TextField(grid_),
                         code, ms, by, status.ok() ? "" : ": ", message);
}

void CallLog::Finish(const absl::Status& status) const {
  const absl::Time now = absl::Now();
  // The metrics count the calls the log lines show, whether or not lines are written.
  CallMetrics::Global().Record(method_, status.code(), now - start_);
  if (!enabled_) return;
  const std::string line = Line(status, now);
  std::fwrite(line.data(), 1, line.size(), stderr);
}

}  // namespace splinegrid::server
