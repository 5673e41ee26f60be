// FitAirfoil (airfoil_fit.h): options and outline validation, feature points, knot placement
// (insertion, then removal), fairing to tolerance and the assembly of the result. The fits
// themselves are ProfileFitter's (profile_fitter.h), the curvature measures those of
// profile_curvature.h, and the outline's simplicity check FindPolylineCrossing's (polyline.h).
#include "core/fit/airfoil/airfoil_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/fit/airfoil/profile_curvature.h"
#include "core/fit/airfoil/profile_fitter.h"
#include "core/grid/polyline.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

// Fewest points of an outline (as io/airfoil.h reads).
constexpr int kMinPoints = 5;
// Consecutive points closer than this fraction of the outline's bounding-box diagonal repeat.
constexpr double kRepeatRelTol = 1e-12;
// Knot placement screens every candidate knot vector with kScreenCorrections rounds (the
// parameters are warm-started from the previous fit) and converges only candidates that miss
// the target by less than the factor kScreenMargin.
constexpr int kScreenCorrections = 3;
constexpr double kScreenMargin = 1.5;
// Removal passes over the knots (each pass tries every knot once).
constexpr int kRemovalPasses = 3;
// Merges (MergeCandidates) replace two or three neighbouring knots by one fewer: a pair a < b by
// one knot at a + f (b - a) for f = 1/2, 1/3, 2/3; a triple a < b < c by the midpoints of its
// pairs (knot averaging), else by [a, c]'s thirds. Measured on dense_profile_test's 15 fits:
// the pair midpoint alone saved 0-2 controls per fit, the pair thirds 0-1 more (the 30P30N
// main element at 2e-4 chord: 23, 22, 21), the triples 0-1 more (NACA 0012 at 20,000 points
// and 1e-4: 17 -> 16, where 5,000 points resampled need 15), each for ~15-40% more time.
// Coarse to fine (CoarseStart): outlines of at least kCoarseStride * kCoarsePoints points place
// their knots on every kCoarseStride-th point first.
constexpr int kCoarseStride = 4;
constexpr int kCoarsePoints = 500;
// Fairing search: lambda = weight 10^-e for e = 0 .. kFairingDecades, then bisections of the
// last decade on a log scale (a factor 10^(1/16) = 1.15), as the adaptive engine does.
constexpr int kFairingDecades = 14;
constexpr int kFairingBisections = 4;
// A feature point turns by at least this multiple of its neighbours' turning (OutlineFeatures).
constexpr double kKinkRatio = 2.0;
// A fit whose curvature exceeds this multiple of the reference's largest has a cusp or a tiny
// loop that the distances cannot see (parameter correction can bunch parameters until the
// speed |C'| nearly vanishes); it is not accepted.
constexpr double kCurvatureGuard = 2.0;

// The largest |kappa| d of a foot taken by parameter correction when the unrestricted knot
// placement failed (ProfileFitter::set_max_focal_ratio): a point moves to its foot only while
// the feet there crowd by at most 1 / (1 + 1/2), i.e. it is nearer to the curve than half the
// radius of curvature. Measured on dense_profile_test's cases with the restriction always on:
// 0.5 fitted all of them, 4 still left a densified RAE 2822 with a cusp.
constexpr double kMaxFocalRatio = 0.5;

// Candidate knots to replace the neighbouring knots `window` (2 or 3 of them) by one fewer,
// best first (the merge rule above).
std::vector<std::vector<double>> MergeCandidates(std::span<const double> window) {
  if (window.size() == 2) {
    const double a = window[0], b = window[1];
    return {{a + (b - a) / 2.0}, {a + (b - a) / 3.0}, {a + 2.0 * (b - a) / 3.0}};
  }
  const double a = window[0], b = window[1], c = window[2];
  return {{(a + b) / 2.0, (b + c) / 2.0}, {a + (c - a) / 3.0, a + 2.0 * (c - a) / 3.0}};
}

// |J_q| of `curve` at its simple interior knots, in knot order: the scaled jumps of the third
// derivative (fairing.h, ScaledDerivativeJumps) of both coordinates.
std::vector<double> JumpMagnitudes(const Curve& curve) {
  const size_t n = curve.control.size() / 2;
  std::vector<double> x(n), y(n);
  for (size_t j = 0; j < n; ++j) x[j] = curve.control[2 * j], y[j] = curve.control[2 * j + 1];
  const std::vector<double> jx = ScaledDerivativeJumps(curve.knots, x);
  const std::vector<double> jy = ScaledDerivativeJumps(curve.knots, y);
  std::vector<double> jump(jx.size());
  for (size_t q = 0; q < jx.size(); ++q) jump[q] = std::hypot(jx[q], jy[q]);
  return jump;
}

