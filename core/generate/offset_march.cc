#include "core/generate/offset_march.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/bspline/evaluation.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/generate/concave_fill.h"
#include "core/generate/loop_geometry.h"
#include "core/grid/polyline.h"
#include "core/grid/sampling.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

// Samples per point of a refitted piece, for its arc length.
constexpr int kArcSamples = 8;
// A corner of the wall stays a corner of a layer while the layer turns there by at least this.
constexpr double kCornerDegrees = 15.0;

// One Jacobi sweep of normal smoothing: every normal but the corners' becomes the normalised
// weighted mean (1, 2, 1) of itself and its neighbours along the loop.
void SmoothNormals(std::vector<Point2>& normals, const std::vector<bool>& corner) {
  const int n = static_cast<int>(normals.size());
  std::vector<Point2> next = normals;
  for (int i = 0; i < n; ++i) {
    if (corner[i]) continue;
    const int prev = i == 0 ? n - 2 : i - 1;
    const int after = i == n - 1 ? 1 : i + 1;
    Point2 m = {normals[prev][0] + 2 * normals[i][0] + normals[after][0],
                normals[prev][1] + 2 * normals[i][1] + normals[after][1]};
    const double len = std::hypot(m[0], m[1]);
    if (len > 0.0) next[i] = {m[0] / len, m[1] / len};
  }
  normals = std::move(next);
}

// Whether the layer q above p is acceptable: every segment keeps its direction and at least
// `min_ratio` of its length, every cell keeps the orientation of the wall's, and q does not
// cross itself. On failure `where` is the first bad segment.
bool LayerValid(const std::vector<Point2>& p, const std::vector<Point2>& q, double orientation,
                double min_ratio, int* where) {
  for (size_t i = 0; i + 1 < p.size(); ++i) {
    const Point2 a = {p[i + 1][0] - p[i][0], p[i + 1][1] - p[i][1]};
    const Point2 b = {q[i + 1][0] - q[i][0], q[i + 1][1] - q[i][1]};
    const double la = std::hypot(a[0], a[1]), lb = std::hypot(b[0], b[1]);
    // The cell p_i, p_i+1, q_i+1, q_i: twice its signed area (shoelace).
    const double area = Cross(p[i], p[i + 1]) + Cross(p[i + 1], q[i + 1]) + Cross(q[i + 1], q[i]) +
                        Cross(q[i], p[i]);
    if (a[0] * b[0] + a[1] * b[1] <= 0.0 || lb < min_ratio * la || area * orientation >= 0.0) {
      *where = static_cast<int>(i);
      return false;
    }
  }
  if (const auto crossing = FindPolylineCrossing(Flat(q), /*closed=*/true)) {
    *where = crossing->first;
    return false;
  }
  return true;
}

// The piece q[a..b] refitted (interpolating, faired with `lambda`) and its points slid along
// it towards even arc-length spacing by the fraction `beta`, but none by more than `slide`;
// the ends stay.
absl::Status RefitPiece(std::vector<Point2>& q, int a, int b, double lambda, double beta,
                        double slide) {
  const int m = b - a + 1;
  if (m < 4) return absl::OkStatus();
  StructuredBlock piece({m, 1, 1}, 2);
  for (int i = 0; i < m; ++i) std::copy(q[a + i].begin(), q[a + i].end(), piece.Point(i, 0, 0));
  FitOptions options;
  options.fairing = lambda;
  SG_ASSIGN_OR_RETURN(const FittedBlock fit, FitBlock(piece, options));
  // Arc length along the fitted piece, sampled.
  const int count = kArcSamples * (m - 1);
  std::vector<double> u(count + 1), s(count + 1, 0.0);
  Point3 prev{};
  for (int t = 0; t <= count; ++t) {
    u[t] = static_cast<double>(t) / count;
    const Point3 x = EvaluatePoint(fit.spline, {u[t], 0.0, 0.0});
    if (t > 0) s[t] = s[t - 1] + std::hypot(x[0] - prev[0], x[1] - prev[1]);
    prev = x;
  }
  auto arc_of = [&](double param) {
    const size_t t =
        std::min<size_t>(std::upper_bound(u.begin(), u.end(), param) - u.begin(), u.size() - 1);
    if (t == 0) return 0.0;
    const double w = (param - u[t - 1]) / (u[t] - u[t - 1]);
    return s[t - 1] + std::clamp(w, 0.0, 1.0) * (s[t] - s[t - 1]);
  };
  auto param_of = [&](double arc) {
    const size_t t =
        std::min<size_t>(std::upper_bound(s.begin(), s.end(), arc) - s.begin(), s.size() - 1);
    if (t == 0) return 0.0;
    const double w = (arc - s[t - 1]) / (s[t] - s[t - 1]);
    return u[t - 1] + std::clamp(w, 0.0, 1.0) * (u[t] - u[t - 1]);
  };
  const std::vector<double>& params = fit.distribution.params(0);
  std::vector<double> now(m), even(m);
  double mismatch = 0.0;
  for (int i = 0; i < m; ++i) {
    now[i] = arc_of(params[i]);
    even[i] = s.back() * i / (m - 1);
    mismatch = std::max(mismatch, std::abs(even[i] - now[i]));
  }
  if (mismatch > 0.0) beta = std::min(beta, slide / mismatch);
  for (int i = 1; i + 1 < m; ++i) {
    const Point3 x =
        EvaluatePoint(fit.spline, {param_of((1 - beta) * now[i] + beta * even[i]), 0, 0});
    q[a + i] = {x[0], x[1]};
  }
  return absl::OkStatus();
}

