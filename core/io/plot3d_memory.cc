#include "core/io/plot3d_memory.h"

#include <algorithm>

namespace splinegrid {
namespace {

// As ParsePlot3d's text test (plot3d.cc): printable ASCII and whitespace.
bool IsTextByte(unsigned char c) { return (c >= 0x20 && c < 0x7f) || (c >= '\t' && c <= '\r'); }

bool IsSeparator(char c) { return c == ',' || c == ' ' || (c >= '\t' && c <= '\r'); }

// The repeat count of a token "digits*...", or 1. Counts above 2^31 - 1 are capped there, as
// the tokenizer rejects them (it then stores one value).
int64_t RepeatCount(std::string_view token) {
  const size_t star = token.find('*');
  if (star == std::string_view::npos || star == 0) return 1;
  int64_t count = 0;
  for (size_t i = 0; i < star; ++i) {
    if (token[i] < '0' || token[i] > '9') return 1;
    count = std::min<int64_t>(count * 10 + (token[i] - '0'), int64_t{1} << 31);
  }
  return std::max<int64_t>(count, 1);
}

}  // namespace

int64_t Plot3dParseBytesBound(std::string_view bytes) {
  const int64_t size = static_cast<int64_t>(bytes.size());
  bool text = true;
  for (size_t i = 0; i < std::min<size_t>(4, bytes.size()); ++i) {
    text = text && IsTextByte(static_cast<unsigned char>(bytes[i]));
  }
  if (!text) return 2 * size + 4096;  // 4-byte floats become doubles
  int64_t tokens = 0, repeats = 0, values = 0;
  bool after_comma = true;  // a comma here would be a null value (start, or ",  ,")
  size_t i = 0;
  while (i < bytes.size()) {
    if (IsSeparator(bytes[i])) {
      if (bytes[i] == ',') {
        tokens += after_comma;
        after_comma = true;
      }
      ++i;
      continue;
    }
    after_comma = false;
    size_t end = i;
    while (end < bytes.size() && !IsSeparator(bytes[end])) ++end;
    const int64_t count = RepeatCount(bytes.substr(i, end - i));
    ++tokens;
    repeats += count > 1;
    values += count;
    i = end;
  }
  // The tokenizer reserves size/24 + 16 token values and doubles from there (fortran_text.cc).
  const int64_t reserved = size / 24 + 16;
  const int64_t token_capacity = tokens <= reserved ? reserved : 2 * tokens;
  return 8 * token_capacity + 32 * repeats + 8 * values + 4096;
}

}  // namespace splinegrid