// Row factors that cap every jump row of `curve`'s knots at the median jump: the row of a knot
// whose unfaired jump |J_q| exceeds the median M is scaled by M / |J_q|. The nose needs jumps a
// hundred times the others; with equal weights its rows would bind the tolerance long before
// the surfaces are faired.
std::vector<double> MedianCappedScales(const Curve& curve) {
  const std::vector<double> jump = JumpMagnitudes(curve);
  if (jump.empty()) return {};
  std::vector<double> sorted = jump;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median = sorted[sorted.size() / 2];
  std::vector<double> scale(jump.size(), 1.0);
  for (size_t q = 0; q < jump.size(); ++q) {
    if (jump[q] > median) scale[q] = median / jump[q];
  }
  return scale;
}

// File comment, step 5: the largest lambda <= weight whose fit is within `tolerance` and
// `accept`ed, or `unfaired` (lambda 0) when none is. Trials are screened (kScreenCorrections).
absl::StatusOr<Fitted> FairToTolerance(ProfileFitter& fitter, const std::vector<double>& interior,
                                       const Fitted& unfaired, double weight, double tolerance,
                                       const std::function<bool(const Fitted&)>& accept) {
  Penalty penalty{0.0, MedianCappedScales(unfaired.curve)};
  std::optional<Fitted> good;
  double bad = 0.0;
  auto try_lambda = [&](double lambda) -> absl::StatusOr<bool> {
    penalty.lambda = lambda;
    absl::StatusOr<Fitted> fit =
        FitAndMeasure(fitter, interior, penalty, unfaired.params, kScreenCorrections);
    if (fit.ok() && fit->max() <= kScreenMargin * tolerance) {
      fit = FitAndMeasure(fitter, interior, penalty, fit->params);
    }
    if (fit.status().code() == absl::StatusCode::kCancelled) return fit.status();
    if (!fit.ok() || !(fit->max() <= tolerance) || !accept(*fit)) return false;
    good = *std::move(fit);
    return true;
  };
  for (int e = 0; e <= kFairingDecades; ++e) {
    const double lambda = weight * std::pow(10.0, -e);
    SG_ASSIGN_OR_RETURN(const bool ok, try_lambda(lambda));
    if (ok) break;
    bad = lambda;
  }
  if (!good) return unfaired;
  for (int step = 0; bad > 0.0 && step < kFairingBisections; ++step) {
    const double mid = std::sqrt(good->lambda * bad);
    SG_ASSIGN_OR_RETURN(const bool ok, try_lambda(mid));
    if (!ok) bad = mid;
  }
  return *std::move(good);
}

// Checks the outline: a curve block of >= kMinPoints finite 2D points, none repeating its
// predecessor.
absl::Status ValidateOutline(const StructuredBlock& points) {
  const Extents& e = points.extents();
  if (e[1] != 1 || e[2] != 1) {
    return absl::InvalidArgumentError(absl::StrCat("points extents = (", e[0], ", ", e[1], ", ",
                                                   e[2], "): an outline is n x 1 x 1"));
  }
  if (points.spatial_dim() != 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("points spatial_dim = ", points.spatial_dim(), ": an outline is planar (2)"));
  }
  if (e[0] < kMinPoints) {
    return absl::InvalidArgumentError(
        absl::StrCat("points: ", e[0], " points, an outline needs at least ", kMinPoints));
  }
  SG_RETURN_IF_ERROR(ValidateFinite(points, "points"));
  const std::span<const double> xy = points.coords();
  double x0 = xy[0], x1 = xy[0], y0 = xy[1], y1 = xy[1];
  for (int i = 0; i < e[0]; ++i) {
    x0 = std::min(x0, xy[2 * i]), x1 = std::max(x1, xy[2 * i]);
    y0 = std::min(y0, xy[2 * i + 1]), y1 = std::max(y1, xy[2 * i + 1]);
  }
  const double repeat = kRepeatRelTol * std::hypot(x1 - x0, y1 - y0);
  for (int i = 1; i < e[0]; ++i) {
    if (std::hypot(xy[2 * i] - xy[2 * i - 2], xy[2 * i + 1] - xy[2 * i - 1]) <= repeat) {
      return absl::InvalidArgumentError(absl::StrCat("points: point ", i, " at (", xy[2 * i], ", ",
                                                     xy[2 * i + 1], ") repeats point ", i - 1));
    }
  }
  return absl::OkStatus();
}

