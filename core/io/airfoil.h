// Airfoil coordinate files in the Selig and Lednicer formats (UIUC airfoil database style).
//
// Selig:    a name line, then "x y" per line from the trailing edge over the upper surface to the
//           leading edge and back along the lower surface to the trailing edge.
// Lednicer: a name line, a line with the upper and lower point counts ("  61.  61."), then the
//           upper surface from leading to trailing edge, then the lower surface from leading to
//           trailing edge; blank lines between the sections are optional.
// The format is detected from the second line: it is Lednicer's count line when both numbers are
// whole numbers >= 2 (a normalized airfoil has x <= 1 and a Selig file starts at the trailing
// edge) and they add up to the number of points that follow; two whole numbers >= 2 that do not
// add up are an error rather than a guess. Numbers may use E or Fortran D exponents and be
// separated by whitespace or a comma. Blank lines are ignored. The result is always in Selig
// order (a Lednicer upper surface is reversed); exact duplicate consecutive points (such as the
// leading edge listed at the start of both Lednicer surfaces) are dropped and counted.
#ifndef SPLINEGRID_CORE_IO_AIRFOIL_H_
#define SPLINEGRID_CORE_IO_AIRFOIL_H_

#include <string>
#include <string_view>

#include "absl/status/statusor.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

// The two airfoil file layouts.
enum class AirfoilFileFormat { kSelig, kLednicer };

// An airfoil outline as read from a file.
struct AirfoilCoordinates {
  // The name line, trimmed of surrounding whitespace.
  std::string name;
  // n x 1 x 1 points, spatial_dim 2, in Selig order (trailing edge, upper surface, leading edge,
  // lower surface, trailing edge).
  StructuredBlock points;
  // Layout the file used.
  AirfoilFileFormat format = AirfoilFileFormat::kSelig;
  // Number of exact duplicate consecutive points that were dropped.
  int duplicates_dropped = 0;
};

// Parses an airfoil file's `text` (see the file comment). INVALID_ARGUMENT naming
// `source_name` and the line for: a missing name line, a line that is not two numbers, NaN/Inf,
// a Lednicer count line whose counts do not match the points, fewer than 5 points (after
// dropping duplicates). O(size of text).
absl::StatusOr<AirfoilCoordinates> ParseAirfoil(std::string_view text,
                                                std::string_view source_name);

// Reads and parses the airfoil file at `path`; NOT_FOUND when it is missing.
absl::StatusOr<AirfoilCoordinates> ReadAirfoilFile(const std::string& path);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_IO_AIRFOIL_H_
