#include "core/io/airfoil.h"

#include <array>
#include <cmath>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/file_util.h"
#include "core/io/fortran_text.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

// Fewest points an airfoil outline may have.
constexpr int kMinPoints = 5;

// A point read from the file and the 1-based line it came from.
struct LinePoint {
  std::array<double, 2> xy;  // x, y
  int64_t line;              // 1-based line number
};

// `text` without leading and trailing whitespace.
std::string_view Trim(std::string_view text) {
  const size_t first = text.find_first_not_of(" \t\r\n\v\f");
  if (first == std::string_view::npos) return {};
  const size_t last = text.find_last_not_of(" \t\r\n\v\f");
  return text.substr(first, last - first + 1);
}

// Parses the non-blank `line` (number `line_number`) as two numbers "x y".
absl::Status ParseLine(std::string_view line, int64_t line_number, const std::string& prefix,
                       LinePoint* point) {
  std::vector<std::string_view> fields;
  size_t pos = 0;
  while (pos < line.size()) {
    while (pos < line.size() && IsListSeparator(line[pos])) ++pos;
    const size_t start = pos;
    while (pos < line.size() && !IsListSeparator(line[pos])) ++pos;
    if (pos > start) fields.push_back(line.substr(start, pos - start));
  }
  const std::string where = absl::StrCat(prefix, "line ", line_number, ": ");
  if (fields.size() != 2) {
    return absl::InvalidArgumentError(absl::StrCat(where, "expected two numbers \"x y\", found ",
                                                   fields.size(), " fields in ", QuoteToken(line)));
  }
  for (int s = 0; s < 2; ++s) {
    double value = 0.0;
    if (!ParseFortranReal(fields[s], &value)) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, QuoteToken(fields[s]), " is not a number"));
    }
    if (!std::isfinite(value)) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, QuoteToken(fields[s]), " is not a finite number"));
    }
    point->xy[s] = value;
  }
  point->line = line_number;
  return absl::OkStatus();
}

// Whether `value` is a whole number that can count Lednicer points.
bool IsPointCount(double value) { return value >= 2 && value <= 1e7 && value == std::floor(value); }

}  // namespace

absl::StatusOr<AirfoilCoordinates> ParseAirfoil(std::string_view text,
                                                std::string_view source_name) {
  const std::string prefix = absl::StrCat("airfoil '", std::string(source_name), "': ");
  AirfoilCoordinates airfoil;
  std::vector<LinePoint> points;
  bool have_name = false;
  int64_t line_number = 0;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = Trim(text.substr(pos, end - pos));
    pos = end + 1;
    ++line_number;
    if (!have_name) {
      if (line.empty()) {
        return absl::InvalidArgumentError(
            absl::StrCat(prefix, "line 1: expected the airfoil name, found an empty line"));
      }
      airfoil.name = std::string(line);
      have_name = true;
      continue;
    }
    if (line.empty()) continue;
    LinePoint point;
    SG_RETURN_IF_ERROR(ParseLine(line, line_number, prefix, &point));
    points.push_back(point);
  }
  if (!have_name) return absl::InvalidArgumentError(absl::StrCat(prefix, "the file is empty"));

  std::vector<LinePoint> ordered;
  if (!points.empty() && IsPointCount(points[0].xy[0]) && IsPointCount(points[0].xy[1])) {
    const int64_t upper = static_cast<int64_t>(points[0].xy[0]);
    const int64_t lower = static_cast<int64_t>(points[0].xy[1]);
    const int64_t available = static_cast<int64_t>(points.size()) - 1;
    if (upper + lower != available) {
      return absl::InvalidArgumentError(
          absl::StrCat(prefix, "line ", points[0].line, ": Lednicer point counts ", upper, " + ",
                       lower, " do not match the ", available, " points that follow"));
    }
    airfoil.format = AirfoilFileFormat::kLednicer;
    for (int64_t p = upper; p >= 1; --p) ordered.push_back(points[p]);              // TE -> LE
    for (int64_t p = upper + 1; p <= available; ++p) ordered.push_back(points[p]);  // LE -> TE
  } else {
    airfoil.format = AirfoilFileFormat::kSelig;
    ordered = std::move(points);
  }

  std::vector<LinePoint> unique;
  unique.reserve(ordered.size());
  for (const LinePoint& point : ordered) {
    if (!unique.empty() && unique.back().xy == point.xy) {
      ++airfoil.duplicates_dropped;
      continue;
    }
    unique.push_back(point);
  }
  if (unique.size() < kMinPoints) {
    return absl::InvalidArgumentError(
        absl::StrCat(prefix, "line ", line_number, " (end of file): found ", unique.size(),
                     " distinct points, an airfoil needs at least ", kMinPoints));
  }
  airfoil.points = StructuredBlock({static_cast<int>(unique.size()), 1, 1}, 2);
  for (size_t p = 0; p < unique.size(); ++p) {
    double* xy = airfoil.points.Point(static_cast<int>(p), 0, 0);
    xy[0] = unique[p].xy[0];
    xy[1] = unique[p].xy[1];
  }
  return airfoil;
}

absl::StatusOr<AirfoilCoordinates> ReadAirfoilFile(const std::string& path) {
  SG_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(path));
  return ParseAirfoil(text, path);
}

}  // namespace splinegrid