// Feature points: those of DetectFeatures that are kinks, turning by at least kKinkRatio times
// as much as both neighbours (a tangent discontinuity stands out; a tight but smooth bend
// sampled coarsely, like a nose, turns by about as much at the neighbours), never the leading
// edge, and only where both neighbouring segments keep order - 2 data points strictly inside
// (what the order - 2 free controls of a segment without interior knots need).
//
// The turning is measured at the length scale of the tolerance, not between neighbouring
// segments: on a dense noisy outline (the file's spacing refined a hundredfold puts points 1e-6
// chord apart at the nose, as close as 1e-6 chord noise) neighbouring segments turn by tens of
// degrees at random, and every such point that DetectFeatures reports and that turns twice as
// much as its neighbours would become a C0 knot (RAE 2822 at 12k points: 1-3 false features,
// up to 26 controls against 17). For a kink angle theta and the fit's tolerance tol, let
//   L(theta) = 8 tol / theta,
// and T_L(r) be the angle between the chords p(a) -> p(r) and p(r) -> p(b), a and b the nearest
// points at least L before and after r along the polyline (or its ends). Why L:
//  - Noise: data anywhere within the tolerance band of a smooth curve move each chord end by at
//    most tol across it, so a chord of length >= L turns by at most 2 tol / L and T_L by at
//    most 4 tol / L = theta / 2: what the fit absorbs anyway cannot turn by theta over L.
//  - Fillet: a kink of angle theta is rounded within tol by a circular fillet of radius R with
//    R (1 / cos(theta / 2) - 1) ~ R theta^2 / 8 = tol, whose arc length R theta is L: over
//    chords of length L the kink turns by theta, the smooth curve by about its curvature * L.
// A point is a kink at angle theta when T_L(r) >= theta, T_L(r) >= kKinkRatio * max(T_L(a),
// T_L(b)) (the neighbours L away, as the neighbouring points were), T_L(r) is the largest
// turning of the points of [a, b] (one kink, not every point whose chords straddle it), and r
// is at least L along the outline from the leading edge (whose chords would measure the nose).
// The angles tried are theta = spike_degrees * 2^j <= 180 degrees: the largest L is that of the
// smallest kink of interest, and larger kinks are also looked at on their own, shorter scale
// (two cove corners 0.06 chord apart each see the other within 8 tol / 4 degrees at 5e-4
// chord). A candidate that is a kink at one of these angles is a feature. Where the points are
// at least L apart, a = r - 1 and b = r + 1 and the test is the one between neighbouring
// segments that coarse outlines have always had (with theta <= the point's turning).
std::vector<int> OutlineFeatures(const StructuredBlock& points, const FeatureOptions& options,
                                 int leading_edge, int order, double tolerance) {
  const int m = static_cast<int>(points.num_points());
  const double spike = options.spike_degrees * std::numbers::pi / 180.0;
  std::vector<double> arc(m, 0.0);  // arc length of the polyline at each point
  for (int i = 1; i < m; ++i) {
    const double *p = points.Point(i - 1, 0, 0), *q = points.Point(i, 0, 0);
    arc[i] = arc[i - 1] + std::hypot(q[0] - p[0], q[1] - p[1]);
  }
  // One scale: the angle theta, L, and per point a, b and T_L.
  struct Scale {
    double theta = 0.0, length = 0.0;
    std::vector<int> before, after;
    std::vector<double> turning;
  };
  std::vector<Scale> scales;
  for (double theta = spike; theta > 0.0 && theta <= std::numbers::pi; theta *= 2.0) {
    Scale& scale = scales.emplace_back();
    scale.theta = theta, scale.length = 8.0 * tolerance / theta;
    scale.before.resize(m), scale.after.resize(m), scale.turning.assign(m, 0.0);
    for (int r = 0; r < m; ++r) {
      const auto lo = std::upper_bound(arc.begin(), arc.end(), arc[r] - scale.length);
      const auto hi = std::lower_bound(arc.begin(), arc.end(), arc[r] + scale.length);
      scale.before[r] = std::max(0, std::min(r - 1, static_cast<int>(lo - arc.begin()) - 1));
      scale.after[r] = std::min(m - 1, std::max(r + 1, static_cast<int>(hi - arc.begin())));
      if (r == 0 || r == m - 1) continue;
      const double *a = points.Point(scale.before[r], 0, 0), *b = points.Point(r, 0, 0),
                   *c = points.Point(scale.after[r], 0, 0);
      const double ux = b[0] - a[0], uy = b[1] - a[1], vx = c[0] - b[0], vy = c[1] - b[1];
      scale.turning[r] = std::abs(std::atan2(ux * vy - uy * vx, ux * vx + uy * vy));
    }
  }
  auto kink = [&](const Scale& scale, int r) {
    if (std::abs(arc[r] - arc[leading_edge]) < scale.length) return false;
    const int a = scale.before[r], b = scale.after[r];
    const double t = scale.turning[r];
    if (t < scale.theta || t < kKinkRatio * std::max(scale.turning[a], scale.turning[b])) {
      return false;
    }
    return *std::max_element(scale.turning.begin() + a, scale.turning.begin() + b + 1) <= t;
  };
  std::vector<int> kept;
  for (int r : DetectFeatures(points, 0, options)) {
    const int previous = kept.empty() ? 0 : kept.back();
    if (r == leading_edge || r - previous < order - 1 || m - 1 - r < order - 1) continue;
    if (std::any_of(scales.begin(), scales.end(), [&](const Scale& s) { return kink(s, r); })) {
      kept.push_back(r);
    }
  }
  return kept;
}

// Interior knots of the reference: the anchors' knots and a knot at every second data point
// of each segment (at least two data points per span).
std::vector<double> ReferenceKnots(const std::vector<int>& anchors,
                                   const std::vector<double>& params, int order) {
  std::vector<double> interior;
  for (size_t a = 0; a + 1 < anchors.size(); ++a) {
    if (a > 0) interior.insert(interior.end(), order - 1, params[anchors[a]]);
    for (int r = anchors[a] + 2; r + 1 < anchors[a + 1]; r += 2) interior.push_back(params[r]);
  }
  return interior;
}

