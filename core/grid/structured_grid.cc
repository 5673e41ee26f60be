#include "core/grid/structured_grid.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/util/check.h"

namespace splinegrid {

int ActiveDirections(const Extents& extents) {
  int active = 0;
  for (int n : extents) active += n > 1 ? 1 : 0;
  return active;
}

StructuredBlock::StructuredBlock(const Extents& extents, int spatial_dim)
    : extents_(extents), spatial_dim_(spatial_dim) {
  SG_CHECK(spatial_dim == 2 || spatial_dim == 3);
  SG_CHECK(extents[0] >= 1 && extents[1] >= 1 && extents[2] >= 1);
  coords_.assign(static_cast<size_t>(spatial_dim * NumPoints(extents)), 0.0);
}

absl::Status ValidateExtents(const Extents& extents, const std::string& what, int64_t max_points,
                             int max_extent) {
  static constexpr char kNames[] = "ijk";
  for (int d = 0; d < 3; ++d) {
    if (extents[d] < 1 || extents[d] > max_extent) {
      return absl::InvalidArgumentError(absl::StrCat(what, ": n", std::string(1, kNames[d]), " = ",
                                                     extents[d], " is outside [1, ", max_extent,
                                                     "]"));
    }
  }
  // Each extent is at most 2^24 here, so the product of the first two fits in int64; compare
  // the third by division so that the full product cannot overflow.
  const int64_t plane = int64_t{extents[0]} * extents[1];
  if (plane > max_points || extents[2] > max_points / plane) {
    return absl::InvalidArgumentError(absl::StrCat(what, ": ", extents[0], " x ", extents[1], " x ",
                                                   extents[2], " points exceeds the limit of ",
                                                   max_points));
  }
  return absl::OkStatus();
}

absl::Status ValidateFinite(const StructuredBlock& block, const std::string& what) {
  const auto coords = block.coords();
  const int s = block.spatial_dim();
  for (size_t c = 0; c < coords.size(); ++c) {
    if (!std::isfinite(coords[c])) {
      const int64_t p = static_cast<int64_t>(c) / s;
      const int64_t ni = block.extent(0), nj = block.extent(1);
      return absl::InvalidArgumentError(absl::StrCat(
          what, ": point (", p % ni, ", ", (p / ni) % nj, ", ", p / (ni * nj), ") coordinate ",
          std::string(1, "xyz"[c % s]), " is ", coords[c], "; coordinates must be finite"));
    }
  }
  return absl::OkStatus();
}

}  // namespace splinegrid
