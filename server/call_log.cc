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

// The length of the UTF-8 sequence that starts text[at], or 0 if none valid starts there
// (RFC 3629: no overlong forms, no surrogates, nothing above U+10FFFF).
size_t Utf8SequenceLength(absl::string_view text, size_t at) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[at + k]); };
  const unsigned char lead = byte(0);
  if (lead < 0x80) return 1;
  size_t n = 0;
  unsigned char lo = 0x80, hi = 0xbf;  // the range of the second byte
  if (lead >= 0xc2 && lead <= 0xdf) {
    n = 2;
  } else if (lead >= 0xe0 && lead <= 0xef) {
    n = 3;
    if (lead == 0xe0) lo = 0xa0;
    if (lead == 0xed) hi = 0x9f;
  } else if (lead >= 0xf0 && lead <= 0xf4) {
    n = 4;
    if (lead == 0xf0) lo = 0x90;
    if (lead == 0xf4) hi = 0x8f;
  } else {
    return 0;
  }
  if (at + n > text.size() || byte(1) < lo || byte(1) > hi) return 0;
  for (size_t k = 2; k < n; ++k) {
    if (byte(k) < 0x80 || byte(k) > 0xbf) return 0;
  }
  return n;
}

// `text` as a JSON string (RFC 8259) whose value is the text itself, so that a log consumer
// reads what the client was sent: the quote, the backslash and control characters escaped
// (no line can be forged), valid UTF-8 kept and every byte of invalid UTF-8 replaced by U+FFFD
// (a JSON string is UTF-8). Cut after `max` bytes, at a character, with "... (N bytes)" appended.
std::string JsonString(absl::string_view text, size_t max) {
  std::string out = "\"";
  size_t at = 0;
  for (; at < text.size() && at < max;) {
    const unsigned char c = static_cast<unsigned char>(text[at]);
    const size_t n = Utf8SequenceLength(text, at);
    if (n == 0) {
      out += "\\ufffd";
      ++at;
    } else if (c == '"' || c == '\\') {
      out.push_back('\\');
      out.push_back(static_cast<char>(c));
      ++at;
    } else if (c < 0x20 || c == 0x7f) {
      absl::StrAppendFormat(&out, "\\u%04x", c);
      ++at;
    } else {
      out.append(text.data() + at, n);
      at += n;
    }
  }
  if (at < text.size()) absl::StrAppend(&out, "... (", text.size(), " bytes)");
  return out + "\"";
}

}  // namespace

std::string CallLog::Line(const absl::Status& status, absl::Time now) const {
  const double ms = absl::ToDoubleMilliseconds(now - start_);
  const std::string time = absl::FormatTime("%Y-%m-%dT%H:%M:%E3SZ", now, absl::UTCTimeZone());
  const std::string code = absl::StatusCodeToString(status.code());
  if (format_ == LogFormat::kJson) {
    return absl::StrFormat(
        "{\"time\":\"%s\",\"method\":%s,\"grid\":%s,\"principal\":%s,\"status\":\"%s\","
        "\"ms\":%.3f,\"message\":%s}\n",
        time, JsonString(method_, kMaxQuotedChars), JsonString(grid_, kMaxQuotedChars),
        JsonString(principal_, kMaxQuotedChars), code, ms,
        JsonString(status.message(), kMaxLoggedMessage));
  }
  const std::string message = EscapeForLog(status.message(), kMaxLoggedMessage);
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