// What knot placement (steps 3 and 4) found.
struct Placement {
  std::vector<double> interior;
  Fitted fitted;
  int inserted = 0;
  int removed = 0;
  std::string stop;  // why the target was not met; empty when it was
};

// Steps 3 and 4 from the knots `interior` and parameters `params`: insertion until every
// distance is within `target` and the curve has no cusp (`cusp` gives the parameter of one),
// at most `cap` controls; then removal and merges. Knot vectors are screened
// (kScreenCorrections).
absl::StatusOr<Placement> PlaceKnots(
    ProfileFitter& fitter, std::vector<double> interior, const std::vector<double>& params,
    double target, int cap, bool remove,
    const std::function<std::optional<double>(const Fitted&)>& cusp) {
  const int m = static_cast<int>(params.size());
  auto screen = [&](const std::vector<double>& knots,
                    const std::vector<double>& start) -> absl::StatusOr<Fitted> {
    SG_ASSIGN_OR_RETURN(Fitted fit, FitAndMeasure(fitter, knots, {}, start, kScreenCorrections));
    if (fit.max() <= target || fit.max() > kScreenMargin * target) return fit;
    return FitAndMeasure(fitter, knots, {}, fit.params);
  };
  Placement out;
  out.interior = std::move(interior);
  SG_ASSIGN_OR_RETURN(out.fitted, screen(out.interior, params));
  for (;;) {
    std::vector<double> ratio(m);
    for (int i = 0; i < m; ++i) ratio[i] = out.fitted.distances[i] / target;
    if (out.fitted.max() <= target) {
      const std::optional<double> at = cusp(out.fitted);
      if (!at) break;
      // Split the span of the cusp: mark the data points around it as twice out.
      const auto it = std::lower_bound(out.fitted.params.begin(), out.fitted.params.end(), *at);
      const int r = static_cast<int>(it - out.fitted.params.begin());
      for (int i = std::max(r - 1, 0); i <= std::min(r, m - 1); ++i) ratio[i] = 2.0;
    }
    const int n = fitter.NumControls(out.interior);
    if (n >= cap) {
      out.stop = absl::StrCat("the control-point cap ", cap, " is reached");
      break;
    }
    const std::vector<double>& at = out.fitted.params;
    if (SplitSpans(at, ratio, 1.0, 1, out.interior,
                   [&] { return fitter.WellPosed(out.interior, at); }) == 0) {
      out.stop = "no knot span with data left to split";
      break;
    }
    ++out.inserted;
    SG_ASSIGN_OR_RETURN(out.fitted, screen(out.interior, out.fitted.params));
  }
  // Removal and merges keep a trial knot vector when its fit meets the target without a cusp.
  auto simple = [](const std::vector<double>& knots, double t) {
    return std::count(knots.begin(), knots.end(), t) == 1;
  };
  auto keep_if_met = [&](std::vector<double> trial) -> absl::StatusOr<bool> {
    if (!fitter.WellPosed(trial, out.fitted.params)) return false;
    absl::StatusOr<Fitted> fit = screen(trial, out.fitted.params);
    if (fit.status().code() == absl::StatusCode::kCancelled) return fit.status();
    if (!fit.ok() || !(fit->max() <= target) || cusp(*fit)) return false;
    out.interior = std::move(trial);
    out.fitted = *std::move(fit);
    return true;
  };
  for (int pass = 0; remove && out.stop.empty() && pass < kRemovalPasses; ++pass) {
    // Candidates: the simple knots, smallest third-derivative jump |J_q| first.
    const std::vector<double> jump = JumpMagnitudes(out.fitted.curve);
    std::vector<std::pair<double, double>> candidates;  // (|J_q|, knot)
    for (size_t q = 0, i = 0; i < out.interior.size(); ++i) {
      if (simple(out.interior, out.interior[i])) candidates.push_back({jump[q++], out.interior[i]});
    }
    std::sort(candidates.begin(), candidates.end());
    int removed = 0;
    for (const auto& [jump, knot] : candidates) {
      std::vector<double> trial = out.interior;
      trial.erase(std::find(trial.begin(), trial.end(), knot));
      SG_ASSIGN_OR_RETURN(const bool kept, keep_if_met(std::move(trial)));
      removed += kept;
    }
    out.removed += removed;
    if (removed == 0) break;
  }
  // Merges: neighbouring simple knots replaced by one fewer (MergeCandidates), pairs until a
  // sweep keeps none, then triples likewise.
  for (int width : {2, 3}) {
    for (bool merged = remove && out.stop.empty(); merged;) {
      merged = false;
      for (size_t i = 0; i + width <= out.interior.size(); ++i) {
        const std::span<const double> window(out.interior.data() + i, width);
        if (!std::all_of(window.begin(), window.end(),
                         [&](double t) { return simple(out.interior, t); })) {
          continue;
        }
        for (const std::vector<double>& fewer : MergeCandidates(window)) {
          std::vector<double> trial = out.interior;
          trial.erase(trial.begin() + i, trial.begin() + i + width);
          trial.insert(trial.begin() + i, fewer.begin(), fewer.end());
          SG_ASSIGN_OR_RETURN(const bool kept, keep_if_met(std::move(trial)));
          if (kept) {
            ++out.removed, merged = true;
            break;
          }
        }
      }
    }
  }
  return out;
}

