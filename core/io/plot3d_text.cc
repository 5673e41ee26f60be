// Plot3D formatted (text) files: layout detection by hypothesis testing, reading and writing.
#include <charconv>
#include <cmath>
#include <optional>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "core/io/fortran_text.h"
#include "core/io/plot3d_internal.h"

namespace splinegrid::plot3d_internal {
namespace {

// One candidate layout of a text file.
struct Hypothesis {
  bool has_block_count;  // the file starts with nblocks
  int spatial_dim;       // 2 or 3
  bool has_iblank;       // every block ends with iblank values
};

// All candidates, in order of preference (see plot3d.h). Those with a block-count line come
// first: ParsePlot3dText keeps the best of each group and gives ties to this group.
constexpr Hypothesis kHypotheses[] = {
    {true, 3, false},  {true, 3, true},  {true, 2, false},  {true, 2, true},
    {false, 3, false}, {false, 3, true}, {false, 2, false}, {false, 2, true},
};
static_assert([] {
  bool counted = true;
  for (const Hypothesis& h : kHypotheses) {
    if (h.has_block_count && !counted) return false;
    counted = h.has_block_count;
  }
  return true;
}());

// How far a hypothesis got; later stages are better candidates for the error message.
enum class Stage { kHeader = 0, kSize = 1, kContent = 2, kMatch = 3 };

// Why a hypothesis failed.
enum class Failure {
  kNone,
  kNotInteger,     // a header token is missing or not an integer literal
  kOutOfRange,     // a header value is outside its range
  kNoLineBreak,    // more values follow the header on its last line
  kTooManyPoints,  // a block exceeds kMaxBlockPoints
  kCountMismatch,  // the number of values differs from what the header implies
  kBadIblank,      // an iblank value is not an integer
};

// The outcome of testing one hypothesis against a tokenized file.
struct Attempt {
  Hypothesis hypothesis = {};
  Stage stage = Stage::kHeader;
  Failure failure = Failure::kNone;
  int64_t progress = 0;          // header tokens accepted
  int64_t at = 0;                // token (header failures) or value (kBadIblank) at fault
  int64_t block = -1;            // block at fault, -1 for the block count
  int direction = 0;             // extent at fault (kNotInteger, kOutOfRange)
  std::vector<Extents> extents;  // extents of the blocks whose header was accepted
  int64_t header_values = 0;     // values before the first coordinate
  int64_t expected_values = 0;   // header + coordinates + iblank implied by the header
  Plot3dLayout layout = Plot3dLayout::kWhole;

