#include "core/io/fortran_text.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace splinegrid {
namespace {

// Longest token the slow path of ParseFortranReal copies; longer ones are not numbers.
constexpr size_t kMaxRealChars = 250;
// Largest repeat count n of "n*value".
constexpr int64_t kMaxRepeat = std::numeric_limits<int32_t>::max();

// True for '0'..'9'.
bool IsDigit(char c) { return c >= '0' && c <= '9'; }

// True when `token` is [sign] digits.
bool IsIntegerLiteral(std::string_view token) {
  size_t i = (!token.empty() && (token[0] == '+' || token[0] == '-')) ? 1 : 0;
  if (i == token.size()) return false;
  for (; i < token.size(); ++i) {
    if (!IsDigit(token[i])) return false;
  }
  return true;
}

// One token as the scanner sees it, before it is converted.
struct RawToken {
  std::string_view text;        // the token's bytes ("," for a null value)
  size_t offset = 0;            // byte offset of the token
  bool null_value = false;      // an empty value between two commas
  bool newline_before = false;  // a line break separates it from the previous token
};

// Splits a list into raw tokens; the single definition of token boundaries, shared by
// TokenizeFortranList and OffsetOfToken so that token indices agree.
class ListScanner {
 public:
  // A scanner over `text`, which must outlive it.
  explicit ListScanner(std::string_view text) : text_(text) {}

  // The next token into `*token`; false at the end of the text.
  bool Next(RawToken* token) {
    bool newline = false;
    const size_t size = text_.size();
    while (pos_ < size) {
      const char c = text_[pos_];
      if (c == ',') {
        if (commas_ > 0) {  // ",," (or a leading ","): a null value
          *token = RawToken{text_.substr(pos_, 1), pos_, true, newline};
          ++pos_;
          return true;
        }
        commas_ = 1;
      } else if (c == '\n') {
        newline = true;
      } else if (!IsListSeparator(c)) {
        break;
      }
      ++pos_;
    }
    if (pos_ >= size) return false;
    const size_t start = pos_;
    while (pos_ < size && !IsListSeparator(text_[pos_])) ++pos_;
    *token = RawToken{text_.substr(start, pos_ - start), start, false, newline};
    commas_ = 0;
    return true;
  }

 private:
  std::string_view text_;
  size_t pos_ = 0;
  int commas_ = 1;  // commas since the last token; 1 at the start so a leading ',' is null
};

// Slow path of ParseFortranReal: D exponents, exponents without a letter, a leading '+',
// and values outside the double range.
bool ParseFortranRealSlow(std::string_view s, double* value) {
  if (s.empty() || s.size() > kMaxRealChars) return false;
  char buffer[kMaxRealChars + 2];
  size_t n = 0;
  size_t i = 0;
  if (s[0] == '+') {
    i = 1;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) return false;
  }
  bool has_exponent = false;
  for (; i < s.size(); ++i) {
    char c = s[i];
    if (c == 'd' || c == 'D' || c == 'e' || c == 'E') {
      if (has_exponent) return false;
      c = 'e';
      has_exponent = true;
    } else if ((c == '+' || c == '-') && n > 0 && !has_exponent &&
               (IsDigit(buffer[n - 1]) || buffer[n - 1] == '.')) {
      buffer[n++] = 'e';  // Fortran's "1.5-100" for 1.5e-100
      has_exponent = true;
    }
    buffer[n++] = c;
  }
  buffer[n] = '\0';
  const auto [end, error] = std::from_chars(buffer, buffer + n, *value);
  if (end != buffer + n) return false;
  if (error == std::errc()) return true;
  if (error != std::errc::result_out_of_range) return false;
  // Overflow gives +-HUGE_VAL (infinite: rejected by callers); underflow gives 0 or a denormal.
  *value = std::strtod(buffer, nullptr);
  return true;
}

// Appends the value of `raw` (a non-null token) to `list`, or records why it is bad.
void AddToken(const RawToken& raw, int64_t index, FortranList* list, bool* bad) {
  const std::string_view text = raw.text;
  double value = 0.0;
  int64_t count = 1;
  std::string problem;
  const size_t star = text.find('*');
  if (star == std::string_view::npos) {
    if (!ParseFortranReal(text, &value)) {
      problem = absl::StrCat(QuoteToken(text), " is not a number");
    } else if (!std::isfinite(value)) {
      problem = absl::StrCat(QuoteToken(text), " is not a finite number");
    }
  } else {
    const std::string_view count_text = text.substr(0, star);
    const std::string_view value_text = text.substr(star + 1);
    count = 0;
    for (char c : count_text) {
      if (!IsDigit(c) || count > kMaxRepeat) {
        count = 0;
        break;
      }
      count = count * 10 + (c - '0');
    }
    if (count < 1 || count > kMaxRepeat) {
      problem = absl::StrCat(QuoteToken(text),
                             " has a bad repeat count: in n*value, n must be a whole number from 1 "
                             "to ",
                             kMaxRepeat);
    } else if (value_text.empty()) {
      problem = absl::StrCat(QuoteToken(text), " repeats a null value (not supported)");
    } else if (!ParseFortranReal(value_text, &value)) {
      problem = absl::StrCat(QuoteToken(text), ": the repeated value is not a number");
    } else if (!std::isfinite(value)) {
      problem = absl::StrCat(QuoteToken(text), ": the repeated value is not a finite number");
    }
  }
  if (!problem.empty()) {
    if (!list->first_bad.has_value()) {
      list->first_bad = BadToken{index, raw.offset, std::move(problem)};
    }
    *bad = true;
    value = std::numeric_limits<double>::quiet_NaN();
    count = 1;
  }
  list->token_values.push_back(value);
  if (count > 1) list->repeats.push_back(RepeatRun{index, count});
  list->num_values += count;
}

}  // namespace