// Where knot placement starts: interior knots and a parameter per data point, and what the
// coarser placements that led there did.
struct Start {
  std::vector<double> interior;
  std::vector<double> params;
  int inserted = 0;
  int removed = 0;
  int fits = 0;  // least-squares solves
};

// PlaceKnots from `start`; when that runs out of splits or controls, again from `scratch` with
// parameter correction restricted to regular feet. When Hoschek's correction crowded the feet of
// a dense outline into a bend of an early, too coarse fit (profile_fitter.h, "Focal points"),
// spans were left without data and looped; the restriction (|kappa| d <= kMaxFocalRatio) avoids
// that. The second placement is kept when it meets the target, and `fitter` then stays
// restricted; else the first stands, with its reason.
absl::StatusOr<Placement> Place(ProfileFitter& fitter, const Start& start, const Start& scratch,
                                double target, int cap, bool remove,
                                const std::function<std::optional<double>(const Fitted&)>& cusp) {
  SG_ASSIGN_OR_RETURN(Placement placed,
                      PlaceKnots(fitter, start.interior, start.params, target, cap, remove, cusp));
  placed.inserted += start.inserted;
  placed.removed += start.removed;
  if (placed.stop.empty()) return placed;
  fitter.set_max_focal_ratio(kMaxFocalRatio);
  SG_ASSIGN_OR_RETURN(Placement regular, PlaceKnots(fitter, scratch.interior, scratch.params,
                                                    target, cap, remove, cusp));
  if (regular.stop.empty()) return regular;
  fitter.set_max_focal_ratio(std::numeric_limits<double>::infinity());
  return placed;
}

// Coarse to fine (file comment, step 3): the knots and parameters that placement ends with on
// every kCoarseStride-th point (the anchors kept), itself started coarse to fine, with the
// parameters carried to the points in between linearly in chord length; `initial` when the
// outline has fewer than kCoarseStride * kCoarsePoints points or the coarse placement fails.
// `fit_data`, `data` and `features` as ProfileFitter takes them; `cusp_at(fitter, fit)` is the
// cusp test of a fit by `fitter`.
absl::StatusOr<Start> CoarseStart(
    const std::vector<double>& fit_data, const std::vector<double>& data,
    const std::vector<int>& features, Start initial, double target, int cap,
    const AirfoilFitOptions& options,
    const std::function<std::optional<double>(const ProfileFitter&, const Fitted&)>& cusp_at) {
  const int m = static_cast<int>(initial.params.size());
  if (m < kCoarseStride * kCoarsePoints) return initial;
  std::vector<int> keep;  // data indices of the coarse outline, ascending, anchors included
  for (int i = 0; i < m; i += kCoarseStride) keep.push_back(i);
  keep.push_back(m - 1);
  keep.insert(keep.end(), features.begin(), features.end());
  std::sort(keep.begin(), keep.end());
  keep.erase(std::unique(keep.begin(), keep.end()), keep.end());
  const int n = static_cast<int>(keep.size());
  std::vector<double> coarse_fit_data(2 * n), coarse_data(2 * n);
  Start coarse{initial.interior, std::vector<double>(n)};
  for (int j = 0; j < n; ++j) {
    for (int c = 0; c < 2; ++c) {
      coarse_fit_data[2 * j + c] = fit_data[2 * keep[j] + c];
      coarse_data[2 * j + c] = data[2 * keep[j] + c];
    }
    coarse.params[j] = initial.params[keep[j]];
  }
  std::vector<int> coarse_features;
  for (int r : features) {
    coarse_features.push_back(
        static_cast<int>(std::lower_bound(keep.begin(), keep.end(), r) - keep.begin()));
  }
  SG_ASSIGN_OR_RETURN(const Start start,
                      CoarseStart(coarse_fit_data, coarse_data, coarse_features, coarse, target,
                                  std::min(cap, n), options, cusp_at));
  ProfileFitter fitter(std::move(coarse_fit_data), std::move(coarse_data), options.order,
                       coarse_features, options.max_parameter_corrections, options.cancel);
  // Every 4th point can leave a segment between close anchors with too few points for its
  // controls: then, and whenever the coarse placement fails, the outline starts from scratch.
  if (!fitter.WellPosed(coarse.interior, coarse.params)) return initial;
  absl::StatusOr<Placement> placed =
      Place(fitter, start, coarse, target, std::min(cap, n), options.remove_knots,
            [&](const Fitted& fit) { return cusp_at(fitter, fit); });
  if (placed.status().code() == absl::StatusCode::kCancelled) return placed.status();
  if (!placed.ok() || !placed->stop.empty()) {
    initial.fits += fitter.fits() + start.fits;
    return initial;
  }
  Start out{placed->interior, std::vector<double>(m), placed->inserted, placed->removed,
            fitter.fits() + start.fits};
  for (int j = 0; j + 1 < n; ++j) {
    const int a = keep[j], b = keep[j + 1];
    const double ua = placed->fitted.params[j], ub = placed->fitted.params[j + 1];
    std::vector<double> arc(b - a + 1, 0.0);
    for (int i = a + 1; i <= b; ++i) {
      arc[i - a] = arc[i - a - 1] + std::hypot(fit_data[2 * i] - fit_data[2 * i - 2],
                                               fit_data[2 * i + 1] - fit_data[2 * i - 1]);
    }
    for (int i = a; i < b; ++i) {
      // Coincident kept points (a merged sharp trailing edge): spaced by index instead.
      const double share = arc.back() > 0.0 ? arc[i - a] / arc.back() : (i - a) / double(b - a);
      out.params[i] = ua + (ub - ua) * share;
    }
  }
  out.params[m - 1] = placed->fitted.params[n - 1];
  return out;
}

