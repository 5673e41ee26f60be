#include "core/grid/sampling.h"

#include <cmath>
#include <string>

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

std::string DistributionField(int d, absl::string_view member = "") {
  return absl::StrCat("distributions.", std::string(1, kNames[d]), member.empty() ? "" : ".",
                      member);
}

// OUT_OF_RANGE when the points of `extents` (each at most 2^30) exceed 2^40 in all: no output
// that large fits any budget, and the product of three counts could overflow an int64.
absl::Status CheckTotal(const Extents& extents, absl::string_view field) {
  constexpr int64_t kMax = int64_t{1} << 40;
  const int64_t plane = int64_t{extents[0]} * extents[1];  // below 2^60
  if (plane > kMax || extents[2] > kMax / plane) {
    return absl::OutOfRangeError(absl::StrCat(field, " gives ", extents[0], " x ", extents[1],
                                              " x ", extents[2],
                                              " points, over 2^40 in one block"));
  }
  return absl::OkStatus();
}

// The distributions can be followed with these point counts (see SampleExtents).
absl::Status CheckDistributions(const std::array<Distribution, 3>& distributions,
                                const Extents& extents) {
  int measured = -1;
  for (int d = 0; d < 3; ++d) {
    const Distribution& dist = distributions[d];
    const bool geometric = dist.kind == Distribution::Kind::kGeometric;
    if (IsMeasured(dist.kind)) {
      if (measured >= 0) {
        return absl::InvalidArgumentError(absl::StrCat(
            DistributionField(measured), " and ", DistributionField(d),
            " are both measured along grid lines (uniform arc length or geometric); at most one "
            "direction may be, the others keep one parameter per index"));
      }
      measured = d;
    }
    if (geometric) {
      if (!(std::isfinite(dist.first_spacing) && dist.first_spacing > 0.0)) {
        return absl::InvalidArgumentError(absl::StrCat(DistributionField(d, "first_spacing"), " = ",
                                                       dist.first_spacing,
                                                       " is not a positive finite length"));
      }
      if (extents[d] < 3) {
        return absl::InvalidArgumentError(absl::StrCat(
            DistributionField(d), " is geometric but the resolution gives ", extents[d],
            " point(s) in that direction; a first spacing needs at least 3"));
      }
    } else if (dist.first_spacing != 0.0) {
      return absl::InvalidArgumentError(absl::StrCat(DistributionField(d, "first_spacing"), " = ",
                                                     dist.first_spacing,
                                                     " is only for the geometric distribution"));
    } else if (dist.from_end) {
      return absl::InvalidArgumentError(absl::StrCat(DistributionField(d, "from_end"),
                                                     " is only for the geometric distribution"));
    }
  }
  return absl::OkStatus();
}

}  // namespace

int MeasuredDirection(const Resolution& resolution) {
  for (int d = 0; d < 3; ++d) {
    if (IsMeasured(resolution.distributions[d].kind)) return d;
  }
  return -1;
}

std::vector<double> UniformParameters(double begin, double end, int count) {
  std::vector<double> out(count, begin);
  for (int q = 1; q < count; ++q) out[q] = begin + (end - begin) * q / (count - 1);
  if (count > 1) out.back() = end;
  return out;
}

double GeometricRatio(double first, double total, int intervals) {
  if (std::abs(total - first * intervals) <= 1e-12 * total) return 1.0;
  const auto sum = [&](double r) {
    return std::abs(r - 1.0) < 1e-12 ? first * intervals
                                     : first * (std::pow(r, intervals) - 1.0) / (r - 1.0);
  };
  double lo = 0.0, hi = 1.0;
  while (sum(hi) < total) hi *= 2.0;
  for (int iteration = 0; iteration < 200 && hi - lo > 1e-15 * hi; ++iteration) {
    const double mid = 0.5 * (lo + hi);
    (sum(mid) < total ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

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
    SG_RETURN_IF_ERROR(CheckTotal(extents, absl::StrCat("refinement_level = ", resolution.level)));
    SG_RETURN_IF_ERROR(CheckDistributions(resolution.distributions, extents));
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
  SG_RETURN_IF_ERROR(CheckTotal(extents, "counts"));
  SG_RETURN_IF_ERROR(CheckDistributions(resolution.distributions, extents));
  return extents;
}

absl::StatusOr<std::array<std::vector<double>, 3>> SampleParameters(
    const PointDistribution& distribution, const Resolution& resolution) {
  SG_ASSIGN_OR_RETURN(const Extents extents, SampleExtents(distribution, resolution));
  SG_ASSIGN_OR_RETURN(const IndexBox box, CheckedBox(distribution, resolution));
  std::array<std::vector<double>, 3> params;
  for (int d = 0; d < 3; ++d) {
    switch (resolution.distributions[d].kind) {
      case Distribution::Kind::kOriginal:
        params[d] = resolution.kind == Resolution::Kind::kLevel
                        ? distribution.Refined(d, box.begin[d], box.end[d], resolution.level)
                        : distribution.Resampled(d, box.begin[d], box.end[d], extents[d]);
        break;
      case Distribution::Kind::kUniformParameter:
        params[d] = UniformParameters(distribution.params(d)[box.begin[d]],
                                      distribution.params(d)[box.end[d]], extents[d]);
        break;
      case Distribution::Kind::kUniformArcLength:
      case Distribution::Kind::kGeometric:
        return absl::InvalidArgumentError(
            absl::StrCat(DistributionField(d),
                         " is measured along the spline's grid lines; sample it with "
                         "BlockSampling"));
    }
  }
  return params;
}

}  // namespace splinegrid
