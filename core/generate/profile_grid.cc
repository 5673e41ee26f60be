#include "core/generate/profile_grid.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "core/generate/cove_completion.h"
#include "core/generate/elliptic.h"
#include "core/generate/loop_geometry.h"
#include "core/generate/offset_march.h"
#include "core/generate/transfinite.h"
#include "core/grid/sampling.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

constexpr double kPi = 3.14159265358979323846;

Point2 At(const StructuredBlock& g, int i, int j) {
  const double* p = g.Point(i, j, 0);
  return {p[0], p[1]};
}

Point2 Minus(const Point2& a, const Point2& b) { return {a[0] - b[0], a[1] - b[1]}; }

double Norm(const Point2& a) { return std::hypot(a[0], a[1]); }

// Distance from p to the segment [a, b].
double SegmentDistance(const Point2& p, const Point2& a, const Point2& b) {
  const Point2 ab = Minus(b, a), ap = Minus(p, a);
  const double length2 = ab[0] * ab[0] + ab[1] * ab[1];
  const double t =
      length2 > 0.0 ? std::clamp((ap[0] * ab[0] + ap[1] * ab[1]) / length2, 0.0, 1.0) : 0.0;
  return Norm({ap[0] - t * ab[0], ap[1] - t * ab[1]});
}

// Whether the segments [a, b] and [c, d] cross (each one's ends strictly on either side of the
// other's line): touching ends of neighbouring segments do not count.
bool SegmentsCross(const Point2& a, const Point2& b, const Point2& c, const Point2& d) {
  const double d1 = Cross(Minus(b, a), Minus(c, a));
  const double d2 = Cross(Minus(b, a), Minus(d, a));
  const double d3 = Cross(Minus(d, c), Minus(a, c));
  const double d4 = Cross(Minus(d, c), Minus(b, c));
  return ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) &&
         ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0));
}

// Whether the closed polyline of line j (points 0 .. ni - 1, the last the first) crosses
// itself. Bounding boxes of runs of kRun segments prune the pairs.
bool SelfIntersects(const StructuredBlock& g, int j) {
  const int segments = g.extent(0) - 1;
  constexpr int kRun = 8;
  struct Box {
    double x0, y0, x1, y1;
  };
  std::vector<Box> boxes;
  for (int s = 0; s < segments; s += kRun) {
    Box b{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
    for (int i = s; i <= std::min(s + kRun, segments); ++i) {
      const Point2 p = At(g, i, j);
      b = {std::min(b.x0, p[0]), std::min(b.y0, p[1]), std::max(b.x1, p[0]), std::max(b.y1, p[1])};
    }
    boxes.push_back(b);
  }
  for (size_t r = 0; r < boxes.size(); ++r) {
    for (size_t q = r; q < boxes.size(); ++q) {
      const Box &a = boxes[r], &b = boxes[q];
      if (a.x1 < b.x0 || b.x1 < a.x0 || a.y1 < b.y0 || b.y1 < a.y0) continue;
      const int s_end = std::min<int>((r + 1) * kRun, segments);
      const int t_end = std::min<int>((q + 1) * kRun, segments);
      for (int s = static_cast<int>(r) * kRun; s < s_end; ++s) {
        for (int t = std::max(static_cast<int>(q) * kRun, s + 2); t < t_end; ++t) {
          if (s == 0 && t == segments - 1) continue;  // neighbours across the seam
          if (SegmentsCross(At(g, s, j), At(g, s + 1, j), At(g, t, j), At(g, t + 1, j)))
            return true;
        }
      }
    }
  }
  return false;
}

absl::Status CheckFinitePositive(double value, const char* field) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, " = ", value, " is not a positive finite number"));
  }
  return absl::OkStatus();
}

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

std::string_view LayerMethodName(LayerMethod method) {
  switch (method) {
    case LayerMethod::kOffsets:
      return "offsets";
    case LayerMethod::kTransfinite:
      return "transfinite";
    case LayerMethod::kElliptic:
      return "elliptic";
  }
  return "unknown";
}