// Trailing edge: ends within the tolerance are one point (a sharp trailing edge).
bool SharpTrailingEdge(const std::vector<double>& data, double tolerance) {
  const size_t m = data.size() / 2;
  const double gap = std::hypot(data[0] - data[2 * m - 2], data[1] - data[2 * m - 1]);
  return gap <= tolerance;
}

// The data the curve is fitted to: `data` with the ends of a sharp trailing edge merged into
// their midpoint.
std::vector<double> MergeTrailingEdge(const std::vector<double>& data, bool sharp) {
  const size_t m = data.size() / 2;
  std::vector<double> fit_data = data;
  if (sharp) {
    for (int c = 0; c < 2; ++c) {
      fit_data[c] = fit_data[2 * m - 2 + c] = 0.5 * (data[c] + data[2 * m - 2 + c]);
    }
  }
  return fit_data;
}

// INVALID_ARGUMENT naming the segments when the outline `fit_data` (closed when `sharp`)
// crosses itself.
absl::Status CheckSimpleOutline(const std::vector<double>& fit_data, bool sharp) {
  if (const std::optional<PolylineCrossing> crossing = FindPolylineCrossing(fit_data, sharp)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "points: the outline crosses itself: segment ", crossing->first, "-", crossing->first + 1,
        " meets segment ", crossing->second, "-", crossing->second + 1,
        " (points must go once around the profile, in Selig order)"));
  }
  return absl::OkStatus();
}

// Leading edge: the point of `data` farthest from the trailing-edge midpoint of `fit_data`.
int LeadingEdge(const std::vector<double>& data, const std::vector<double>& fit_data) {
  const int m = static_cast<int>(data.size() / 2);
  const double te_x = 0.5 * (fit_data[0] + fit_data[2 * m - 2]);
  const double te_y = 0.5 * (fit_data[1] + fit_data[2 * m - 1]);
  double farthest = -1.0;
  int leading_edge = 0;
  for (int i = 0; i < m; ++i) {
    const double d = std::hypot(data[2 * i] - te_x, data[2 * i + 1] - te_y);
    if (d > farthest) farthest = d, leading_edge = i;
  }
  return leading_edge;
}

// The most control points of a fit of m points (`max_control_points`, 0: m); INVALID_ARGUMENT
// when that is below what order k and the feature points need.
absl::StatusOr<int> ControlCap(int m, int k, size_t num_features, int max_control_points) {
  const int min_controls = k + static_cast<int>(num_features) * (k - 1);
  const int cap = max_control_points == 0 ? m : std::min(max_control_points, m);
  if (cap < min_controls) {
    const std::string need = absl::StrCat("order ", k, " and ", num_features,
                                          " feature points need at least ", min_controls);
    return absl::InvalidArgumentError(
        cap < m ? absl::StrCat("max_control_points = ", cap, ": ", need)
                : absl::StrCat("points: ", m, " points are too few, ", need, " controls"));
  }
  return cap;
}

// The parameters of the outline `points` with the coordinates `fit_data` (merged trailing
// edge).
std::vector<double> OutlineParameters(const StructuredBlock& points,
                                      const std::vector<double>& fit_data,
                                      Parametrization parametrization) {
  StructuredBlock work = points;
  std::copy(fit_data.begin(), fit_data.end(), work.coords().begin());
  return ParametrizeBlock(work, parametrization)[0];
}

