// Airfoil profile fits: the shared coordinate files within 1e-4 chord with few controls, sharp
// and blunt trailing edges, feature points, fairing, and every error path.
#include "core/fit/airfoil/airfoil_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/bspline/differential_geometry.h"
#include "core/bspline/evaluation.h"
#include "core/io/airfoil.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

// The fitting tolerance of the issue, in chords.
constexpr double kTolerance = 1e-4;
// Dense polyline check of the distances: samples of the curve, and how far the reported (Newton)
// distance may exceed the polyline's (the chord error h^2 kappa / 8 at the nose is ~2e-8).
constexpr int kDenseSamples = 40000;
constexpr double kDistanceSlack = 1e-7;
// Samples per data interval for counting curvature extrema independently of the fit's metrics.
constexpr int kExtremaSamples = 16;

StructuredBlock Shared(const std::string& name) {
  absl::StatusOr<AirfoilCoordinates> airfoil =
      ReadAirfoilFile(SharedDataPath("airfoils/" + name + ".dat"));
  EXPECT_TRUE(airfoil.ok()) << airfoil.status();
  return airfoil.ok() ? airfoil->points : StructuredBlock();
}

// A block of 2D points from interleaved coordinates.
StructuredBlock Outline(const std::vector<double>& xy) {
  StructuredBlock block({static_cast<int>(xy.size() / 2), 1, 1}, 2);
  std::copy(xy.begin(), xy.end(), block.coords().begin());
  return block;
}

// NACA 4-digit section (Abbott & von Doenhoff, "Theory of Wing Sections", 1959, sec. 6.4) in
// Selig order, `per_side` cosine-spaced intervals per surface: camber `m` at `p`, thickness
// `t`; the x^4 coefficient 0.1015 (published, blunt trailing edge) or 0.1036 (closed).
std::vector<double> Naca4(double m, double p, double t, bool sharp, int per_side) {
  const double a4 = sharp ? 0.1036 : 0.1015;
  std::vector<double> upper, lower;
  for (int i = 0; i <= per_side; ++i) {
    const double x = 0.5 * (1.0 - std::cos(std::numbers::pi * i / per_side));
    const double yt = 5.0 * t *
                      (0.2969 * std::sqrt(x) - 0.1260 * x - 0.3516 * x * x + 0.2843 * x * x * x -
                       a4 * x * x * x * x);
    const double yc = x < p ? m / (p * p) * (2 * p * x - x * x)
                            : m / ((1 - p) * (1 - p)) * (1 - 2 * p + 2 * p * x - x * x);
    const double slope = x < p ? 2 * m / (p * p) * (p - x) : 2 * m / ((1 - p) * (1 - p)) * (p - x);
    const double theta = std::atan(slope);
    upper.insert(upper.end(), {x - yt * std::sin(theta), yc + yt * std::cos(theta)});
    lower.insert(lower.end(), {x + yt * std::sin(theta), yc - yt * std::cos(theta)});
  }
  std::vector<double> xy;
  for (int i = per_side; i >= 0; --i) xy.insert(xy.end(), {upper[2 * i], upper[2 * i + 1]});
  for (int i = 1; i <= per_side; ++i) xy.insert(xy.end(), {lower[2 * i], lower[2 * i + 1]});
  return xy;
}

// Distance from each point of `block` to the polyline through kDenseSamples + 1 points of the
// fitted curve, uniformly in u, and its feature points: an oracle for the reported (Newton)
// distances.
std::vector<double> PolylineDistances(const AirfoilFit& fit, const StructuredBlock& block) {
  std::vector<double> u(kDenseSamples + 1);
  for (int q = 0; q <= kDenseSamples; ++q) u[q] = static_cast<double>(q) / kDenseSamples;
  for (int r : fit.features) u.push_back(fit.params[r]);
  std::sort(u.begin(), u.end());
  const StructuredBlock dense = EvaluateGrid(fit.curve, {u, {0.0}, {0.0}});
  const int samples = static_cast<int>(u.size()) - 1;
  const std::span<const double> c = dense.coords();
  std::vector<double> out;
  for (int i = 0; i < block.extent(0); ++i) {
    const double* p = block.Point(i, 0, 0);
    double best = std::numeric_limits<double>::infinity();
    for (int q = 0; q < samples; ++q) {
      const double ax = c[2 * q], ay = c[2 * q + 1];
      const double dx = c[2 * q + 2] - ax, dy = c[2 * q + 3] - ay;
      const double len2 = dx * dx + dy * dy;
      const double s =
          len2 > 0.0 ? std::clamp(((p[0] - ax) * dx + (p[1] - ay) * dy) / len2, 0.0, 1.0) : 0.0;
      best = std::min(best, std::hypot(ax + s * dx - p[0], ay + s * dy - p[1]));
    }
    out.push_back(best);
  }
  return out;
}

