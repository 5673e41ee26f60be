#include "core/util/quote.h"

#include <algorithm>
#include <cstdio>

#include "absl/strings/str_cat.h"

namespace splinegrid {
namespace {

// Appends the escape of `c` to `out`.
void AppendEscaped(unsigned char c, bool escape_quote, std::string* out) {
  switch (c) {
    case '\n':
      out->append("\\n");
      return;
    case '\r':
      out->append("\\r");
      return;
    case '\t':
      out->append("\\t");
      return;
    case '\\':
      out->append("\\\\");
      return;
    case '\'':
      out->append(escape_quote ? "\\'" : "'");
      return;
    default:
      break;
  }
  if (c >= 0x20 && c < 0x7f) {
    out->push_back(static_cast<char>(c));
    return;
  }
  char hex[5];
  std::snprintf(hex, sizeof(hex), "\\x%02x", c);
  out->append(hex);
}

// Escapes `text` into at most `max` characters; whether all of it fit.
bool Escape(absl::string_view text, size_t max, bool escape_quote, std::string* out) {
  std::string piece;
  for (const char c : text) {
    piece.clear();
    AppendEscaped(static_cast<unsigned char>(c), escape_quote, &piece);
    if (out->size() + piece.size() > max) return false;
    out->append(piece);
  }
  return true;
}

}  // namespace

std::string QuoteClientString(absl::string_view text, size_t max) {
  std::string out = "'";
  out.reserve(std::min(text.size(), max) + 32);
  const bool whole = Escape(text, max + 1, /*escape_quote=*/true, &out);
  if (whole) return absl::StrCat(out, "'");
  return absl::StrCat(out, "...' (", text.size(), " bytes)");
}

std::string EscapeForLog(absl::string_view text, size_t max) {
  std::string out;
  out.reserve(std::min(text.size(), max) + 32);
  if (Escape(text, max, /*escape_quote=*/false, &out)) return out;
  return absl::StrCat(out, "... (", text.size(), " bytes)");
}

}  // namespace splinegrid
