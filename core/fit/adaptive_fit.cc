#include "core/fit/adaptive_fit.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include "absl/strings/str_cat.h"
#include "core/bspline/basis.h"
#include "core/bspline/contraction.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

constexpr char kDirectionNames[] = "ijk";

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

// For every data index r of direction d: max over the grid lines of d of
// |(I - P_d) X| / tolerance, where P_d fits each line with `knots`.
absl::StatusOr<std::vector<double>> DirectionResidualRatio(
    const StructuredBlock& block, int d, const std::vector<double>& params, const KnotVector& knots,
    const std::vector<Pin>& pins, std::span<const double> tolerance, const CancelCheck& cancel) {
  const DirectionView v = ViewOf(block, d);
  const int s = block.spatial_dim();
  SG_ASSIGN_OR_RETURN(DirectionFit fit,
                      DirectionFit::Create(knots, params, EndCondition::kInterpolate, pins));
  std::vector<double> control(v.a * knots.num_controls() * v.b);
  SG_RETURN_IF_ERROR(fit.Apply(block.coords().data(), v.a, v.b, control.data(), cancel));
  std::vector<double> fitted(block.coords().size());
  ContractDirection(control.data(), v.a, v.b, SampleBasis(knots, params), 0, fitted.data());
  std::vector<double> worst(v.m, 0.0);
  const double* data = block.coords().data();
  for (int64_t e = 0; e < v.b; ++e) {
    for (int64_t r = 0; r < v.m; ++r) {
      const int64_t base = v.a * (r + v.m * e);
      for (int64_t x = 0; x < v.points_a; ++x) {
        double d2 = 0.0;
        for (int c = 0; c < s; ++c) {
          const double diff = fitted[base + s * x + c] - data[base + s * x + c];
          d2 += diff * diff;
        }
        const double tol =
            tolerance.size() == 1 ? tolerance[0] : tolerance[x + v.points_a * (r + v.m * e)];
        worst[r] = std::max(worst[r], std::sqrt(d2) / tol);
      }
    }
  }
  return worst;
}