// Interior curvature extrema of each surface, counted with CurveCurvature at kExtremaSamples
// per data interval, the surfaces split at the largest curvature (the nose).
std::array<int, 2> SurfaceExtrema(const AirfoilFit& fit) {
  std::vector<double> kappa;
  for (size_t i = 0; i + 1 < fit.params.size(); ++i) {
    for (int j = 0; j < kExtremaSamples; ++j) {
      const double u = fit.params[i] + (fit.params[i + 1] - fit.params[i]) * j / kExtremaSamples;
      kappa.push_back(CurveCurvature(fit.curve, 0, u));
    }
  }
  const size_t nose = std::max_element(kappa.begin(), kappa.end()) - kappa.begin();
  std::array<int, 2> count = {0, 0};
  for (size_t q = 1; q + 1 < kappa.size(); ++q) {
    const double before = kappa[q] - kappa[q - 1], after = kappa[q + 1] - kappa[q];
    if (q != nose && before * after < 0.0) ++count[q < nose ? 0 : 1];
  }
  return count;
}

// The angle between the tangents C'(a) and C'(b) of `curve`, in radians.
double TangentAngle(const TensorSpline& curve, double a, double b) {
  const Point3 ta = EvaluateDerivatives(curve, {a, 0.0, 0.0}, 1)(1, 0, 0);
  const Point3 tb = EvaluateDerivatives(curve, {b, 0.0, 0.0}, 1)(1, 0, 0);
  const double dot = ta[0] * tb[0] + ta[1] * tb[1];
  return std::acos(
      std::clamp(dot / (std::hypot(ta[0], ta[1]) * std::hypot(tb[0], tb[1])), -1.0, 1.0));
}

// The common checks of a fit of `block` within `tolerance`.
void ExpectWithinTolerance(const AirfoilFit& fit, const StructuredBlock& block, double tolerance,
                           const std::string& what) {
  EXPECT_TRUE(fit.met) << what << ": " << fit.unmet_reason;
  EXPECT_LE(fit.max_deviation, tolerance) << what;
  ASSERT_EQ(fit.distances.size(), block.num_points()) << what;
  const std::vector<double> oracle = PolylineDistances(fit, block);
  for (size_t i = 0; i < oracle.size(); ++i) {
    // The polyline is inside the curve's chord error: the foot found is the closest point.
    EXPECT_NEAR(fit.distances[i], oracle[i], kDistanceSlack) << what << " point " << i;
  }
  EXPECT_EQ(fit.num_control_points, fit.curve.num_control_points()) << what;
  EXPECT_EQ(fit.curve.spatial_dim(), 2) << what;
}

TEST(AirfoilFitTest, SharedAirfoilsWithinTolerance) {
  struct Case {
    std::string name;
    bool sharp;
    int max_controls;  // measured: 16, 13, 18 controls
  };
  for (const Case& c :
       {Case{"rae2822", true, 18}, Case{"naca0012", false, 15}, Case{"sc20714", false, 21}}) {
    const StructuredBlock block = Shared(c.name);
    absl::StatusOr<AirfoilFit> fit = FitAirfoil(block, AirfoilFitOptions());
    ASSERT_TRUE(fit.ok()) << c.name << ": " << fit.status();
    ExpectWithinTolerance(*fit, block, kTolerance, c.name);
    EXPECT_EQ(fit->sharp_trailing_edge, c.sharp) << c.name;
    EXPECT_LE(fit->num_control_points, c.max_controls) << c.name;
    EXPECT_TRUE(fit->features.empty()) << c.name;  // the leading edge is not a feature
    EXPECT_EQ(fit->curvature.piece_extrema.size(), 2u) << c.name;  // upper and lower surface
    // The ends are interpolated.
    const Point3 start = EvaluatePoint(fit->curve, {0.0, 0.0, 0.0});
    const Point3 end = EvaluatePoint(fit->curve, {1.0, 0.0, 0.0});
    const int m = static_cast<int>(block.num_points());
    for (int s = 0; s < 2; ++s) {
      EXPECT_NEAR(start[s], block.Point(0, 0, 0)[s], 1e-12) << c.name;
      EXPECT_NEAR(end[s], block.Point(m - 1, 0, 0)[s], 1e-12) << c.name;
    }
  }
}

