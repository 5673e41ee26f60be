// Client-supplied strings (grid names, ids, tokens, ...) echoed into a log line or an error
// message: escaped so that they cannot forge a line or a terminal sequence, and cut so that a
// 1 MiB name gives a short message (gRPC refuses a status message beyond its metadata limit).
#ifndef SPLINEGRID_CORE_UTIL_QUOTE_H_
#define SPLINEGRID_CORE_UTIL_QUOTE_H_

#include <cstddef>
#include <string>

#include "absl/strings/string_view.h"

namespace splinegrid {

// The default cut, in output characters.
inline constexpr size_t kMaxQuotedChars = 200;

// `text` in single quotes for an error message or a log line: printable ASCII is kept, the
// quote, the backslash and every other byte are C-escaped (\n, \t, \', \\, \x1b, \xc3 ...).
// When the escaped text is longer than `max` characters it is cut there and the original
// length is noted:
//   'grids/wing'    'grids/a\nb'    'aaaa...aaa'... (1048576 bytes)
// Cost O(min(|text|, max)).
std::string QuoteClientString(absl::string_view text, size_t max = kMaxQuotedChars);

// `text` as one line for a log field, without quotes: control characters, non-ASCII bytes and
// the backslash C-escaped, cut after `max` characters with "... (N bytes)" appended.
std::string EscapeForLog(absl::string_view text, size_t max);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_UTIL_QUOTE_H_