// The reference (file comment): the fairest curve within the tolerance, and its largest
// curvature, which bounds every accepted fit's (kCurvatureGuard). Too few points for its knots
// (high orders on tiny outlines): no reference, every extremum counts as spurious. Sets
// result.reference_curvature; returns the curvature limit (infinite without a reference).
absl::StatusOr<double> FitReference(ProfileFitter& fitter, const std::vector<double>& params,
                                    const AirfoilFitOptions& options, AirfoilFit& result) {
  const int m = static_cast<int>(params.size());
  const std::vector<int>& anchors = fitter.anchors();
  const std::vector<double> dense_knots = ReferenceKnots(anchors, params, options.order);
  if (fitter.NumControls(dense_knots) > m || !fitter.WellPosed(dense_knots, params)) {
    return std::numeric_limits<double>::infinity();
  }
  SG_ASSIGN_OR_RETURN(const Fitted dense, FitAndMeasure(fitter, dense_knots, {}, params));
  SG_ASSIGN_OR_RETURN(const Fitted reference,
                      FairToTolerance(fitter, dense_knots, dense, options.fairing.weight,
                                      options.tolerance, [](const Fitted&) { return true; }));
  result.reference_curvature =
      MeasureCurvature(reference, anchors, result.leading_edge, options.curvature_level);
  CountSpurious(result.reference_curvature, result.reference_curvature);
  return kCurvatureGuard * result.reference_curvature.total.max_abs_curvature;
}

// The placed fit `fitted` converged (parameter correction to the end) at knots `interior`: the
// converged fit when it is within `target` without a cusp, or when placement stopped short
// (`stop` not empty); else `fitted`.
absl::StatusOr<Fitted> Converged(ProfileFitter& fitter, const std::vector<double>& interior,
                                 Fitted fitted, const std::string& stop, double target,
                                 const std::function<std::optional<double>(const Fitted&)>& cusp) {
  SG_ASSIGN_OR_RETURN(Fitted converged, FitAndMeasure(fitter, interior, {}, fitted.params));
  if (!stop.empty() || (converged.max() <= target && !cusp(converged))) return converged;
  return fitted;
}

// Step 5: fairing of `fitted` (to tolerance when `to_tolerance`, else with the fixed weight of
// FairingMode::kWeight, else none). A faired curve must also be no less fair than the unfaired
// one by the measures reported: squared curvature differences and spurious extrema. Sets the
// unfaired and final curvature of `result`.
absl::StatusOr<Fitted> Fair(ProfileFitter& fitter, const std::vector<double>& interior,
                            Fitted fitted, bool to_tolerance, double curvature_limit,
                            const AirfoilFitOptions& options, AirfoilFit& result) {
  const std::vector<int>& anchors = fitter.anchors();
  const int level = options.curvature_level;
  result.unfaired_curvature = MeasureCurvature(fitted, anchors, result.leading_edge, level);
  CountSpurious(result.reference_curvature, result.unfaired_curvature);
  if (to_tolerance) {
    const ProfileCurvature& before = result.unfaired_curvature;
    auto fairer = [&](const Fitted& fit) {
      ProfileCurvature c = MeasureCurvature(fit, anchors, result.leading_edge, level);
      CountSpurious(result.reference_curvature, c);
      return c.total.max_abs_curvature <= curvature_limit &&
             c.total.sum_squared_differences <= before.total.sum_squared_differences &&
             c.spurious() <= before.spurious();
    };
    SG_ASSIGN_OR_RETURN(fitted, FairToTolerance(fitter, interior, fitted, options.fairing.weight,
                                                options.tolerance, fairer));
  } else if (options.fairing.mode == FairingMode::kWeight) {
    SG_ASSIGN_OR_RETURN(
        fitted,
        FitAndMeasure(fitter, interior, {options.fairing.weight, MedianCappedScales(fitted.curve)},
                      fitted.params));
  }
  result.curvature = MeasureCurvature(fitted, anchors, result.leading_edge, level);
  CountSpurious(result.reference_curvature, result.curvature);
  return fitted;
}

// Why `result` (its fields set by Assemble) is not met: the cusp or the worst point of `data`,
// and the control points with the fixed fairing weight or the placement's `stop`.
std::string UnmetReason(const AirfoilFit& result, const std::vector<double>& data, double tolerance,
                        double curvature_limit, const std::string& stop) {
  const int w = result.worst_point;
  const double peak = result.curvature.total.max_abs_curvature;
  std::string reason =
      result.max_deviation <= tolerance
          ? absl::StrCat("the curve has a cusp: curvature ", peak, " exceeds ", kCurvatureGuard,
                         " times the reference's ", curvature_limit / kCurvatureGuard)
          : absl::StrCat("point ", w, " at (", data[2 * w], ", ", data[2 * w + 1], ") is ",
                         result.max_deviation, " from the curve, over the tolerance ", tolerance);
  absl::StrAppend(
      &reason, " with ", result.num_control_points, " control points: ",
      stop.empty() ? absl::StrCat("the fixed fairing weight ", result.fairing_weight) : stop);
  return reason;
}

// The result from the final fit: the curve, its distances and worst point, and whether the
// tolerance and the curvature limit are met (else why not).
absl::Status Assemble(Fitted fitted, const std::vector<double>& data, double tolerance,
                      double curvature_limit, const std::string& stop, AirfoilFit& result) {
  SG_ASSIGN_OR_RETURN(result.curve,
                      TensorSpline::Create({fitted.curve.knots, KnotVector(), KnotVector()}, 2,
                                           fitted.curve.control));
  result.num_control_points = fitted.curve.knots.num_controls();
  result.fairing_weight = fitted.lambda;
  result.params = std::move(fitted.feet);
  result.distances = std::move(fitted.distances);
  result.worst_point =
      static_cast<int>(std::max_element(result.distances.begin(), result.distances.end()) -
                       result.distances.begin());
  result.max_deviation = result.distances[result.worst_point];
  const double peak = result.curvature.total.max_abs_curvature;
  result.met = result.max_deviation <= tolerance && peak <= curvature_limit;
  if (!result.met) {
    result.unmet_reason = UnmetReason(result, data, tolerance, curvature_limit, stop);
  }
  return absl::OkStatus();
}

}  // namespace

