#include "core/fit/adaptive/refinement.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/bspline/basis.h"
#include "core/bspline/contraction.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

// The tensor view (a, m, b) of direction d: a = coordinates x faster directions.
struct DirectionView {
  int64_t a, m, b, points_a;  // points_a = a / spatial_dim
};

DirectionView ViewOf(const StructuredBlock& block, int d) {
  const Extents& n = block.extents();
  DirectionView v{block.spatial_dim(), n[d], 1, 1};
  for (int e = 0; e < d; ++e) v.points_a *= n[e];
  for (int e = d + 1; e < 3; ++e) v.b *= n[e];
  v.a *= v.points_a;
  return v;
}

// The relative tolerance of an edge between points with edge tolerances a and b: the looser
// one, or 0 (off) if either is off. So an edge gets a tight value only if both its ends have
// it: along a wall, or inside a cell whose corners were all tightened.
double EdgeLimit(double a, double b) {
  if (a <= 0.0 || b <= 0.0) return 0.0;
  return std::max(a, b);
}

}  // namespace

absl::Status FeatureOptions::Validate() const {
  const std::pair<const char*, double> angles[] = {{"angle_degrees", angle_degrees},
                                                   {"spike_degrees", spike_degrees}};
  for (const auto& [name, value] : angles) {
    if (!(value >= 0.0 && value <= 180.0)) {
      return absl::InvalidArgumentError(
          absl::StrCat("features.", name, " = ", value, " is outside [0, 180]"));
    }
  }
  if (!(spike_ratio >= 1.0) || !std::isfinite(spike_ratio)) {
    return absl::InvalidArgumentError(
        absl::StrCat("features.spike_ratio = ", spike_ratio, " is not a finite number >= 1"));
  }
  if (!(kink_ratio >= 0.0) || !std::isfinite(kink_ratio)) {
    return absl::InvalidArgumentError(
        absl::StrCat("features.kink_ratio = ", kink_ratio, " is not a finite number >= 0"));
  }
  return absl::OkStatus();
}

ErrorAssessment AssessErrors(const StructuredBlock& block, const double* fitted,
                             std::span<const double> tolerance,
                             std::span<const double> edge_tolerance, int per_index_direction,
                             std::vector<double>* per_index) {
  const Extents& n = block.extents();
  const int s = block.spatial_dim();
  const double* data = block.coords().data();
  if (per_index) per_index->assign(n[std::max(per_index_direction, 0)], 0.0);
  ErrorAssessment result;
  auto note = [&](double ratio, int i, int j, int k, bool edge) {
    if (per_index) {
      const Extents x = {i, j, k};
      double& w = (*per_index)[x[per_index_direction]];
      w = std::max(w, ratio);
    }
    if (ratio > result.max_ratio) {
      result.max_ratio = ratio;
      result.max_at = {i, j, k};
      result.max_is_edge = edge;
    }
  };
  const int64_t stride[3] = {s, int64_t{s} * n[0], int64_t{s} * n[0] * n[1]};
  for (int k = 0; k < n[2]; ++k) {
    for (int j = 0; j < n[1]; ++j) {
      for (int i = 0; i < n[0]; ++i) {
        const int64_t p = block.Index(i, j, k);
        const double* x = data + s * p;
        const double* f = fitted + s * p;
        const double tol = tolerance.size() == 1 ? tolerance[0] : tolerance[p];
        if (std::isfinite(tol)) {
          double d2 = 0.0;
          for (int c = 0; c < s; ++c) d2 += (f[c] - x[c]) * (f[c] - x[c]);
          note(std::sqrt(d2) / tol, i, j, k, false);
        }
        if (edge_tolerance.empty()) continue;
        const double edge_p = edge_tolerance.size() == 1 ? edge_tolerance[0] : edge_tolerance[p];
        const int idx[3] = {i, j, k};
        for (int d = 0; d < 3; ++d) {
          if (idx[d] + 1 >= n[d]) continue;
          const double edge_q =
              edge_tolerance.size() == 1 ? edge_tolerance[0] : edge_tolerance[p + stride[d] / s];
          const double edge = EdgeLimit(edge_p, edge_q);
          if (edge <= 0.0) continue;
          double len2 = 0.0, err2 = 0.0;
          for (int c = 0; c < s; ++c) {
            const double dx = x[stride[d] + c] - x[c];
            const double df = f[stride[d] + c] - f[c];
            len2 += dx * dx;
            err2 += (df - dx) * (df - dx);
          }
          if (!(len2 > 0.0)) continue;
          const double ratio = std::sqrt(err2 / len2) / edge;
          note(ratio, i, j, k, true);
          Extents q = {i, j, k};
          ++q[d];
          note(ratio, q[0], q[1], q[2], true);
        }
      }
    }
  }
  return result;
}