// Turning angle (radians) at the inner points of every grid line of direction d, and the
// grid indices r (0 < r < m - 1) where some line has a kink there (see the header).
std::vector<int> DetectFeatures(const StructuredBlock& block, int d,
                                const ToleranceFitOptions& options) {
  const DirectionView v = ViewOf(block, d);
  const int s = block.spatial_dim();
  const double kPi = 3.14159265358979323846;
  const double absolute = options.feature_angle_degrees * kPi / 180.0;
  const double spike = options.feature_spike_degrees * kPi / 180.0;
  std::vector<bool> feature(v.m, false);
  std::vector<double> angle(v.m, 0.0);
  const double* data = block.coords().data();
  for (int64_t e = 0; e < v.b; ++e) {
    for (int64_t x = 0; x < v.points_a; ++x) {
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
        if (angle[r] >= absolute ||
            (angle[r] >= spike && angle[r] >= options.feature_spike_ratio * neighbours)) {
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

// The knots and pins of one direction: simple knots plus knots of multiplicity order - 1 at
// the feature parameters, whose controls are pinned to the feature points.
struct DirectionKnots {
  int order = 1;
  std::vector<double> interior;  // simple knots, ascending
  std::vector<int> features;     // data indices, ascending
};

absl::StatusOr<KnotVector> BuildKnots(const DirectionKnots& dk, const std::vector<double>& params) {
  std::vector<double> knots(dk.order, 0.0);
  std::vector<double> inner = dk.interior;
  for (int r : dk.features) inner.insert(inner.end(), dk.order - 1, params[r]);
  std::sort(inner.begin(), inner.end());
  knots.insert(knots.end(), inner.begin(), inner.end());
  knots.insert(knots.end(), dk.order, 1.0);
  return KnotVector::Create(dk.order, std::move(knots));
}

std::vector<Pin> FeaturePins(const KnotVector& knots, const std::vector<int>& features,
                             const std::vector<double>& params) {
  std::vector<Pin> pins;
  for (int r : features) {
    pins.push_back({knots.FindSpan(params[r]) - knots.order() + 1, r});
  }
  return pins;
}

bool WellPosed(const DirectionKnots& dk, const std::vector<double>& params) {
  absl::StatusOr<KnotVector> knots = BuildKnots(dk, params);
  if (!knots.ok()) return false;
  const std::vector<Pin> pins = FeaturePins(*knots, dk.features, params);
  std::vector<int> pinned = {0, knots->num_controls() - 1};
  for (const Pin& pin : pins) pinned.push_back(pin.control);
  if (!SchoenbergWhitneyHolds(*knots, params, pinned)) return false;
  // Schoenberg-Whitney is structural; the factorisation also rejects numerically singular
  // configurations (strongly graded knots) that the fit itself would reject.
  return DirectionFit::Create(*knots, params, EndCondition::kInterpolate, pins).ok();
}

// Splits knot spans whose worst ratio exceeds `limit` at the middle of their data (worst span
// first), keeping only splits after which the data still determine every control
// (Schoenberg-Whitney) and at most `max_new` of them. Returns the number of knots added.
int SplitSpans(const std::vector<double>& params, const std::vector<double>& ratio, double limit,
               int max_new, DirectionKnots& dk) {
  std::vector<double> breaks = {0.0};
  breaks.insert(breaks.end(), dk.interior.begin(), dk.interior.end());
  for (int r : dk.features) breaks.push_back(params[r]);
  breaks.push_back(1.0);
  std::sort(breaks.begin(), breaks.end());
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
    dk.interior.insert(std::upper_bound(dk.interior.begin(), dk.interior.end(), knot), knot);
    if (WellPosed(dk, params)) {
      ++added;
    } else {
      dk.interior.erase(std::find(dk.interior.begin(), dk.interior.end(), knot));
    }
  }
  return added;
}

}  // namespace

absl::StatusOr<ToleranceFitResult> FitToTolerance(const StructuredBlock& block,
                                                  std::span<const double> tolerance,
                                                  const ToleranceFitOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const Extents& m = block.extents();
  if (options.order < 2 || options.order > kMaxOrder) {
    return absl::InvalidArgumentError(
        absl::StrCat("order = ", options.order, " is outside [2, ", kMaxOrder, "]"));
  }
  if (options.max_controls_per_direction < 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "max_controls_per_direction = ", options.max_controls_per_direction, " is negative"));
  }
  if (tolerance.size() != 1 && static_cast<int64_t>(tolerance.size()) != block.num_points()) {
    return absl::InvalidArgumentError(absl::StrCat("tolerance: ", tolerance.size(), " values for ",
                                                   block.num_points(),
                                                   " points; give one or one per point"));
  }
  for (size_t p = 0; p < tolerance.size(); ++p) {
    if (!(tolerance[p] > 0.0) || !std::isfinite(tolerance[p])) {
      return absl::InvalidArgumentError(
          absl::StrCat("tolerance", tolerance.size() == 1 ? "" : absl::StrCat("[", p, "]"), " = ",
                       tolerance[p], "; tolerances must be positive and finite"));
    }
  }
  SG_RETURN_IF_ERROR(ValidateFinite(block, "points"));

  const std::array<std::vector<double>, 3> params =
      ParametrizeBlock(block, options.parametrization);
  std::array<int, 3> cap;
  std::array<DirectionKnots, 3> dk;
  std::array<double, 3> share;
  int active = 0;
  for (int d = 0; d < 3; ++d) active += m[d] > 1 ? 1 : 0;
  for (int d = 0; d < 3; ++d) {
    cap[d] = m[d];
    if (options.max_controls_per_direction > 0) {
      cap[d] = std::min(cap[d], std::max(options.max_controls_per_direction, 2));
    }
    dk[d].order = m[d] == 1 ? 1 : std::min(options.order, cap[d]);
    share[d] = 1.0 / std::max(active, 1);
    if (m[d] > 2 && options.detect_features && dk[d].order > 1) {
      for (int r : DetectFeatures(block, d, options)) {
        dk[d].features.push_back(r);
        const int controls =
            static_cast<int>(dk[d].interior.size() + dk[d].features.size() * (dk[d].order - 1)) +
            dk[d].order;
        if (controls > cap[d] || !WellPosed(dk[d], params[d])) dk[d].features.pop_back();
      }
    }
  }
  // Expands tolerance for MeasureDeviation, which wants one value per point.
  std::vector<double> per_point;
  std::span<const double> tol_points = tolerance;
  if (tolerance.size() == 1) {
    per_point.assign(block.num_points(), tolerance[0]);
    tol_points = per_point;
  }
  auto num_controls = [&](int d) {
    return static_cast<int>(dk[d].interior.size() + dk[d].features.size() * (dk[d].order - 1)) +
           dk[d].order;
  };

  ToleranceFitResult result;
  std::array<KnotVector, 3> knots;
  DirectionPins pins;
  auto build_knots = [&]() -> absl::Status {
    for (int d = 0; d < 3; ++d) {
      if (m[d] == 1) continue;
      SG_ASSIGN_OR_RETURN(knots[d], BuildKnots(dk[d], params[d]));
      pins[d] = FeaturePins(knots[d], dk[d].features, params[d]);
    }
    return absl::OkStatus();
  };
  auto fit = [&]() -> absl::StatusOr<std::pair<TensorSpline, Deviation>> {
    SG_RETURN_IF_ERROR(build_knots());
    SG_ASSIGN_OR_RETURN(
        TensorSpline spline,
        FitTensor(block, params, knots, EndCondition::kInterpolate, options.cancel, pins));
    SG_ASSIGN_OR_RETURN(Deviation dev,
                        MeasureDeviation(spline, params, block, options.cancel, tol_points));
    return std::make_pair(std::move(spline), dev);
  };

  SG_ASSIGN_OR_RETURN(auto current, fit());
  for (; current.second.max_ratio > 1.0 && result.iterations < options.max_iterations;
       ++result.iterations) {
    SG_RETURN_IF_ERROR(PollCancel(options.cancel));
    int added = 0;
    bool any_room = false;
    for (int d = 0; d < 3; ++d) {
      if (m[d] == 1 || num_controls(d) >= cap[d]) continue;
      any_room = true;
      SG_ASSIGN_OR_RETURN(std::vector<double> ratio,
                          DirectionResidualRatio(block, d, params[d], knots[d], pins[d], tolerance,
                                                 options.cancel));
      added += SplitSpans(params[d], ratio, share[d], cap[d] - num_controls(d), dk[d]);
    }
    if (!any_room) break;
    if (added == 0) {
      // Every direction meets its share but the combination does not: tighten the shares.
      for (double& sh : share) sh *= 0.6;
      if (share[0] < 1e-6 && share[1] < 1e-6 && share[2] < 1e-6) break;
      continue;
    }
    result.knots_inserted += added;
    SG_ASSIGN_OR_RETURN(current, fit());
  }

  if (current.second.max_ratio <= 1.0 && options.remove_unneeded_knots) {
    for (int d = 0; d < 3; ++d) {
      for (size_t i = 0; i < dk[d].interior.size();) {
        SG_RETURN_IF_ERROR(PollCancel(options.cancel));
        const double knot = dk[d].interior[i];
        dk[d].interior.erase(dk[d].interior.begin() + i);
        absl::StatusOr<std::pair<TensorSpline, Deviation>> trial = fit();
        if (!trial.ok() && trial.status().code() == absl::StatusCode::kCancelled) {
          return trial.status();
        }
        if (trial.ok() && trial->second.max_ratio <= 1.0) {
          current = *std::move(trial);
          ++result.knots_removed;
        } else {
          dk[d].interior.insert(dk[d].interior.begin() + i, knot);
          ++i;
        }
      }
    }
    SG_RETURN_IF_ERROR(build_knots());
  }
  for (int d = 0; d < 3; ++d) result.features[d] = dk[d].features;

  const Deviation& dev = current.second;
  result.met = dev.max_ratio <= 1.0;
  result.worst_ratio = dev.max_ratio;
  result.worst_at = dev.max_ratio_at;
  if (!result.met) {
    const Extents& at = dev.max_ratio_at;
    result.unmet_reason = absl::StrCat(
        "point (", at[0], ", ", at[1], ", ", at[2], ") deviates ", dev.max_ratio,
        " times its tolerance after ", result.iterations, " refinement rounds with ",
        current.first.control_extents()[0], " x ", current.first.control_extents()[1], " x ",
        current.first.control_extents()[2], " control points",
        options.max_controls_per_direction > 0
            ? absl::StrCat(" (cap ", options.max_controls_per_direction, " per direction)")
            : "");
  }
  SG_ASSIGN_OR_RETURN(PointDistribution distribution, PointDistribution::Create(params));
  FitSummary& summary = result.fitted.summary;
  result.fitted.spline = std::move(current.first);
  result.fitted.distribution = std::move(distribution);
  summary.deviation = dev;
  summary.num_points = block.num_points();
  summary.num_control_points = result.fitted.spline.num_control_points();
  summary.compression_ratio = static_cast<double>(summary.num_points) / summary.num_control_points;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace splinegrid
