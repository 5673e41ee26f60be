// Numbers as Fortran list-directed output writes them: the token layer of the text readers.
//
// A list is a sequence of values separated by whitespace and/or single commas. A value is
//   - a real: [sign] digits [. digits] [exponent], exponent = (E|e|D|d) [sign] digits, or, as
//     Fortran writes three-digit exponents, a sign directly after the mantissa ("1.5-100");
//   - a repeat "n*real" standing for n copies of the real, n a whole number in [1, 2^31 - 1].
// Null values (",," or "n*" with no value) and the "/" terminator are not supported; they are
// reported as bad tokens. Tokenizing is one pass over the text with std::from_chars
// (~10 ns per number), and no position bookkeeping: positions are recovered on demand.
#ifndef SPLINEGRID_CORE_IO_FORTRAN_TEXT_H_
#define SPLINEGRID_CORE_IO_FORTRAN_TEXT_H_

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace splinegrid {

// Parses all of `token` as a Fortran real (see the file comment) into `*value`; false when it is
// not one. "nan", "inf" and overflowing exponents parse to NaN / +-inf: callers check finiteness.
bool ParseFortranReal(std::string_view token, double* value);

// True for the bytes that separate list values: space, \t, \n, \v, \f, \r and ','.
inline bool IsListSeparator(char c) { return c == ' ' || c == ',' || (c >= '\t' && c <= '\r'); }

// A 1-based line and column in a text.
struct TextPosition {
  int64_t line = 1;    // 1-based line number
  int64_t column = 1;  // 1-based byte column within the line
};

// The line and column of byte `offset` of `text` (O(offset); meant for error messages).
TextPosition PositionOfOffset(std::string_view text, size_t offset);

// "line L, column C" for byte `offset` of `text`.
std::string DescribeOffset(std::string_view text, size_t offset);

// `token` quoted for an error message, shortened to ~40 bytes, non-printable bytes as \xNN.
std::string QuoteToken(std::string_view token);

// The first token of a list that is not a valid value.
struct BadToken {
  int64_t token_index = 0;  // 0-based index among all tokens
  size_t offset = 0;        // byte offset of the token in the text
  std::string problem;      // what is wrong, e.g. "'abc' is not a number"
};

// A run of equal values written as "n*value" with n > 1.
struct RepeatRun {
  int64_t token_index = 0;  // the token holding the repeat
  int64_t count = 0;        // n
};

// The values of a Fortran list, tokenized once.
struct FortranList {
  // One value per token; NaN for a bad token (which also counts as one value).
  std::vector<double> token_values;
  // The tokens that stand for several values, in increasing token order.
  std::vector<RepeatRun> repeats;
  // Number of values once repeats are expanded.
  int64_t num_values = 0;
  // Tokens [0, num_leading_integers) are plain integer literals ([sign] digits, no repeat).
  int64_t num_leading_integers = 0;
  // For each of those leading integer tokens (at most max_leading_integers of them): whether
  // a line break (or the end of the text) follows it before the next token.
  std::vector<bool> line_break_after;
  // Whether a line break separates some two tokens (false for a text on a single line).
  bool has_line_breaks = false;
  // The first bad token, if any (tokenizing goes on past it, so counts stay meaningful).
  std::optional<BadToken> first_bad;
};

// Splits `text` into a FortranList. Never fails: bad tokens are recorded, not fatal.
// `max_leading_integers` caps the line_break_after bookkeeping. O(text size).
FortranList TokenizeFortranList(std::string_view text, int64_t max_leading_integers);

// Byte offset of token `token_index` of `text` (the text's size when there is no such token).
// O(offset): re-scans the text; meant for error messages.
size_t OffsetOfToken(std::string_view text, int64_t token_index);

// Index of the token holding expanded value `value_index` of `list`.
int64_t TokenOfValue(const FortranList& list, int64_t value_index);

// Index of the first expanded value that token `token_index` of `list` stands for.
int64_t ValueOfToken(const FortranList& list, int64_t token_index);

// Reads the expanded values of a FortranList in order.
class FortranValueCursor {
 public:
  // A cursor at expanded value `first_value` of `list` (which must outlive the cursor).
  FortranValueCursor(const FortranList& list, int64_t first_value);
  // The next value. Precondition: fewer than list.num_values values have been read.
  double Next() {
    if (left_in_run_ == 0) Advance();
    --left_in_run_;
    return current_;
  }

 private:
  // Moves to the next token and loads its value and repeat count.
  void Advance();

  const FortranList& list_;
  int64_t next_token_ = 0;   // token to load on the next Advance()
  size_t next_repeat_ = 0;   // first entry of list_.repeats at or after next_token_
  int64_t left_in_run_ = 0;  // values of the current token not yet returned
  double current_ = 0.0;     // value of the current token
};

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_IO_FORTRAN_TEXT_H_