bool ParseFortranReal(std::string_view token, double* value) {
  const char* begin = token.data();
  const char* end = begin + token.size();
  const auto [stop, error] = std::from_chars(begin, end, *value);
  if (error == std::errc() && stop == end) return true;
  return ParseFortranRealSlow(token, value);
}

TextPosition PositionOfOffset(std::string_view text, size_t offset) {
  TextPosition position;
  const size_t stop = std::min(offset, text.size());
  size_t line_start = 0;
  for (size_t i = 0; i < stop; ++i) {
    if (text[i] == '\n') {
      ++position.line;
      line_start = i + 1;
    }
  }
  position.column = static_cast<int64_t>(offset - line_start) + 1;
  return position;
}

std::string DescribeOffset(std::string_view text, size_t offset) {
  const TextPosition position = PositionOfOffset(text, offset);
  return absl::StrCat("line ", position.line, ", column ", position.column);
}

std::string QuoteToken(std::string_view token) {
  constexpr size_t kMaxShown = 40;
  std::string quoted = "'";
  for (size_t i = 0; i < token.size() && i < kMaxShown; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7f) {
      quoted.push_back(static_cast<char>(c));
    } else {
      absl::StrAppendFormat(&quoted, "\\x%02x", c);
    }
  }
  if (token.size() > kMaxShown) quoted += "...";
  quoted += "'";
  return quoted;
}

FortranList TokenizeFortranList(std::string_view text, int64_t max_leading_integers) {
  FortranList list;
  list.token_values.reserve(text.size() / 24 + 16);
  ListScanner scanner(text);
  RawToken raw;
  bool leading = true;         // every token so far is an integer literal
  bool last_has_slot = false;  // the previous token has an entry in line_break_after
  int64_t index = 0;
  while (scanner.Next(&raw)) {
    if (last_has_slot) list.line_break_after.back() = raw.newline_before;
    if (index > 0 && raw.newline_before) list.has_line_breaks = true;
    last_has_slot = false;
    bool bad = false;
    if (raw.null_value) {
      if (!list.first_bad.has_value()) {
        list.first_bad = BadToken{index, raw.offset,
                                  "empty value between commas (Fortran null values are not "
                                  "supported)"};
      }
      list.token_values.push_back(std::numeric_limits<double>::quiet_NaN());
      ++list.num_values;
      bad = true;
    } else {
      AddToken(raw, index, &list, &bad);
    }
    if (leading) {
      if (!bad && IsIntegerLiteral(raw.text)) {
        ++list.num_leading_integers;
        if (list.num_leading_integers <= max_leading_integers) {
          list.line_break_after.push_back(false);
          last_has_slot = true;
        }
      } else {
        leading = false;
      }
    }
    ++index;
  }
  if (last_has_slot) list.line_break_after.back() = true;  // the end of the text
  return list;
}

size_t OffsetOfToken(std::string_view text, int64_t token_index) {
  ListScanner scanner(text);
  RawToken raw;
  for (int64_t index = 0; scanner.Next(&raw); ++index) {
    if (index == token_index) return raw.offset;
  }
  return text.size();
}

int64_t TokenOfValue(const FortranList& list, int64_t value_index) {
  int64_t extra = 0;  // values beyond one per token, from repeats before the token
  for (const RepeatRun& run : list.repeats) {
    if (run.token_index + extra > value_index) break;
    if (value_index < run.token_index + extra + run.count) return run.token_index;
    extra += run.count - 1;
  }
  return value_index - extra;
}

int64_t ValueOfToken(const FortranList& list, int64_t token_index) {
  int64_t value = token_index;
  for (const RepeatRun& run : list.repeats) {
    if (run.token_index >= token_index) break;
    value += run.count - 1;
  }
  return value;
}

FortranValueCursor::FortranValueCursor(const FortranList& list, int64_t first_value) : list_(list) {
  const int64_t token = TokenOfValue(list, first_value);
  next_token_ = token;
  while (next_repeat_ < list.repeats.size() && list.repeats[next_repeat_].token_index < token) {
    ++next_repeat_;
  }
  Advance();
  left_in_run_ -= first_value - ValueOfToken(list, token);
}

void FortranValueCursor::Advance() {
  current_ = list_.token_values[static_cast<size_t>(next_token_)];
  left_in_run_ = 1;
  if (next_repeat_ < list_.repeats.size() &&
      list_.repeats[next_repeat_].token_index == next_token_) {
    left_in_run_ = list_.repeats[next_repeat_].count;
    ++next_repeat_;
  }
  ++next_token_;
}

}  // namespace splinegrid