// The aim of the issue: RAE 2822 within 1e-4 chord with <= 25 controls and no spurious
// curvature extrema. The data's own curvature (three-point circles through the 6-digit
// coordinates) has three extrema on the upper surface (minimum near x = 0.85, maximum near
// 0.55, minimum near 0.40) and two on the lower (minimum near 0.24, maximum near 0.38), apart
// from rounding noise at the trailing edge. The fit has as many, at x = 0.85, 0.59, 0.49 and
// 0.32, 0.37 (cubic pieces place them at knots).
TEST(AirfoilFitTest, Rae2822FewControlsNoSpuriousExtrema) {
  const StructuredBlock block = Shared("rae2822");
  absl::StatusOr<AirfoilFit> fit = FitAirfoil(block, AirfoilFitOptions());
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_TRUE(fit->met) << fit->unmet_reason;
  EXPECT_LE(fit->num_control_points, 18);  // measured 16; the aim is 25
  EXPECT_EQ(fit->curvature.spurious(), 0);
  EXPECT_EQ(fit->unfaired_curvature.spurious(), 0);
  EXPECT_EQ(SurfaceExtrema(*fit), (std::array<int, 2>{3, 2}));
  EXPECT_THAT(fit->curvature.piece_extrema, ::testing::ElementsAre(3, 2));
  // The nose: the largest curvature, near the leading-edge radius 0.00827 chord (kappa 121).
  EXPECT_NEAR(fit->curvature.total.max_abs_curvature, 121.0, 10.0);
  EXPECT_EQ(fit->leading_edge, 64);
}

TEST(AirfoilFitTest, SharpAndBluntTrailingEdges) {
  for (const bool sharp : {true, false}) {
    const std::string what = sharp ? "NACA 2412 closed" : "NACA 2412 blunt";
    const StructuredBlock block = Outline(Naca4(0.02, 0.4, 0.12, sharp, 80));
    absl::StatusOr<AirfoilFit> fit = FitAirfoil(block, AirfoilFitOptions());
    ASSERT_TRUE(fit.ok()) << what << ": " << fit.status();
    ExpectWithinTolerance(*fit, block, kTolerance, what);
    EXPECT_EQ(fit->sharp_trailing_edge, sharp) << what;
    EXPECT_LE(fit->num_control_points, 16) << what;
    EXPECT_EQ(fit->curvature.spurious(), 0) << what;
    const Point3 start = EvaluatePoint(fit->curve, {0.0, 0.0, 0.0});
    const Point3 end = EvaluatePoint(fit->curve, {1.0, 0.0, 0.0});
    const double gap = std::hypot(start[0] - end[0], start[1] - end[1]);
    if (sharp) {
      EXPECT_LT(gap, 1e-12) << what;  // closed
      // A C0 corner: the tangents at the two ends are not parallel (the wedge is 16.5 degrees).
      EXPECT_GT(std::numbers::pi - TangentAngle(fit->curve, 0.0, 1.0), 0.25) << what;
    } else {
      EXPECT_NEAR(gap, 2 * 0.6 * 0.0021, 1e-6) << what;  // 2 y_t(1) = 0.00252
    }
  }
  // Ends closer than the tolerance are one point, their midpoint.
  StructuredBlock almost = Shared("rae2822");
  const int m = static_cast<int>(almost.num_points());
  almost.Point(m - 1, 0, 0)[1] += 0.5 * kTolerance;
  absl::StatusOr<AirfoilFit> fit = FitAirfoil(almost, AirfoilFitOptions());
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_TRUE(fit->sharp_trailing_edge);
  EXPECT_NEAR(fit->distances.front(), 0.25 * kTolerance, 1e-12);
  EXPECT_NEAR(fit->distances.back(), 0.25 * kTolerance, 1e-12);
}