absl::Status ProfileGridOptions::Validate() const {
  if (wall_points < 9) {
    return absl::InvalidArgumentError(absl::StrCat("wall_points = ", wall_points, " is below 9"));
  }
  if (first_height && distance) {
    SG_RETURN_IF_ERROR(ValidateLayerStack(layers, *first_height, *distance));
  } else {
    // The stack (distance >= layers x first_height) is checked once the unset length is known
    // from the profile's chord (GenerateProfileGrid).
    SG_RETURN_IF_ERROR(ValidateLayerCount(layers));
    if (first_height) SG_RETURN_IF_ERROR(CheckFinitePositive(*first_height, "first_height"));
    if (distance) SG_RETURN_IF_ERROR(CheckFinitePositive(*distance, "distance"));
  }
  if (static_cast<int64_t>(wall_points) * (layers + 1) > kMaxProfileGridPoints) {
    return absl::InvalidArgumentError(absl::StrCat(
        "wall_points * (layers + 1) = ", static_cast<int64_t>(wall_points) * (layers + 1),
        " points exceed the limit of ", kMaxProfileGridPoints));
  }
  if (fit_tolerance) SG_RETURN_IF_ERROR(CheckFinitePositive(*fit_tolerance, "fit_tolerance"));
  if (method == LayerMethod::kElliptic && (wall_points % 2 == 0 || layers % 2 != 0)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the elliptic method solves on every second point and layer first: wall_points = ",
        wall_points, " must be odd and layers = ", layers, " even"));
  }
  return absl::OkStatus();
}

int HeldLayers(const CompletionOptions& completion, const AlgebraicGrid& algebraic, double chord) {
  return std::max(LayersWithin(LayerHeights(completion), kHeldBoundaryLayer * chord),
                  algebraic.marched_layers + 1);
}

double ProfileChord(const StructuredBlock& coordinates) {
  double chord = 0.0;
  for (int i = 1; i < coordinates.extent(0); ++i) {
    chord = std::max(chord, Norm(Minus(At(coordinates, i, 0), At(coordinates, 0, 0))));
  }
  return chord;
}

OGridQuality MeasureOGrid(const StructuredBlock& g, const std::vector<int>& corners) {
  OGridQuality q;
  const int ni = g.extent(0), nj = g.extent(1);
  q.min_cell_area = std::numeric_limits<double>::infinity();
  for (int j = 0; j + 1 < nj; ++j) {
    for (int i = 0; i + 1 < ni; ++i) {
      const double area = SignedCellArea(g, i, j);
      q.min_cell_area = std::min(q.min_cell_area, area);
      q.negative_cells += !(area > 0.0);
    }
  }
  q.first_height_min = std::numeric_limits<double>::infinity();
  q.outer_distance_min = std::numeric_limits<double>::infinity();
  std::vector<bool> corner(ni, false);
  for (int c : corners) {
    if (c >= 0 && c < ni) corner[c] = true;
  }
  corner[0] = corner[ni - 1] = corner[0] || corner[ni - 1];
  for (int i = 0; i < ni; ++i) {
    const Point2 line = Minus(At(g, i, std::min(1, nj - 1)), At(g, i, 0));
    const double height = Norm(line);
    q.first_height_min = std::min(q.first_height_min, height);
    q.first_height_max = std::max(q.first_height_max, height);
    if (!corner[i] && height > 0.0) {
      const int im = i == 0 ? ni - 2 : i - 1, ip = i == ni - 1 ? 1 : i + 1;
      const Point2 tangent = Minus(At(g, ip, 0), At(g, im, 0));
      const double cosine =
          std::abs(tangent[0] * line[0] + tangent[1] * line[1]) / (Norm(tangent) * height);
      q.wall_orthogonality_degrees = std::max(
          q.wall_orthogonality_degrees, 90.0 - std::acos(std::min(1.0, cosine)) * 180.0 / kPi);
    }
    double nearest = std::numeric_limits<double>::infinity();
    const Point2 outer = At(g, i, nj - 1);
    for (int w = 0; w + 1 < ni; ++w) {
      nearest = std::min(nearest, SegmentDistance(outer, At(g, w, 0), At(g, w + 1, 0)));
    }
    q.outer_distance_min = std::min(q.outer_distance_min, nearest);
    q.outer_distance_max = std::max(q.outer_distance_max, nearest);
  }
  for (int j = 1; j < nj; ++j) {
    if (SelfIntersects(g, j)) {
      if (q.self_intersecting_layers++ == 0) q.first_self_intersecting_layer = j;
    }
  }
  return q;
}