// The checks of MarchOffsets' wall loop: 5 points at least, closed, finite, not crossing itself.
absl::Status CheckWallLoop(const WallLoop& wall) {
  const int n = static_cast<int>(wall.points.size());
  if (n < 5)
    return absl::InvalidArgumentError(absl::StrCat("the wall has ", n, " points; 5 at least"));
  if (wall.points.front() != wall.points.back()) {
    return absl::InvalidArgumentError(
        "the wall loop is not closed: its last point is not its first");
  }
  for (double v : Flat(wall.points)) {
    if (!std::isfinite(v))
      return absl::InvalidArgumentError("the wall has a non-finite coordinate");
  }
  if (const auto crossing = FindPolylineCrossing(Flat(wall.points), true)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the wall crosses itself: segment ", crossing->first, " meets segment ", crossing->second));
  }
  return absl::OkStatus();
}

// The wall's corner indices with the loop's ends added, sorted and unique.
absl::StatusOr<std::vector<int>> SortedCorners(const WallLoop& wall) {
  const int n = static_cast<int>(wall.points.size());
  std::vector<int> corners = wall.corners;
  corners.push_back(0);
  corners.push_back(n - 1);
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  if (corners.front() < 0 || corners.back() > n - 1) {
    return absl::InvalidArgumentError("a wall corner index is outside the loop");
  }
  return corners;
}

// The corners still sharp on a layer, and the pieces they split its refit into.
struct LayerCorners {
  std::vector<bool> is_corner;  // per point
  std::vector<int> pieces;      // piece ends, from 0 to n - 1
};

// Corners still sharp on layer p keep their normal (the bisector) and split the refit; once a
// corner has opened up below kCornerDegrees it is smoothed like any point (the seam at the
// loop's ends always splits the refit).
LayerCorners SharpCorners(const std::vector<Point2>& p, const std::vector<int>& corners) {
  const int n = static_cast<int>(p.size());
  LayerCorners out{std::vector<bool>(n, false), {0}};
  for (int c : corners) {
    if (c == 0 || c == n - 1) continue;
    if (TurningDegrees(p, c) >= kCornerDegrees) {
      out.is_corner[c] = true;
      out.pieces.push_back(c);
    }
  }
  out.pieces.push_back(n - 1);
  if (TurningDegrees(p, 0) >= kCornerDegrees) out.is_corner[0] = out.is_corner[n - 1] = true;
  return out;
}

// Layer k + 1 (step h) above p along `normals`, which get two more smoothing sweeps per retry
// (counted in `*retries`) until the layer is valid (LayerValid); FAILED_PRECONDITION when
// max_retries does not suffice.
absl::StatusOr<std::vector<Point2>> OffsetWithRetries(const std::vector<Point2>& p,
                                                      std::vector<Point2>& normals,
                                                      const std::vector<bool>& is_corner, double h,
                                                      double orientation, int k,
                                                      const OffsetOptions& options, int* retries) {
  const int n = static_cast<int>(p.size());
  std::vector<Point2> q(n);
  int where = 0;
  for (int attempt = 0; attempt <= options.max_retries; ++attempt) {
    if (attempt > 0) {
      for (int s = 0; s < 2 * attempt; ++s) SmoothNormals(normals, is_corner);
      ++*retries;
    }
    for (int i = 0; i < n; ++i) q[i] = {p[i][0] + h * normals[i][0], p[i][1] + h * normals[i][1]};
    q.back() = q.front();
    if (LayerValid(p, q, orientation, options.min_segment_ratio, &where)) return q;
  }
  return absl::FailedPreconditionError(absl::StrCat(
      "layer ", k + 1, " folds at wall segment ", where, " even with smoothed normals (step ", h,
      "); use more layers, a smaller growth or a smoother wall"));
}

