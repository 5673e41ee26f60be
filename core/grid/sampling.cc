#include "core/grid/sampling.h"

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

constexpr char kNames[] = "ijk";

// The validated box (the whole block when none is given).
absl::StatusOr<IndexBox> CheckedBox(const PointDistribution& distribution,
                                    const Resolution& resolution) {
  IndexBox box;
  for (int d = 0; d < 3; ++d) box.end[d] = distribution.num_points(d) - 1;
  if (!resolution.box) return box;
  for (int d = 0; d < 3; ++d) {
    const int b = resolution.box->begin[d], e = resolution.box->end[d];
    const int last = distribution.num_points(d) - 1;
    if (b < 0 || e > last || e < b) {
      return absl::InvalidArgumentError(absl::StrCat("index_box ", std::string(1, kNames[d]),
                                                     " = [", b, ", ", e, "] is not inside [0, ",
                                                     last, "] with begin <= end"));
    }
  }
  return *resolution.box;
}

}  // namespace

absl::StatusOr<Extents> SampleExtents(const PointDistribution& distribution,
                                      const Resolution& resolution) {
  SG_ASSIGN_OR_RETURN(const IndexBox box, CheckedBox(distribution, resolution));
  Extents extents;
  if (resolution.kind == Resolution::Kind::kLevel) {
    if (resolution.level < 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("refinement_level = ", resolution.level, " is negative"));
    }
    if (resolution.level > kMaxRefinementLevel) {
      return absl::OutOfRangeError(absl::StrCat("refinement_level = ", resolution.level,
                                                " is above the highest level, ",
                                                kMaxRefinementLevel));
    }
    for (int d = 0; d < 3; ++d) {
      const int64_t n = (int64_t{box.end[d]} - box.begin[d]) * (int64_t{1} << resolution.level) + 1;
      if (n > (int64_t{1} << 30)) {
        return absl::OutOfRangeError(absl::StrCat("refinement_level = ", resolution.level,
                                                  " gives ", n, " points in direction ",
                                                  std::string(1, kNames[d])));
      }
      extents[d] = static_cast<int>(n);
    }
    return extents;
  }
  for (int d = 0; d < 3; ++d) {
    const int n = resolution.counts[d];
    if (n < 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("counts.", std::string(1, kNames[d]), " = ", n, " is below 1"));
    }
    if (n > (1 << 30)) {
      return absl::OutOfRangeError(
          absl::StrCat("counts.", std::string(1, kNames[d]), " = ", n, " is above 2^30"));
    }
    if (n > 1 && box.begin[d] == box.end[d]) {
      return absl::InvalidArgumentError(
          absl::StrCat("counts.", std::string(1, kNames[d]), " = ", n,
                       " but the block (or box) has a single point in that direction; use 1"));
    }
    extents[d] = n;
  }
  return extents;
}

absl::StatusOr<std::array<std::vector<double>, 3>> SampleParameters(
    const PointDistribution& distribution, const Resolution& resolution) {
  SG_ASSIGN_OR_RETURN(const Extents extents, SampleExtents(distribution, resolution));
  SG_ASSIGN_OR_RETURN(const IndexBox box, CheckedBox(distribution, resolution));
  std::array<std::vector<double>, 3> params;
  for (int d = 0; d < 3; ++d) {
    params[d] = resolution.kind == Resolution::Kind::kLevel
                    ? distribution.Refined(d, box.begin[d], box.end[d], resolution.level)
                    : distribution.Resampled(d, box.begin[d], box.end[d], extents[d]);
  }
  return params;
}

}  // namespace splinegrid