  // Values per point in a block's data.
  int values_per_point() const { return hypothesis.spatial_dim + (hypothesis.has_iblank ? 1 : 0); }
};

// Tests `hypothesis` against `list`, with 3D blocks in `layout`.
Attempt Evaluate(const FortranList& list, const Hypothesis& hypothesis, Plot3dLayout layout) {
  Attempt a;
  a.hypothesis = hypothesis;
  a.layout = hypothesis.spatial_dim == 3 ? layout : Plot3dLayout::kWhole;
  const int dim = hypothesis.spatial_dim;
  const int64_t integers = static_cast<int64_t>(list.line_break_after.size());
  auto fail = [&](Failure failure, int64_t at) {
    a.failure = failure;
    a.at = at;
    return a;
  };
  int64_t t = 0;
  int64_t num_blocks = 1;
  if (hypothesis.has_block_count) {
    if (integers < 1) return fail(Failure::kNotInteger, 0);
    const double value = list.token_values[0];
    if (value < 1 || value > kMaxBlocks) return fail(Failure::kOutOfRange, 0);
    num_blocks = static_cast<int64_t>(value);
    t = a.progress = 1;
  }
  for (a.block = 0; a.block < num_blocks; ++a.block) {
    Extents extents = {1, 1, 1};
    for (a.direction = 0; a.direction < dim; ++a.direction, ++t) {
      if (t >= integers) return fail(Failure::kNotInteger, t);
      const double value = list.token_values[t];
      if (value < 1 || value > kMaxExtent) return fail(Failure::kOutOfRange, t);
      extents[a.direction] = static_cast<int>(value);
      a.progress = t + 1;
    }
    a.extents.push_back(extents);
  }
  a.header_values = t;
  if (list.has_line_breaks && !list.line_break_after[t - 1]) {
    return fail(Failure::kNoLineBreak, t - 1);
  }
  a.stage = Stage::kSize;
  a.expected_values = a.header_values;
  for (a.block = 0; a.block < num_blocks; ++a.block) {
    const int64_t points = CheckedNumPoints(a.extents[a.block]);
    if (points < 0) return fail(Failure::kTooManyPoints, 0);
    a.expected_values += points * a.values_per_point();
  }
  if (a.expected_values != list.num_values) return fail(Failure::kCountMismatch, 0);
  a.stage = Stage::kContent;
  if (hypothesis.has_iblank) {
    int64_t first = a.header_values;  // first value of the slab
    for (a.block = 0; a.block < num_blocks; ++a.block) {
      const int64_t points = NumPoints(a.extents[a.block]);
      const int64_t n = SlabPoints(a.extents[a.block], a.layout);
      for (int64_t slab = 0; slab < points; slab += n) {
        first += n * dim;
        FortranValueCursor cursor(list, first);
        for (int64_t p = 0; p < n; ++p) {
          const double value = cursor.Next();
          if (!(std::abs(value) <= 2147483647.0) || value != std::floor(value)) {
            return fail(Failure::kBadIblank, first + p);
          }
        }
        first += n;
      }
    }
  }
  a.block = -1;
  a.stage = Stage::kMatch;
  return a;
}

// "2*113*33", "(3+1)*2*257*97" or "3*(65*17*1 + 73*65*1)": the count formula of `a`.
std::string CountFormula(const Attempt& a) {
  const int dim = a.hypothesis.spatial_dim;
  const std::string factor =
      a.hypothesis.has_iblank ? absl::StrCat("(", dim, "+1)") : absl::StrCat(dim);
  auto product = [dim](const Extents& e) {
    return dim == 2 ? absl::StrCat(e[0], "*", e[1]) : absl::StrCat(e[0], "*", e[1], "*", e[2]);
  };
  if (a.extents.size() == 1) return absl::StrCat(factor, "*", product(a.extents[0]));
  if (a.extents.size() <= 4) {
    std::vector<std::string> terms;
    for (const Extents& e : a.extents) terms.push_back(product(e));
    return absl::StrCat(factor, "*(", absl::StrJoin(terms, " + "), ")");
  }
  int64_t points = 0;
  for (const Extents& e : a.extents) points += NumPoints(e);
  return absl::StrCat(factor, "*", points, " (", points, " points in ", a.extents.size(),
                      " blocks)");
}

// "block 2, y of point (3, 4, 0)" for expanded value `value` under the layout of `a`.
std::string DescribeValue(const Attempt& a, int64_t value) {
  if (value < a.header_values) return "header";
  const BlockValue located =
      LocateBlockValue(a.extents, a.values_per_point(), value - a.header_values);
  if (located.block >= static_cast<int64_t>(a.extents.size())) return "after the last block";
  const Extents& extents = a.extents[located.block];
  return absl::StrCat("block ", located.block, ", ",
                      DescribeBlockValue(extents, a.hypothesis.spatial_dim,
                                         WholeLayoutIndex(extents, a.values_per_point(), a.layout,
                                                          located.index_in_block)));
}

// The error message for failed attempt `a` (without the prefix), its layout named after
// `label` ("best-matching layout").
std::string FailureMessage(const Attempt& a, const FortranList& list, std::string_view text,
                           const char* label = "best-matching layout") {
  const std::string layout =
      absl::StrCat(" (", label, ": ", a.hypothesis.spatial_dim, "D, ",
                   a.hypothesis.has_block_count ? "block-count line" : "no block-count line", ", ",
                   a.hypothesis.has_iblank ? "iblank" : "no iblank", ")");
  // The header value at fault (meaningful for kNotInteger and kOutOfRange only).
  auto what = [&a]() {
    return a.block < 0 ? std::string("the block count")
                       : absl::StrCat("block ", a.block, ": ", ExtentName(a.direction));
  };
  switch (a.failure) {
    case Failure::kNotInteger: {
      const size_t offset = OffsetOfToken(text, a.at);
      if (offset >= text.size()) {
        return absl::StrCat("the file ends in the header, where ", what(), " was expected", layout);
      }
      const size_t end = text.find_first_of(" \t\r\n\v\f,", offset);
      return absl::StrCat(what(), " at ", DescribeOffset(text, offset),
                          ": expected a positive integer, found ",
                          QuoteToken(text.substr(offset, end - offset)), layout);
    }
    case Failure::kOutOfRange:
      return absl::StrCat(what(), " = ", list.token_values[a.at], " at ",
                          DescribeOffset(text, OffsetOfToken(text, a.at)), " must be from 1 to ",
                          a.block < 0 ? kMaxBlocks : kMaxExtent, layout);
    case Failure::kNoLineBreak:
      return absl::StrCat("the header should end at a line break after the value at ",
                          DescribeOffset(text, OffsetOfToken(text, a.at)),
                          ", but more values follow on that line", layout);
    case Failure::kTooManyPoints:
      return absl::StrCat("block ", a.block, ": ", TooManyPointsMessage(a.extents[a.block]),
                          layout);
    case Failure::kCountMismatch: {
      const int64_t found = list.num_values - a.header_values;
      std::string message =
          absl::StrCat("expected ", CountFormula(a), " = ", a.expected_values - a.header_values,
                       a.hypothesis.has_iblank ? " coordinates and iblank values" : " coordinates",
                       " after the header, found ", found);
      if (list.num_values < a.expected_values) {
        absl::StrAppend(&message, "; the file ends before ", DescribeValue(a, list.num_values));
      } else {
        const int64_t token = TokenOfValue(list, a.expected_values);
        absl::StrAppend(&message, "; unexpected values after the last block start at ",
                        DescribeOffset(text, OffsetOfToken(text, token)));
      }
      return absl::StrCat(message, layout);
    }
    case Failure::kBadIblank: {
      const int64_t token = TokenOfValue(list, a.at);
      return absl::StrCat(DescribeValue(a, a.at), " at ",
                          DescribeOffset(text, OffsetOfToken(text, token)), ": ",
                          list.token_values[token], " is not an integer", layout);
    }
    case Failure::kNone:
      break;
  }
  return "internal error: no failure recorded";
}

// Appends `value` in shortest round-trip form, with ".0" added to integral values so that
// coordinates never look like header integers.
void AppendReal(double value, std::string* out) {
  char buffer[40];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  (void)error;  // 40 bytes always suffice for a double
  bool integral = true;
  for (const char* c = buffer; c < end; ++c) {
    if (*c != '-' && (*c < '0' || *c > '9')) integral = false;
  }
  out->append(buffer, end);
  if (integral) out->append(".0");
}

}  // namespace

absl::StatusOr<MultiBlockGrid> ParsePlot3dText(std::string_view text, std::string_view source,
                                               const Plot3dReadOptions& options,
                                               Plot3dFormat* detected) {
  const Plot3dLayout layout = options.layout.value_or(Plot3dLayout::kWhole);
  const FortranList list = TokenizeFortranList(text, 1 + 3 * kMaxBlocks);
  std::optional<Attempt> match;
  // The failed attempt that got furthest, with and without a block-count line.
  std::optional<Attempt> best_by_count[2];
  const auto better = [](const Attempt& a, const std::optional<Attempt>& than) {
    return !than.has_value() || a.stage > than->stage ||
           (a.stage == than->stage && a.stage == Stage::kHeader && a.progress > than->progress);
  };
  // The attempt with a block-count line that failed in its header at the latest block.
  std::optional<Attempt> counted_header;
  for (const Hypothesis& hypothesis : kHypotheses) {
    Attempt attempt = Evaluate(list, hypothesis, layout);
    if (attempt.stage == Stage::kMatch) {
      match = std::move(attempt);
      break;
    }
    if (hypothesis.has_block_count && attempt.stage == Stage::kHeader &&
        (!counted_header.has_value() || attempt.block > counted_header->block)) {
      counted_header = attempt;
    }
    std::optional<Attempt>& best = best_by_count[hypothesis.has_block_count];
    if (better(attempt, best)) best = std::move(attempt);
  }
  // Ties go to the earlier hypothesis, as the order of kHypotheses has it: a block-count line.
  const bool counted_is_best =
      best_by_count[1].has_value() &&
      (!best_by_count[0].has_value() || !better(*best_by_count[0], best_by_count[1]));
  const std::optional<Attempt>& best = best_by_count[counted_is_best ? 1 : 0];
  if (list.first_bad.has_value()) {
    const BadToken& bad = *list.first_bad;
    const Attempt* layout = match.has_value() ? &*match : &*best;
    std::string where;
    if (layout->stage >= Stage::kContent) {
      where = absl::StrCat(DescribeValue(*layout, ValueOfToken(list, bad.token_index)), ", ");
    }
    return absl::InvalidArgumentError(absl::StrCat(
        ErrorPrefix(source), where, DescribeOffset(text, bad.offset), ": ", bad.problem));
  }
  if (!match.has_value()) {
    std::string message = FailureMessage(*best, list, text);
    // A file that starts like a block-count line and the blocks' dimensions, but fails in that
    // header after the first block's (a block's dimensions line missing: coordinates read as
    // dimensions), is best read without one, which then misses values. Both readings say what
    // is wrong.
    if (!counted_is_best && counted_header.has_value() && counted_header->block >= 1) {
      absl::StrAppend(&message, "; read with a block-count line instead: ",
                      FailureMessage(*counted_header, list, text, "layout"));
    }
    return absl::InvalidArgumentError(absl::StrCat(ErrorPrefix(source), message));
  }
  const Attempt& a = *match;
  const int dim = a.hypothesis.spatial_dim;
  MultiBlockGrid grid;
  grid.blocks.reserve(a.extents.size());
  FortranValueCursor cursor(list, a.header_values);
  for (const Extents& extents : a.extents) {
    StructuredBlock block(extents, dim);
    const std::span<double> coords = block.coords();
    const int64_t points = block.num_points();
    const int64_t n = SlabPoints(extents, a.layout);
    if (a.hypothesis.has_iblank) block.iblank().resize(static_cast<size_t>(points));
    for (int64_t first = 0; first < points; first += n) {
      for (int s = 0; s < dim; ++s) {
        for (int64_t p = first; p < first + n; ++p) coords[p * dim + s] = cursor.Next();
      }
      if (a.hypothesis.has_iblank) {
        for (int64_t p = first; p < first + n; ++p) {
          block.iblank()[p] = static_cast<int>(cursor.Next());
        }
      }
    }
    grid.blocks.push_back(std::move(block));
  }
  if (detected != nullptr) {
    Plot3dFormat format;
    format.encoding = Plot3dEncoding::kAscii;
    format.spatial_dim = dim;
    format.has_block_count = a.hypothesis.has_block_count;
    format.has_iblank = a.hypothesis.has_iblank;
    format.bytes_per_real = 8;
    format.layout = a.layout;
    *detected = format;
  }
  return grid;
}

std::string EncodePlot3dText(const MultiBlockGrid& grid, const Plot3dFormat& format) {
  constexpr int kRealsPerLine = 4;
  constexpr int kIntegersPerLine = 10;
  const int dim = format.spatial_dim;
  std::string out;
  int64_t values = 0;
  for (const StructuredBlock& block : grid.blocks) values += block.num_points() * (dim + 1);
  out.reserve(static_cast<size_t>(values * 24 + 64));
  if (format.has_block_count) absl::StrAppend(&out, grid.blocks.size(), "\n");
  for (const StructuredBlock& block : grid.blocks) {
    absl::StrAppend(&out, block.extent(0), " ", block.extent(1));
    if (dim == 3) absl::StrAppend(&out, " ", block.extent(2));
    out.push_back('\n');
  }
  const Plot3dLayout layout = dim == 3 ? format.layout : Plot3dLayout::kWhole;
  for (const StructuredBlock& block : grid.blocks) {
    const std::span<const double> coords = block.coords();
    const int64_t n = SlabPoints(block.extents(), layout);
    for (int64_t first = 0; first < block.num_points(); first += n) {
      for (int s = 0; s < dim; ++s) {
        for (int64_t q = 0; q < n; ++q) {
          AppendReal(coords[(first + q) * dim + s], &out);
          out.push_back((q + 1) % kRealsPerLine == 0 || q + 1 == n ? '\n' : ' ');
        }
      }
      if (format.has_iblank) {
        for (int64_t q = 0; q < n; ++q) {
          absl::StrAppend(&out, block.iblank()[first + q]);
          out.push_back((q + 1) % kIntegersPerLine == 0 || q + 1 == n ? '\n' : ' ');
        }
      }
    }
  }
  return out;
}

}  // namespace splinegrid::plot3d_internal
