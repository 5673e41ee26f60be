#include "core/bspline/block_sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/bspline/line_arc_length.h"
#include "core/grid/structured_grid.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

constexpr char kNames[] = "ijk";

// The two directions other than d, lower first.
std::array<int, 2> Others(int d) { return {d == 0 ? 1 : 0, d == 2 ? 1 : 2}; }

// Arc lengths from the line's start of `count` points spread by `distribution` over `length`.
std::vector<double> TargetLengths(const Distribution& distribution, double length, int count) {
  std::vector<double> s = UniformParameters(0.0, length, count);
  if (distribution.kind != Distribution::Kind::kGeometric || count < 3) return s;
  const double h = distribution.first_spacing;
  const double r = GeometricRatio(h, length, count - 1);
  double spacing = h;
  for (int q = 1; q + 1 < count; ++q) {
    s[q] = s[q - 1] + spacing;
    spacing *= r;
  }
  if (distribution.from_end) {
    std::vector<double> mirrored(count);
    for (int q = 0; q < count; ++q) mirrored[q] = length - s[count - 1 - q];
    mirrored.front() = 0.0;
    mirrored.back() = length;
    return mirrored;
  }
  return s;
}

}  // namespace

int64_t BlockSampling::Bytes(const Resolution& resolution, const Extents& extents) {
  int64_t values = int64_t{extents[0]} + extents[1] + extents[2];
  // The parameters of every line, and one line's target lengths (twice, mirrored).
  const int d = MeasuredDirection(resolution);
  if (d >= 0) values += NumPoints(extents) + 2 * extents[d];
  return values * int64_t{sizeof(double)};
}

absl::StatusOr<BlockSampling> BlockSampling::Create(const TensorSpline& spline,
                                                    const PointDistribution& distribution,
                                                    const Resolution& resolution,
                                                    const CancelCheck& cancel) {
  BlockSampling sampling;
  SG_ASSIGN_OR_RETURN(sampling.extents_, SampleExtents(distribution, resolution));
  const int d = MeasuredDirection(resolution);
  // The tensor directions (the measured one sampled evenly in parameter, then dropped).
  Resolution tensor = resolution;
  if (d >= 0) tensor.distributions[d] = {Distribution::Kind::kUniformParameter};
  SG_ASSIGN_OR_RETURN(sampling.params_, SampleParameters(distribution, tensor));
  if (d < 0) return sampling;
  sampling.measured_ = d;
  sampling.params_[d].clear();

  const Distribution& wanted = resolution.distributions[d];
  const int first = resolution.box ? resolution.box->begin[d] : 0;
  const int last = resolution.box ? resolution.box->end[d] : distribution.num_points(d) - 1;
  const double t0 = distribution.params(d)[first], t1 = distribution.params(d)[last];
  const Extents& n = sampling.extents_;
  const auto [e1, e2] = Others(d);
  sampling.line_params_.resize(NumPoints(n));
  // A line shorter than this is a collapsed edge: its length is rounding (the derivative
  // weights of equal control points cancel only in exact arithmetic).
  double scale = 0.0;
  for (double x : spline.control()) scale = std::max(scale, std::abs(x));
  const double negligible = 1e-12 * scale;
  // Points nearer than this can round to the same coordinates: a few ulps of the largest one.
  const double separable = kResolvableUlps * std::numeric_limits<double>::epsilon() * scale;
  for (int c = 0; c < n[e2]; ++c) {
    for (int a = 0; a < n[e1]; ++a) {
      SG_RETURN_IF_ERROR(PollCancel(cancel));
      Point3 fixed = {0.0, 0.0, 0.0};
      fixed[e1] = sampling.params_[e1][a];
      fixed[e2] = sampling.params_[e2][c];
      // The directions by value: clang 14 does not capture structured bindings.
      const auto line_name = [&, i1 = e1, i2 = e2] {
        return absl::StrCat("the grid line at output ", std::string(1, kNames[i1]), " = ", a, ", ",
                            std::string(1, kNames[i2]), " = ", c);
      };
      const LineArcLength line(spline, d, fixed, t0, t1);
      double* t = sampling.line_params_.data() + (int64_t{a} + int64_t{n[e1]} * c) * n[d];
      if (line.length() <= negligible) {
        const std::vector<double> even = UniformParameters(t0, t1, n[d]);
        std::copy(even.begin(), even.end(), t);
        continue;
      }
      if (wanted.kind == Distribution::Kind::kGeometric &&
          !(wanted.first_spacing < line.length())) {
        return absl::InvalidArgumentError(absl::StrCat(
            "distributions.", std::string(1, kNames[d]), ".first_spacing = ", wanted.first_spacing,
            " is not below the length ", line.length(), " of ", line_name()));
      }
      const std::vector<double> s = TargetLengths(wanted, line.length(), n[d]);
      for (int q = 0; q < n[d]; ++q) t[q] = line.ParameterAt(s[q]);
      t[0] = t0;  // a single point sits at the first index, as in the other distributions
      if (n[d] > 1) t[n[d] - 1] = t1;
      for (int q = 1; q < n[d]; ++q) {
        if (!(t[q] > t[q - 1]) || !(s[q] - s[q - 1] > separable)) {
          return absl::InvalidArgumentError(absl::StrCat(
              "distributions.", std::string(1, kNames[d]), ": points ", q - 1, " and ", q, " of ",
              line_name(), " are ", s[q] - s[q - 1],
              " apart, closer than double precision separates at coordinates up to ", scale));
        }
      }
    }
  }
  return sampling;
}

Point3 BlockSampling::ParametersAt(int a, int b, int c) const {
  const std::array<int, 3> index = {a, b, c};
  Point3 uvw;
  for (int e = 0; e < 3; ++e) {
    if (e != measured_) uvw[e] = params_[e][index[e]];
  }
  if (measured_ >= 0) {
    const auto [e1, e2] = Others(measured_);
    const int64_t line = index[e1] + int64_t{extents_[e1]} * index[e2];
    uvw[measured_] = line_params_[line * extents_[measured_] + index[measured_]];
  }
  return uvw;
}

void EvaluateSampledPoints(const TensorSpline& spline, const BlockSampling& sampling, int64_t first,
                           int64_t count, double* points, double* du, double* dv, double* dw) {
  const Extents& n = sampling.extents();
  const int s = spline.spatial_dim();
  for (int64_t p = first; p < first + count; ++p) {
    const int a = static_cast<int>(p % n[0]);
    const int b = static_cast<int>((p / n[0]) % n[1]);
    const int c = static_cast<int>(p / (int64_t{n[0]} * n[1]));
    const Point3 uvw = sampling.ParametersAt(a, b, c);
    const int64_t at = (p - first) * s;
    if (du == nullptr) {
      const Point3 x = EvaluatePoint(spline, uvw);
      for (int i = 0; i < s; ++i) points[at + i] = x[i];
      continue;
    }
    const PartialDerivatives d = EvaluateDerivatives(spline, uvw, 1);
    for (int i = 0; i < s; ++i) {
      points[at + i] = d(0, 0, 0)[i];
      du[at + i] = d(1, 0, 0)[i];
      dv[at + i] = d(0, 1, 0)[i];
      dw[at + i] = d(0, 0, 1)[i];
    }
  }
}

}  // namespace splinegrid