TEST(AirfoilFitTest, FeaturePointsKeptLeadingEdgeSmooth) {
  // A tab bent up by atan(0.3) = 16.7 degrees at the upper-surface point x = 0.7.
  std::vector<double> xy = Naca4(0.0, 0.4, 0.12, false, 40);
  int kink = 0;  // the upper-surface point nearest x = 0.7
  while (xy[2 * kink] > 0.7) ++kink;
  const double hinge = xy[2 * kink];
  for (int i = 0; i < kink; ++i) xy[2 * i + 1] += 0.3 * (xy[2 * i] - hinge);
  AirfoilFitOptions options;
  options.features.angle_degrees = 10.0;
  const StructuredBlock block = Outline(xy);
  absl::StatusOr<AirfoilFit> fit = FitAirfoil(block, options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  ExpectWithinTolerance(*fit, block, kTolerance, "kinked NACA 0012");
  EXPECT_THAT(fit->features, ::testing::ElementsAre(kink));
  EXPECT_LT(fit->distances[kink], 1e-12);  // the pinned control is the data point
  const double u = fit->params[kink];
  EXPECT_GT(TangentAngle(fit->curve, u - 1e-9, u + 1e-9), 0.25);  // the corner is kept
  EXPECT_EQ(fit->curvature.piece_extrema.size(), 3u);  // split at the feature and at the nose

  // The NACA 0012 file turns by 29.6 degrees at its leading-edge point: a feature for
  // DetectFeatures at 20 degrees, but the nose stays smooth.
  options.features.angle_degrees = 20.0;
  const StructuredBlock naca = Shared("naca0012");
  EXPECT_FALSE(DetectFeatures(naca, 0, options.features).empty());
  fit = FitAirfoil(naca, options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_TRUE(fit->features.empty());
  ExpectWithinTolerance(*fit, naca, kTolerance, "naca0012, features at 20 degrees");
}

// Coarse to fine (airfoil_fit.h, step 3) keeps every 4th point and the anchors: a feature at
// point 3 leaves the segment before it with no coarse point inside, too few for its controls.
// The fit must then start from scratch, not fail. A 90-degree kink where a straight tab of 4
// points meets a 2,400-point ellipse.
TEST(AirfoilFitTest, DenseOutlineWithAFeatureNearItsEnd) {
  std::vector<double> xy = {1.15, 0.0, 1.10, 0.0, 1.05, 0.0};
  constexpr int kEllipse = 2400;
  for (int q = 0; q < kEllipse; ++q) {
    const double t = 2.0 * std::numbers::pi * q / kEllipse;
    xy.push_back(0.5 + 0.5 * std::cos(t));
    xy.push_back(0.06 * std::sin(t));
  }
  const StructuredBlock block = Outline(xy);
  absl::StatusOr<AirfoilFit> fit = FitAirfoil(block, {});
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_THAT(fit->features, ::testing::ElementsAre(3));
  EXPECT_TRUE(fit->met) << fit->unmet_reason;
  EXPECT_LE(fit->max_deviation, kTolerance);
}

TEST(AirfoilFitTest, FairingKeepsToleranceAndDoesNotRoughen) {
  for (const std::string name : {"rae2822", "naca0012", "sc20714"}) {
    for (const double headroom : {1.0, 0.7}) {
      const std::string what = name + " headroom " + std::to_string(headroom);
      AirfoilFitOptions options;
      options.fairing_headroom = headroom;
      absl::StatusOr<AirfoilFit> fit = FitAirfoil(Shared(name), options);
      ASSERT_TRUE(fit.ok()) << what << ": " << fit.status();
      EXPECT_TRUE(fit->met) << what << ": " << fit->unmet_reason;
      EXPECT_LE(fit->max_deviation, kTolerance) << what;
      EXPECT_LE(fit->curvature.total.sum_squared_differences,
                fit->unfaired_curvature.total.sum_squared_differences)
          << what;
      EXPECT_LE(fit->curvature.spurious(), fit->unfaired_curvature.spurious()) << what;
    }
  }
  // With room left by the knots, fairing acts: NACA 0012 with the knots of insertion alone
  // (with removal and merges its 11 controls are fairer unfaired than the 14 of insertion faired:
  // sum of squared curvature differences 566 against 570, and no lambda lowers it further).
  // Measured lambda 2.7e-4.
  AirfoilFitOptions options;
  options.fairing_headroom = 0.7;
  options.remove_knots = false;
  absl::StatusOr<AirfoilFit> faired = FitAirfoil(Shared("naca0012"), options);
  ASSERT_TRUE(faired.ok()) << faired.status();
  EXPECT_GT(faired->fairing_weight, 1e-5);
  EXPECT_LT(faired->curvature.total.sum_squared_differences,
            faired->unfaired_curvature.total.sum_squared_differences);
  // Off: the least-squares curve.
  options.fairing.mode = FairingMode::kOff;
  absl::StatusOr<AirfoilFit> plain = FitAirfoil(Shared("naca0012"), options);
  ASSERT_TRUE(plain.ok()) << plain.status();
  EXPECT_EQ(plain->fairing_weight, 0.0);
  EXPECT_EQ(plain->curvature.total.sum_squared_differences,
            plain->unfaired_curvature.total.sum_squared_differences);
}

TEST(AirfoilFitTest, FewestPointsAndHighOrders) {
  const std::vector<double> xy = {1.0, 0.0, 0.5, 0.06, 0.0, 0.0, 0.5, -0.04, 1.0, 0.0};
  for (const int order : {3, 4, 5}) {
    AirfoilFitOptions options;
    options.order = order;
    absl::StatusOr<AirfoilFit> fit = FitAirfoil(Outline(xy), options);
    ASSERT_TRUE(fit.ok()) << "order " << order << ": " << fit.status();
    EXPECT_TRUE(fit->met) << "order " << order << ": " << fit->unmet_reason;
    EXPECT_TRUE(fit->sharp_trailing_edge);
  }
  AirfoilFitOptions options;
  options.order = 6;
  EXPECT_THAT(std::string(FitAirfoil(Outline(xy), options).status().message()),
              HasSubstr("points: 5 points are too few, order 6"));
}

TEST(AirfoilFitTest, ControlCapIsReportedNotAnError) {
  AirfoilFitOptions options;
  options.max_control_points = 8;
  absl::StatusOr<AirfoilFit> fit = FitAirfoil(Shared("rae2822"), options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_FALSE(fit->met);
  EXPECT_EQ(fit->num_control_points, 8);
  EXPECT_GT(fit->max_deviation, kTolerance);
  EXPECT_THAT(fit->unmet_reason, HasSubstr(absl::StrCat("point ", fit->worst_point, " at (")));
  EXPECT_THAT(fit->unmet_reason, HasSubstr("cap 8"));
}

TEST(AirfoilFitTest, CancelStopsTheFit) {
  AirfoilFitOptions options;
  options.cancel = [] { return true; };
  EXPECT_EQ(FitAirfoil(Shared("rae2822"), options).status().code(), absl::StatusCode::kCancelled);
}

TEST(AirfoilFitTest, BadInputNamesTheField) {
  const std::vector<double> good = Naca4(0.0, 0.4, 0.12, false, 10);
  auto with = [&](auto change) {
    std::vector<double> xy = good;
    change(xy);
    return Outline(xy);
  };
  struct Case {
    std::string what;
    StructuredBlock points;
    AirfoilFitOptions options;
    std::string message;
  };
  std::vector<Case> cases;
  auto add = [&](std::string what, StructuredBlock points, auto set, std::string message) {
    AirfoilFitOptions options;
    set(options);
    cases.push_back({std::move(what), std::move(points), std::move(options), std::move(message)});
  };
  const auto keep = [](AirfoilFitOptions&) {};
  add("4 points", Outline({1, 0, 0, 0.1, 0, 0, 1, -0.01}), keep, "points: 4 points");
  add("NaN", with([](auto& xy) { xy[7] = std::nan(""); }), keep, "points: point (3, 0, 0)");
  add("repeat", with([](auto& xy) { xy[8] = xy[6], xy[9] = xy[7]; }), keep, "point 4 at (");
  add("swapped", with([](auto& xy) { std::swap(xy[6], xy[10]), std::swap(xy[7], xy[11]); }), keep,
      "points: the outline crosses itself");
  add("3D", StructuredBlock({12, 1, 1}, 3), keep, "points spatial_dim = 3");
  add("surface", StructuredBlock({6, 2, 1}, 2), keep, "points extents = (6, 2, 1)");
  add(
      "tolerance 0", Outline(good), [](auto& o) { o.tolerance = 0.0; }, "tolerance = 0");
  add(
      "tolerance NaN", Outline(good), [](auto& o) { o.tolerance = std::nan(""); },
      "tolerance = nan");
  add(
      "tolerance -1", Outline(good), [](auto& o) { o.tolerance = -1.0; }, "tolerance = -1");
  add(
      "order", Outline(good), [](auto& o) { o.order = 2; }, "order = 2");
  add(
      "cap", Outline(good), [](auto& o) { o.max_control_points = 3; }, "max_control_points = 3");
  add(
      "corrections", Outline(good), [](auto& o) { o.max_parameter_corrections = -1; },
      "max_parameter_corrections = -1");
  add(
      "headroom", Outline(good), [](auto& o) { o.fairing_headroom = 0.0; }, "fairing_headroom = 0");
  add(
      "weight", Outline(good), [](auto& o) { o.fairing.weight = -1.0; }, "fairing weight = -1");
  add(
      "level", Outline(good), [](auto& o) { o.curvature_level = 9; }, "curvature_level = 9");
  for (const Case& c : cases) {
    absl::StatusOr<AirfoilFit> fit = FitAirfoil(c.points, c.options);
    EXPECT_EQ(fit.status().code(), absl::StatusCode::kInvalidArgument) << c.what;
    EXPECT_THAT(std::string(fit.status().message()), HasSubstr(c.message)) << c.what;
  }
}

}  // namespace
}  // namespace splinegrid