// Refit and fair layer q (above p, layer k + 1 of step h) between corners; slide towards even
// spacing by the part of the remaining distance this layer covers (so the unevenness left is
// the fraction of the distance still to go).
absl::Status RefitLayer(const std::vector<Point2>& p, const std::vector<int>& pieces, double h,
                        int k, double orientation, const OffsetOptions& options,
                        std::vector<Point2>& q) {
  const double fraction = static_cast<double>(k + 1) / options.layers;
  const double lambda = options.fairing * fraction;
  const double beta = options.uniformity / (options.layers - k);
  const double tilt = (options.wall_tilt_degrees +
                       (options.far_tilt_degrees - options.wall_tilt_degrees) * fraction) *
                      3.14159265358979323846 / 180.0;
  std::vector<Point2> refitted = q;
  for (size_t c = 0; c + 1 < pieces.size(); ++c) {
    SG_RETURN_IF_ERROR(
        RefitPiece(refitted, pieces[c], pieces[c + 1], lambda, beta, std::tan(tilt) * h));
  }
  refitted.back() = refitted.front();
  // The refit must not spoil the layer; if it does, keep the offsets as they are.
  int where = 0;
  if (LayerValid(p, refitted, orientation, options.min_segment_ratio, &where)) {
    q = std::move(refitted);
  }
  return absl::OkStatus();
}

// Curvature reduction of layer q (above p) before the next step h_next (concave_fill.h): its
// convex corners and the seam stay, the rest is smoothed where concave beyond
// max_concave_turning, no point moving by more than h_next. Kept only if the layer stays valid
// above p.
void ReduceConcaveCurvature(const std::vector<Point2>& p, const std::vector<bool>& is_corner,
                            double h_next, double orientation, const OffsetOptions& options,
                            std::vector<Point2>& q) {
  const int n = static_cast<int>(q.size());
  std::vector<bool> fixed(n);
  for (int i = 0; i < n; ++i) fixed[i] = is_corner[i] && SignedTurning(q, i, orientation) > 0.0;
  std::vector<Point2> filled = q;
  const ConcaveFill fill =
      FillConcavities(filled, fixed, orientation, h_next, options.max_concave_turning, h_next);
  int where = 0;
  if (fill.rounds > 0 && LayerValid(p, filled, orientation, options.min_segment_ratio, &where)) {
    q = std::move(filled);
  }
}

}  // namespace

absl::Status ValidateLayerCount(int layers) {
  if (layers < 1 || layers > kMaxLayers) {
    return absl::InvalidArgumentError(
        absl::StrCat("layers = ", layers, " is outside [1, ", kMaxLayers, "]"));
  }
  return absl::OkStatus();
}

absl::Status ValidateLayerStack(int layers, double first_height, double distance) {
  SG_RETURN_IF_ERROR(ValidateLayerCount(layers));
  if (!(first_height > 0.0) || !std::isfinite(first_height)) {
    return absl::InvalidArgumentError(
        absl::StrCat("first_height = ", first_height, " is not a positive finite number"));
  }
  if (!(distance > 0.0) || !std::isfinite(distance)) {
    return absl::InvalidArgumentError(
        absl::StrCat("distance = ", distance, " is not a positive finite number"));
  }
  if (distance < first_height * layers * (1.0 - 1e-12)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "distance = ", distance, " is below layers x first_height = ", layers * first_height,
        "; the layers cannot shrink"));
  }
  return absl::OkStatus();
}