absl::StatusOr<std::vector<double>> DirectionResidualRatio(
    const StructuredBlock& block, int d, const std::vector<double>& params, const KnotVector& knots,
    const std::vector<Pin>& pins, std::span<const double> tolerance,
    std::span<const double> edge_tolerance, const CancelCheck& cancel) {
  const DirectionView v = ViewOf(block, d);
  SG_ASSIGN_OR_RETURN(DirectionFit fit,
                      DirectionFit::Create(knots, params, EndCondition::kInterpolate, pins));
  std::vector<double> control(v.a * knots.num_controls() * v.b);
  SG_RETURN_IF_ERROR(fit.Apply(block.coords().data(), v.a, v.b, control.data(), cancel));
  std::vector<double> fitted(block.coords().size());
  ContractDirection(control.data(), v.a, v.b, SampleBasis(knots, params), 0, fitted.data());
  std::vector<double> worst;
  AssessErrors(block, fitted.data(), tolerance, edge_tolerance, d, &worst);
  return worst;
}

std::vector<int> DetectFeatures(const StructuredBlock& block, int d,
                                const FeatureOptions& options) {
  if (!options.detect || block.extent(d) < 3) return {};
  const DirectionView v = ViewOf(block, d);
  const int s = block.spatial_dim();
  const double kPi = 3.14159265358979323846;
  const double absolute = options.angle_degrees * kPi / 180.0;
  const double spike = options.spike_degrees * kPi / 180.0;
  std::vector<bool> feature(v.m, false);
  std::vector<double> angle(v.m, 0.0);
  const double* data = block.coords().data();
  const Extents& n = block.extents();
  for (int64_t e = 0; e < v.b; ++e) {
    for (int64_t x = 0; x < v.points_a; ++x) {
      // Only lines on the block's boundary: an index of every other active direction is 0 or
      // its last. A kink of one interior line (a grid singularity) is no reason to make every
      // line C0 there.
      const int64_t line = x + v.points_a * e;  // linear index with direction d removed
      bool on_boundary = false;
      for (int o = 0, stride = 1; o < 3; ++o) {
        if (o == d) continue;
        const int64_t idx = (line / stride) % n[o];
        if (n[o] > 1 && (idx == 0 || idx == n[o] - 1)) on_boundary = true;
        stride *= n[o];
      }
      if (!on_boundary && ActiveDirections(n) > 1) continue;
      auto point = [&](int64_t r) { return data + s * x + v.a * (r + v.m * e); };
      for (int64_t r = 1; r + 1 < v.m; ++r) {
        const double *p0 = point(r - 1), *p1 = point(r), *p2 = point(r + 1);
        double dot = 0.0, l1 = 0.0, l2 = 0.0;
        for (int c = 0; c < s; ++c) {
          const double a = p1[c] - p0[c], b = p2[c] - p1[c];
          dot += a * b;
          l1 += a * a;
          l2 += b * b;
        }
        angle[r] =
            l1 > 0.0 && l2 > 0.0 ? std::acos(std::clamp(dot / std::sqrt(l1 * l2), -1.0, 1.0)) : 0.0;
      }
      for (int64_t r = 1; r + 1 < v.m; ++r) {
        const double neighbours = std::max(angle[r - 1], r + 2 < v.m ? angle[r + 1] : 0.0);
        if ((angle[r] >= absolute && angle[r] >= options.kink_ratio * neighbours) ||
            (angle[r] >= spike && angle[r] >= options.spike_ratio * neighbours)) {
          feature[r] = true;
        }
      }
    }
  }
  std::vector<int> features;
  for (int r = 1; r + 1 < v.m; ++r) {
    // Two features next to each other leave no data between them: keep the first.
    if (feature[r] && (features.empty() || features.back() < r - 1)) features.push_back(r);
  }
  return features;
}

