#include "core/generate/transfinite.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/generate/loop_geometry.h"
#include "core/generate/offset_march.h"
#include "core/grid/sampling.h"

namespace splinegrid {
namespace {

// Points on either side of a corner whose normals fan towards the corner's normal.
constexpr int kCornerFan = 4;

constexpr double kPi = 3.14159265358979323846;

}  // namespace

absl::Status CompletionOptions::Validate() const {
  if (layers < 1 || layers > 100000) {
    return absl::InvalidArgumentError(absl::StrCat("layers = ", layers, " is outside [1, 100000]"));
  }
  if (!(first_height > 0.0) || !std::isfinite(first_height) || !(distance > 0.0) ||
      !std::isfinite(distance)) {
    return absl::InvalidArgumentError(absl::StrCat("first_height = ", first_height,
                                                   " and distance = ", distance,
                                                   " must be positive and finite"));
  }
  if (!(orthogonal_reach > 0.0) || !std::isfinite(orthogonal_reach)) {
    return absl::InvalidArgumentError(
        absl::StrCat("orthogonal_reach = ", orthogonal_reach, " is not a positive finite number"));
  }
  if (distance < first_height * layers * (1.0 - 1e-12)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "distance = ", distance, " is below layers x first_height = ", layers * first_height));
  }
  return absl::OkStatus();
}

Circle EnclosingCircle(const std::vector<Point2>& wall, double distance) {
  const int n = static_cast<int>(wall.size());
  Circle circle;
  for (int i = 0; i + 1 < n; ++i) {
    circle.center[0] += wall[i][0] / (n - 1);
    circle.center[1] += wall[i][1] / (n - 1);
  }
  double reach = 0.0;
  for (const Point2& p : wall) {
    reach = std::max(reach, std::hypot(p[0] - circle.center[0], p[1] - circle.center[1]));
  }
  circle.radius = distance + reach;
  return circle;
}

std::vector<Point2> PointsOnCircle(const Circle& circle, const std::vector<Point2>& loop,
                                   OuterSpacing spacing) {
  const std::vector<Point2>& w = loop;
  const Point2& c = circle.center;
  const int n = static_cast<int>(w.size());
  const double orientation = SignedArea2(w) > 0.0 ? 1.0 : -1.0;
  const double start = std::atan2(w[0][1] - c[1], w[0][0] - c[0]);
  std::vector<double> arc(n, 0.0);
  for (int i = 1; i < n; ++i) {
    arc[i] = arc[i - 1] + std::hypot(w[i][0] - w[i - 1][0], w[i][1] - w[i - 1][1]);
  }
  std::vector<Point2> out(n);
  for (int i = 0; i < n; ++i) {
    const double fraction =
        spacing == OuterSpacing::kEven ? static_cast<double>(i) / (n - 1) : arc[i] / arc.back();
    const double angle = start + orientation * 2.0 * kPi * fraction;
    out[i] = {c[0] + circle.radius * std::cos(angle), c[1] + circle.radius * std::sin(angle)};
  }
  out.back() = out.front();
  return out;
}

std::vector<Point2> OuterCircle(const WallLoop& wall, double distance, OuterSpacing spacing) {
  return PointsOnCircle(EnclosingCircle(wall.points, distance), wall.points, spacing);
}

std::vector<double> LayerHeights(const CompletionOptions& options) {
  const double r = GeometricRatio(options.first_height, options.distance, options.layers);
  std::vector<double> d(options.layers + 1, 0.0);
  for (int j = 1; j <= options.layers; ++j) {
    d[j] = d[j - 1] + options.first_height * std::pow(r, j - 1);
  }
  return d;
}

void InterpolateLines(const std::vector<Point2>& inner, const std::vector<Point2>& directions,
                      const std::vector<Point2>& outer, const std::vector<double>& heights,
                      const CompletionOptions& options, int from, StructuredBlock& grid) {
  const int n = static_cast<int>(inner.size());
  const double length = heights.back() - heights[from];
  // The exponent of the orthogonalising bump t (1 - t)^m, whose largest value, about
  // 1 / (e (m + 1)) at t = 1 / (m + 1), bounds how far (times the length) the lines bend off
  // straight.
  const double m = std::max(1.0, length / (std::exp(1.0) * options.orthogonal_reach) - 1.0);
  for (int j = from; j < static_cast<int>(heights.size()); ++j) {
    const double t = (heights[j] - heights[from]) / length;
    const double bump = options.orthogonalize ? t * std::pow(1.0 - t, m) : 0.0;
    for (int i = 0; i < n; ++i) {
      double* x = grid.Point(i, j, 0);
      for (int c = 0; c < 2; ++c) {
        const double chord = outer[i][c] - inner[i][c];
        x[c] = inner[i][c] + t * chord + bump * (length * directions[i][c] - chord);
      }
    }
  }
}

absl::StatusOr<StructuredBlock> TransfiniteGrid(const WallLoop& wall,
                                                const std::vector<Point2>& outer,
                                                const CompletionOptions& options) {
  if (absl::Status s = options.Validate(); !s.ok()) return s;
  const std::vector<Point2>& w = wall.points;
  const int n = static_cast<int>(w.size());
  if (n < 5 || static_cast<int>(outer.size()) != n) {
    return absl::InvalidArgumentError(absl::StrCat("the wall has ", n,
                                                   " points and the outer loop ", outer.size(),
                                                   "; give the same number, >= 5"));
  }
  if (w.front() != w.back() || outer.front() != outer.back()) {
    return absl::InvalidArgumentError("both loops must be closed (last point = first)");
  }
  const double orientation = SignedArea2(w) > 0.0 ? 1.0 : -1.0;
  if (SignedArea2(outer) * orientation <= 0.0) {
    return absl::InvalidArgumentError("the outer loop runs the other way round than the wall");
  }
  // The normals, with the neighbours of a blunt corner (a blunt trailing edge's base) turned
  // part of the way towards the corner's bisector: the corner fans its lines out over a few
  // points instead of one (its neighbours' lines would otherwise bend apart by the corner's
  // angle and cross further out).
  std::vector<Point2> normals = LoopNormals(w, orientation);
  for (int c : wall.corners) {
    const int at = c == n - 1 ? 0 : c;
    // Not at a sharp trailing edge: its neighbours' lines must leave the thin wedge first, and
    // its own line, alone in the exterior angle, bisects it.
    if (TurningDegrees(w, at) > kWedgeDegrees) {
      normals[at] = CornerBisector(w, at, orientation);
      continue;
    }
    for (int side : {-1, 1}) {
      for (int q = 1; q <= kCornerFan; ++q) {
        int i = at + side * q;
        if (i < 0) i += n - 1;
        if (i >= n - 1) i -= n - 1;
        const double f = 1.0 - static_cast<double>(q) / (kCornerFan + 1);
        Point2 mix = {f * normals[at][0] + (1 - f) * normals[i][0],
                      f * normals[at][1] + (1 - f) * normals[i][1]};
        const double len = std::hypot(mix[0], mix[1]);
        if (len > 0.0) normals[i] = {mix[0] / len, mix[1] / len};
      }
    }
  }
  normals.back() = normals.front();
  StructuredBlock grid({n, options.layers + 1, 1}, 2);
  InterpolateLines(w, normals, outer, LayerHeights(options), options, 0, grid);
  if (orientation > 0.0) return ReversedI(grid);
  return grid;
}

}  // namespace splinegrid