absl::Status ValidateMarchedGrowth(int layers, double first_height, double distance) {
  if (layers == 1 && distance > first_height * (1.0 + 1e-12)) {  // no ratio reaches it
    return absl::InvalidArgumentError(absl::StrCat("layers = 1 with first_height = ", first_height,
                                                   " cannot reach distance = ", distance,
                                                   ": one layer is first_height high"));
  }
  if (const double ratio = GeometricRatio(first_height, distance, layers);
      !(ratio <= kMaxGrowthRatio)) {
    return absl::InvalidArgumentError(
        absl::StrCat("distance = ", distance, " needs a growth ratio of ", ratio,
                     " between layers (", layers, " layers from first_height = ", first_height,
                     "), above ", kMaxGrowthRatio, "; use more layers or a larger first_height"));
  }
  return absl::OkStatus();
}

absl::Status OffsetOptions::Validate() const {
  SG_RETURN_IF_ERROR(ValidateLayerStack(layers, first_height, distance));
  SG_RETURN_IF_ERROR(ValidateMarchedGrowth(layers, first_height, distance));
  if (normal_smoothing < 0 || !(fairing >= 0.0) || !std::isfinite(fairing) ||
      !(uniformity >= 0.0 && uniformity <= 1.0) ||
      !(min_segment_ratio > 0.0 && min_segment_ratio < 1.0) || max_retries < 0 ||
      !(max_concave_turning > 0.0 && max_concave_turning < 1.0) ||
      !(wall_tilt_degrees >= 0.0 && wall_tilt_degrees < 90.0) ||
      !(far_tilt_degrees >= 0.0 && far_tilt_degrees < 90.0)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "smoothing options out of range: normal_smoothing = ", normal_smoothing, ", fairing = ",
        fairing, ", uniformity = ", uniformity, ", min_segment_ratio = ", min_segment_ratio,
        ", max_concave_turning = ", max_concave_turning, ", max_retries = ", max_retries,
        ", tilts = ", wall_tilt_degrees, " and ", far_tilt_degrees, " degrees"));
  }
  return absl::OkStatus();
}

absl::StatusOr<OffsetGrid> MarchOffsets(const WallLoop& wall, const OffsetOptions& options) {
  SG_RETURN_IF_ERROR(options.Validate());
  SG_RETURN_IF_ERROR(CheckWallLoop(wall));
  const int n = static_cast<int>(wall.points.size());
  SG_ASSIGN_OR_RETURN(const std::vector<int> corners, SortedCorners(wall));
  const double orientation = SignedArea2(wall.points) > 0.0 ? 1.0 : -1.0;

  OffsetGrid out;
  out.growth_ratio = GeometricRatio(options.first_height, options.distance, options.layers);
  out.block = StructuredBlock({n, options.layers + 1, 1}, 2);
  std::vector<Point2> p = wall.points;
  auto store = [&](int j) {
    for (int i = 0; i < n; ++i) std::copy(p[i].begin(), p[i].end(), out.block.Point(i, j, 0));
  };
  store(0);
  for (int k = 0; k < options.layers; ++k) {
    SG_RETURN_IF_ERROR(PollCancel(options.cancel));
    const double h = options.first_height * std::pow(out.growth_ratio, k);
    out.steps.push_back(h);
    // Progress through the layers (not the distance: with geometric growth the last few
    // layers cover most of it).
    const double fraction = static_cast<double>(k + 1) / options.layers;
    const LayerCorners sharp = SharpCorners(p, corners);
    std::vector<Point2> normals = LoopNormals(p, orientation);
    for (int i = 0; i < n; ++i) {
      if (sharp.is_corner[i] && TurningDegrees(p, i) > kWedgeDegrees) {
        normals[i] = CornerBisector(p, i, orientation);
      }
    }
    const int sweeps = static_cast<int>(std::lround(options.normal_smoothing * fraction));
    for (int s = 0; s < sweeps; ++s) SmoothNormals(normals, sharp.is_corner);
    SG_ASSIGN_OR_RETURN(
        std::vector<Point2> q,
        OffsetWithRetries(p, normals, sharp.is_corner, h, orientation, k, options, &out.retries));
    SG_RETURN_IF_ERROR(RefitLayer(p, sharp.pieces, h, k, orientation, options, q));
    ReduceConcaveCurvature(p, sharp.is_corner, h * out.growth_ratio, orientation, options, q);
    p = std::move(q);
    store(k + 1);
  }
  // Right-handed: with the layers outward, i must run clockwise for positive cell areas.
  if (orientation > 0.0) out.block = ReversedI(out.block);
  return out;
}

}  // namespace splinegrid