namespace {

// The number of data in every span of the interior knots (last span closed).
std::vector<int> DataPerSpan(const std::vector<double>& params, const std::vector<double>& knots) {
  std::vector<int> count(knots.size() + 1, 0);
  for (double u : params) {
    ++count[std::upper_bound(knots.begin(), knots.end(), u) - knots.begin()];
  }
  return count;
}

}  // namespace

int SingleDatumRun(const std::vector<double>& params, const std::vector<double>& knots) {
  int longest = 0, run = 0;
  for (int c : DataPerSpan(params, knots)) {
    run = c < 2 ? run + 1 : 0;
    longest = std::max(longest, run);
  }
  return longest;
}

std::vector<double> BreakSingleDatumRuns(const std::vector<double>& params,
                                         const std::vector<double>& knots, int max_run) {
  const std::vector<int> count = DataPerSpan(params, knots);
  std::vector<double> kept;
  int run = count[0] < 2 ? 1 : 0;
  int previous = count[0];  // data of the span ending at the next knot
  for (size_t s = 1; s < count.size(); ++s) {
    if (count[s] < 2 && run + 1 > max_run) {
      previous += count[s];  // drop knots[s - 1]: span s joins the one before
      if (previous >= 2) run = 0;
      continue;
    }
    kept.push_back(knots[s - 1]);
    previous = count[s];
    run = count[s] < 2 ? run + 1 : 0;
  }
  return kept;
}

int SplitSpans(const std::vector<double>& params, const std::vector<double>& ratio, double limit,
               int max_new, std::vector<double>& knots, const std::function<bool()>& well_posed,
               int max_single_run) {
  std::vector<double> breaks = {0.0};
  breaks.insert(breaks.end(), knots.begin(), knots.end());
  breaks.push_back(1.0);
  std::vector<std::pair<double, double>> candidates;  // (worst ratio, new knot)
  const int m = static_cast<int>(params.size());
  for (size_t span = 0; span + 1 < breaks.size(); ++span) {
    const double lo = breaks[span], hi = breaks[span + 1];
    // Data strictly inside the span.
    const int r0 =
        static_cast<int>(std::upper_bound(params.begin(), params.end(), lo) - params.begin());
    const int r1 =
        static_cast<int>(std::lower_bound(params.begin(), params.end(), hi) - params.begin());
    if (r1 - r0 < 2) continue;
    double worst = 0.0;
    for (int r = std::max(r0 - 1, 0); r <= std::min(r1, m - 1); ++r) {
      worst = std::max(worst, ratio[r]);
    }
    if (worst <= limit) continue;
    const int mid = (r0 + r1 - 1) / 2;
    candidates.push_back({worst, 0.5 * (params[mid] + params[mid + 1])});
  }
  std::sort(candidates.begin(), candidates.end(), std::greater<>());
  int added = 0;
  for (const auto& [worst, knot] : candidates) {
    if (added == max_new) break;
    const auto at = knots.insert(std::upper_bound(knots.begin(), knots.end(), knot), knot);
    if ((max_single_run <= 0 || SingleDatumRun(params, knots) <= max_single_run) && well_posed()) {
      ++added;
    } else {
      knots.erase(std::find(knots.begin(), knots.end(), knot));
    }
    (void)at;
  }
  return added;
}

}  // namespace splinegrid