int64_t ProfileCurvature::spurious() const {
  return std::accumulate(spurious_extrema.begin(), spurious_extrema.end(), int64_t{0});
}

absl::Status AirfoilFitOptions::Validate() const {
  auto bad = [](const char* field, auto value, const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat(field, " = ", value, ": ", why));
  };
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) {
    return bad("tolerance", tolerance, "must be a positive finite length");
  }
  if (order < 3 || order > kMaxOrder) {
    return bad("order", order, absl::StrCat("must be in [3, ", kMaxOrder, "]"));
  }
  if (max_control_points != 0 && max_control_points < order) {
    return bad("max_control_points", max_control_points, "must be 0 (no cap) or >= order");
  }
  if (max_parameter_corrections < 0) {
    return bad("max_parameter_corrections", max_parameter_corrections, "must be >= 0");
  }
  SG_RETURN_IF_ERROR(fairing.Validate());
  if (!(fairing_headroom > 0.0 && fairing_headroom <= 1.0)) {
    return bad("fairing_headroom", fairing_headroom, "must be in (0, 1]");
  }
  if (curvature_level < 0 || curvature_level > 6) {
    return bad("curvature_level", curvature_level, "must be in [0, 6]");
  }
  return absl::OkStatus();
}

absl::StatusOr<AirfoilFit> FitAirfoil(const StructuredBlock& points,
                                      const AirfoilFitOptions& options) {
  SG_RETURN_IF_ERROR(options.Validate());
  SG_RETURN_IF_ERROR(ValidateOutline(points));
  const int m = static_cast<int>(points.num_points());
  const int k = options.order;
  const double tolerance = options.tolerance;
  const int level = options.curvature_level;
  const std::vector<double> data(points.coords().begin(), points.coords().end());
  AirfoilFit result;

  result.sharp_trailing_edge = SharpTrailingEdge(data, tolerance);
  const std::vector<double> fit_data = MergeTrailingEdge(data, result.sharp_trailing_edge);
  SG_RETURN_IF_ERROR(CheckSimpleOutline(fit_data, result.sharp_trailing_edge));
  result.leading_edge = LeadingEdge(data, fit_data);
  result.features = OutlineFeatures(points, options.features, result.leading_edge, k, tolerance);
  SG_ASSIGN_OR_RETURN(const int cap,
                      ControlCap(m, k, result.features.size(), options.max_control_points));

  const std::vector<double> params = OutlineParameters(points, fit_data, options.parametrization);
  ProfileFitter fitter(fit_data, data, k, result.features, options.max_parameter_corrections,
                       options.cancel);
  std::vector<double> interior;
  for (int r : result.features) interior.insert(interior.end(), k - 1, params[r]);
  SG_ASSIGN_OR_RETURN(const double curvature_limit, FitReference(fitter, params, options, result));
  auto cusp_at = [&](const ProfileFitter& by, const Fitted& fit) -> std::optional<double> {
    const auto [kappa, u] = CurvaturePeak(fit, by.anchors(), level);
    if (kappa > curvature_limit) return u;
    return std::nullopt;
  };
  auto cusp = [&](const Fitted& fit) { return cusp_at(fitter, fit); };

  // Steps 3 and 4 (coarse to fine), then the unfaired fit converged.
  const bool fair_to_tolerance = options.fairing.mode == FairingMode::kToTolerance;
  const double target = tolerance * (fair_to_tolerance ? options.fairing_headroom : 1.0);
  const Start scratch{interior, params};
  SG_ASSIGN_OR_RETURN(const Start start, CoarseStart(fit_data, data, result.features, scratch,
                                                     target, cap, options, cusp_at));
  SG_ASSIGN_OR_RETURN(Placement placed,
                      Place(fitter, start, scratch, target, cap, options.remove_knots, cusp));
  result.knots_inserted = placed.inserted;
  result.knots_removed = placed.removed;
  interior = std::move(placed.interior);
  SG_ASSIGN_OR_RETURN(Fitted fitted, Converged(fitter, interior, std::move(placed.fitted),
                                               placed.stop, target, cusp));

  SG_ASSIGN_OR_RETURN(
      fitted, Fair(fitter, interior, std::move(fitted), fair_to_tolerance && placed.stop.empty(),
                   curvature_limit, options, result));
  result.fits = fitter.fits() + start.fits;
  SG_RETURN_IF_ERROR(
      Assemble(std::move(fitted), data, tolerance, curvature_limit, placed.stop, result));
  return result;
}

}  // namespace splinegrid