absl::StatusOr<ProfileGrid> GenerateProfileGrid(const StructuredBlock& coordinates,
                                                const ProfileGridOptions& options) {
  SG_RETURN_IF_ERROR(options.Validate());
  ProfileGrid out;
  auto start = std::chrono::steady_clock::now();
  const double chord = ProfileChord(coordinates);
  if (!(chord > 0.0) || !std::isfinite(chord)) {
    return absl::InvalidArgumentError(
        absl::StrCat("the profile's chord (largest distance from its first point) is ", chord,
                     ": check the coordinates"));
  }
  out.fit_tolerance =
      options.fit_tolerance ? *options.fit_tolerance : kDefaultProfileFitTolerance * chord;
  AirfoilFitOptions fit_options;
  fit_options.tolerance = out.fit_tolerance;
  fit_options.cancel = options.cancel;
  SG_ASSIGN_OR_RETURN(out.profile, FitAirfoil(coordinates, fit_options));
  if (!out.profile.met) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the profile cannot be fitted within fit_tolerance = ", out.fit_tolerance,
        options.fit_tolerance
            ? ""
            : absl::StrCat(" (the default, ", kDefaultProfileFitTolerance, " of its chord)"),
        ": ", out.profile.unmet_reason));
  }
  out.fit_seconds = SecondsSince(start);
  out.first_height = options.first_height.value_or(kDefaultFirstHeight * chord);
  out.distance = options.distance.value_or(kDefaultFarDistance * chord);
  if (const absl::Status stack = ValidateLayerStack(options.layers, out.first_height, out.distance);
      !stack.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat(stack.message(), " (unset lengths default to ", kDefaultFirstHeight, " and ",
                     kDefaultFarDistance, " of the profile's chord, ", chord, ")"));
  }

  start = std::chrono::steady_clock::now();
  Profile profile;
  profile.curve = out.profile.curve;
  profile.closed = out.profile.sharp_trailing_edge;
  for (int f : out.profile.features) profile.corners.push_back(out.profile.params[f]);
  WallOptions wall_options;
  wall_options.num_points = options.wall_points;
  SG_ASSIGN_OR_RETURN(out.wall, DistributeWall(profile, wall_options));
  out.wall_seconds = SecondsSince(start);

  start = std::chrono::steady_clock::now();
  if (options.method == LayerMethod::kOffsets) {
    OffsetOptions offsets;
    offsets.layers = options.layers;
    offsets.first_height = out.first_height;
    offsets.distance = out.distance;
    offsets.cancel = options.cancel;
    SG_ASSIGN_OR_RETURN(OffsetGrid grid, MarchOffsets(out.wall, offsets));
    out.block = std::move(grid.block);
    out.growth_ratio = grid.growth_ratio;
    out.retries = grid.retries;
  } else {
    CompletionOptions completion;
    completion.layers = options.layers;
    completion.first_height = out.first_height;
    completion.distance = out.distance;
    completion.orthogonalize = options.orthogonalize;
    completion.orthogonal_reach = kOrthogonalReach * chord;
    const bool elliptic = options.method == LayerMethod::kElliptic;
    SG_ASSIGN_OR_RETURN(
        AlgebraicGrid algebraic,
        AlgebraicOGrid(out.wall, elliptic ? OuterSpacing::kEven : OuterSpacing::kFollowWall,
                       completion, options.cancel));
    out.marched_layers = algebraic.marched_layers;
    if (!elliptic) {
      out.block = std::move(algebraic.block);
    } else {
      EllipticOptions smoothing;
      smoothing.cancel = options.cancel;
      SG_ASSIGN_OR_RETURN(
          CoarseToFine smoothed,
          SmoothCoarseToFine(algebraic.block, HeldLayers(completion, algebraic, chord), smoothing,
                             /*compare=*/false));
      out.block = std::move(smoothed.fine.grid);
      out.coarse_sweeps = smoothed.coarse.sweeps;
      out.fine_sweeps = smoothed.fine.sweeps;
      out.coarse_seconds = smoothed.coarse.seconds;
      out.fine_seconds = smoothed.fine.seconds;
      out.elliptic_converged = smoothed.fine.converged;
      out.elliptic_restarts = smoothed.coarse.restarts + smoothed.fine.restarts;
      out.elliptic_relaxation = smoothed.fine.relaxation;
    }
    out.growth_ratio = GeometricRatio(out.first_height, out.distance, options.layers);
  }
  out.layer_seconds = SecondsSince(start);

  // The block's i runs along the loop or against it (offset_march.h): map the corners.
  start = std::chrono::steady_clock::now();
  const int ni = out.block.extent(0);
  const bool reversed = At(out.block, 1, 0) != out.wall.points[1];
  for (int c : out.wall.corners) out.corners.push_back(reversed ? ni - 1 - c : c);
  out.quality = MeasureOGrid(out.block, out.corners);
  out.measure_seconds = SecondsSince(start);
  return out;
}

}  // namespace splinegrid
