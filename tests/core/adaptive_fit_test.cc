// FitToTolerance: synthetic smooth, kinked and noisy data, the shared C-grids at the paper's
// scale of tolerances, argument errors and cancellation. Every "met" is verified independently
// with MeasureDeviation at the fitted block's own parameters.
#include "core/fit/adaptive/adaptive_fit.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/bspline/evaluation.h"
#include "core/io/planar_view.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

// MeasureDeviation and the fit's own ratio test round differently: a point reported within
// tolerance may exceed it by this relative amount.
constexpr double kToleranceRounding = 1e-12;
// A FitToTolerance call that gives up (cap or iteration limit) must do so quickly.
constexpr double kGiveUpSeconds = 2.0;

// Independent check of a tolerance fit: the deviation of the returned spline at the returned
// distribution's parameters, against the data.
Deviation Remeasure(const ToleranceFitResult& result, const StructuredBlock& block) {
  const PointDistribution& dist = result.fitted.distribution;
  absl::StatusOr<Deviation> dev = MeasureDeviation(
      result.fitted.spline, {dist.params(0), dist.params(1), dist.params(2)}, block);
  EXPECT_TRUE(dev.ok()) << dev.status();
  return dev.ok() ? *dev : Deviation{};
}

// Checks what every successful tolerance fit must satisfy, whether met or not.
void ExpectConsistentSummary(const ToleranceFitResult& result, const StructuredBlock& block,
                             double tolerance) {
  const FitSummary& summary = result.fitted.summary;
  EXPECT_EQ(summary.num_points, block.num_points());
  EXPECT_EQ(summary.num_control_points, result.fitted.spline.num_control_points());
  EXPECT_DOUBLE_EQ(summary.compression_ratio,
                   static_cast<double>(block.num_points()) / summary.num_control_points);
  const Deviation dev = Remeasure(result, block);
  EXPECT_NEAR(dev.max, summary.deviation.max, kToleranceRounding * (1.0 + dev.max));
  EXPECT_NEAR(result.worst_ratio, dev.max / tolerance, kToleranceRounding * result.worst_ratio);
  EXPECT_EQ(result.met, result.worst_ratio <= 1.0);
  if (result.met) {
    EXPECT_LE(dev.max, tolerance * (1.0 + kToleranceRounding));
    EXPECT_TRUE(result.unmet_reason.empty()) << result.unmet_reason;
  } else {
    EXPECT_GT(dev.max, tolerance);
  }
}

absl::StatusOr<ToleranceFitResult> Fit(const StructuredBlock& block, double tolerance,
                                       const ToleranceFitOptions& options = {}) {
  const std::vector<double> tol = {tolerance};
  return FitToTolerance(block, tol, options);
}

// ----- Synthetic data ---------------------------------------------------------------------------

// A smooth, curved 3D surface patch on a stretched 61 x 41 grid.
StructuredBlock SmoothSurface() {
  StructuredBlock block({61, 41, 1}, 3);
  for (int j = 0; j < 41; ++j) {
    for (int i = 0; i < 61; ++i) {
      const double u = std::pow(i / 60.0, 1.2), v = j / 40.0;
      double* p = block.Point(i, j, 0);
      p[0] = 2.0 * u;
      p[1] = 1.5 * v + 0.1 * u * u;
      p[2] = 0.3 * std::sin(2.0 * u) * std::cos(3.0 * v);
    }
  }
  return block;
}

// The 2D curve y = |x - 0.3| + 0.2 x^2 on x in [-1, 1] (201 points, the kink at index 130),
// made of two smooth arcs that meet at a right-ish angle.
constexpr int kKinkIndex = 130;
StructuredBlock KinkedCurve() {
  StructuredBlock block({201, 1, 1}, 2);
  for (int r = 0; r < 201; ++r) {
    const double x = r == kKinkIndex ? 0.3 : -1.0 + 0.01 * r;
    block.Point(r, 0, 0)[0] = x;
    block.Point(r, 0, 0)[1] = std::abs(x - 0.3) + 0.2 * x * x;
  }
  return block;
}

// A gently curved 41 x 41 surface with uniform noise of amplitude 1e-2 (fixed seed).
StructuredBlock NoisySurface() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> noise(-1e-2, 1e-2);
  StructuredBlock block({41, 41, 1}, 3);
  for (int j = 0; j < 41; ++j) {
    for (int i = 0; i < 41; ++i) {
      const double u = i / 40.0, v = j / 40.0;
      double* p = block.Point(i, j, 0);
      p[0] = u;
      p[1] = v;
      p[2] = 0.2 * u * v + noise(rng);
    }
  }
  return block;
}

TEST(FitToToleranceTest, SmoothSurfaceIsMetWithFewControls) {
  const StructuredBlock block = SmoothSurface();
  for (double tolerance : {1e-4, 1e-6}) {
    SCOPED_TRACE(absl::StrCat("tolerance ", tolerance));
    const absl::StatusOr<ToleranceFitResult> result = Fit(block, tolerance);
    ASSERT_TRUE(result.ok()) << result.status();
    EXPECT_TRUE(result->met) << result->unmet_reason;
    ExpectConsistentSummary(*result, block, tolerance);
    EXPECT_TRUE(result->features[0].empty() && result->features[1].empty());
    const Extents n = result->fitted.spline.control_extents();
    EXPECT_LE(n[0], tolerance > 1e-5 ? 10 : 24);
    EXPECT_LE(n[1], tolerance > 1e-5 ? 12 : 24);
    EXPECT_EQ(n[2], 1);
    EXPECT_GT(result->fitted.summary.compression_ratio, tolerance > 1e-5 ? 30.0 : 5.0);
    EXPECT_GT(result->knots_inserted, 0);
  }
}

TEST(FitToToleranceTest, KinkIsAFeatureAndIsMetWithFewControls) {
  const StructuredBlock block = KinkedCurve();
  for (double tolerance : {1e-5, 1e-7}) {
    SCOPED_TRACE(absl::StrCat("tolerance ", tolerance));
    const absl::StatusOr<ToleranceFitResult> result = Fit(block, tolerance);
    ASSERT_TRUE(result.ok()) << result.status();
    EXPECT_TRUE(result->met) << result->unmet_reason;
    ExpectConsistentSummary(*result, block, tolerance);
    EXPECT_EQ(result->features[0], std::vector<int>{kKinkIndex});
    EXPECT_LE(result->fitted.spline.control_extents()[0], tolerance > 1e-6 ? 15 : 35);
    // The kink has a knot of multiplicity order - 1 at its parameter...
    const double u_kink = result->fitted.distribution.params(0)[kKinkIndex];
    const KnotVector& knots = result->fitted.spline.knots(0);
    EXPECT_EQ(knots.Multiplicity(u_kink), knots.order() - 1);
    // ... and the fit passes through it (to rounding).
    const Point3 p = EvaluatePoint(result->fitted.spline, {u_kink, 0.0, 0.0});
    EXPECT_NEAR(p[0], block.Point(kKinkIndex, 0, 0)[0], 1e-15);
    EXPECT_NEAR(p[1], block.Point(kKinkIndex, 0, 0)[1], 1e-15);
  }
}

// Without feature detection the same curve needs many more controls (the kink is only
// approximated by dense knots), which is what the feature saves.
TEST(FitToToleranceTest, KinkWithoutFeatureDetectionNeedsManyMoreControls) {
  const StructuredBlock block = KinkedCurve();
  ToleranceFitOptions options;
  options.features.detect = false;
  const absl::StatusOr<ToleranceFitResult> plain = Fit(block, 1e-5, options);
  // Not meeting a tolerance is not an error (adaptive_fit.h): a result must come back.
  ASSERT_TRUE(plain.ok()) << plain.status();
  ExpectConsistentSummary(*plain, block, 1e-5);
  EXPECT_TRUE(plain->features[0].empty());
  const absl::StatusOr<ToleranceFitResult> with_feature = Fit(block, 1e-5);
  ASSERT_TRUE(with_feature.ok()) << with_feature.status();
  EXPECT_GT(plain->fitted.spline.control_extents()[0],
            3 * with_feature->fitted.spline.control_extents()[0]);
}

// Noise far above the tolerance cannot be met under a control cap: the result says so, names
// the worst point, respects the cap and returns quickly.
TEST(FitToToleranceTest, NoisyDataUnderACapIsReportedUnmet) {
  const StructuredBlock block = NoisySurface();
  for (bool detect_features : {false, true}) {
    SCOPED_TRACE(detect_features ? "with feature detection" : "without feature detection");
    ToleranceFitOptions options;
    options.max_controls_per_direction = 12;
    options.features.detect = detect_features;
    const auto start = std::chrono::steady_clock::now();
    const absl::StatusOr<ToleranceFitResult> result = Fit(block, 1e-5, options);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(result.ok()) << result.status();
    EXPECT_LT(seconds, kGiveUpSeconds);
    EXPECT_FALSE(result->met);
    ExpectConsistentSummary(*result, block, 1e-5);
    EXPECT_GT(result->worst_ratio, 100.0);  // the noise is ~1000 tolerances
    EXPECT_LE(result->iterations, options.max_iterations);
    const Extents& at = result->worst_at;
    EXPECT_THAT(result->unmet_reason,
                HasSubstr(absl::StrCat("point (", at[0], ", ", at[1], ", ", at[2], ")")));
    EXPECT_THAT(result->unmet_reason, HasSubstr("cap 12 per direction"));
    // The worst point is where the remeasured deviation is largest.
    EXPECT_EQ(at, Remeasure(*result, block).max_at);
    // "Most control points per direction" (adaptive_fit.h), feature knots included.
    const Extents n = result->fitted.spline.control_extents();
    EXPECT_LE(n[0], 12);
    EXPECT_LE(n[1], 12);
  }
}

// Without a cap the iteration limit ends the refinement: a hard tolerance with few rounds.
TEST(FitToToleranceTest, IterationLimitEndsTheRefinement) {
  const StructuredBlock block = SmoothSurface();
  ToleranceFitOptions options;
  options.max_iterations = 1;
  options.remove_unneeded_knots = false;
  const absl::StatusOr<ToleranceFitResult> result = Fit(block, 1e-9, options);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_FALSE(result->met);
  EXPECT_EQ(result->iterations, 1);
  ExpectConsistentSummary(*result, block, 1e-9);
  EXPECT_THAT(result->unmet_reason, HasSubstr("after 1 refinement rounds"));
}

// Per-point tolerances: loose everywhere except one row, which then drives the knots.
TEST(FitToToleranceTest, PerPointTolerancesAreHonoured) {
  const StructuredBlock block = SmoothSurface();
  std::vector<double> tolerance(block.num_points(), 1e-2);
  for (int i = 0; i < block.extent(0); ++i) tolerance[block.Index(i, 0, 0)] = 1e-7;
  const absl::StatusOr<ToleranceFitResult> result =
      FitToTolerance(block, tolerance, ToleranceFitOptions());
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_TRUE(result->met) << result->unmet_reason;
  const Deviation dev = Remeasure(*result, block);
  const PointDistribution& dist = result->fitted.distribution;
  for (int j = 0; j < block.extent(1); ++j) {
    for (int i = 0; i < block.extent(0); ++i) {
      const Point3 p =
          EvaluatePoint(result->fitted.spline, {dist.params(0)[i], dist.params(1)[j], 0.0});
      const double* q = block.Point(i, j, 0);
      const double d = std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
      ASSERT_LE(d, tolerance[block.Index(i, j, 0)] * (1.0 + kToleranceRounding) + 1e-15)
          << i << ", " << j;
    }
  }
  EXPECT_GT(dev.max, 1e-7);  // the loose points were not fitted to the tight tolerance
}

// ----- Shared grids -----------------------------------------------------------------------------

// The 2D grid of shared file `relative` (planar view for two-plane files).
StructuredBlock SharedPlanarBlock(const std::string& relative) {
  absl::StatusOr<MultiBlockGrid> grid = ReadPlot3dFile(SharedDataPath(relative));
  EXPECT_TRUE(grid.ok()) << grid.status();
  if (!grid.ok()) return StructuredBlock();
  absl::StatusOr<MultiBlockGrid> planar = AsPlanarGrid(*grid);
  EXPECT_TRUE(planar.ok()) << planar.status();
  return planar.ok() ? planar->blocks[0] : StructuredBlock();
}

// The paper's scale of tolerances (chords) on the NACA 0012 and RAE 2822 C-grids.
TEST(FitToToleranceTest, SharedCGridsMeetChordTolerances) {
  for (const std::string file : {"grids/n0012_113-33.p2dfmt", "grids/rae2822_257x97.fmt"}) {
    const StructuredBlock block = SharedPlanarBlock(file);
    ASSERT_EQ(block.spatial_dim(), 2) << file;
    int previous_controls = 0;
    for (double tolerance : {1e-2, 1e-3}) {
      SCOPED_TRACE(absl::StrCat(file, ", tolerance ", tolerance));
      const absl::StatusOr<ToleranceFitResult> result = Fit(block, tolerance);
      ASSERT_TRUE(result.ok()) << result.status();
      EXPECT_TRUE(result->met) << result->unmet_reason;
      ExpectConsistentSummary(*result, block, tolerance);
      // Compression is reported and real: fewer control points than grid points.
      EXPECT_GT(result->fitted.summary.compression_ratio, 1.2);
      EXPECT_LT(result->fitted.summary.num_control_points, block.num_points());
      // A tighter tolerance never needs fewer controls here.
      EXPECT_GE(result->fitted.summary.num_control_points, previous_controls);
      previous_controls = result->fitted.summary.num_control_points;
      // The C-grid's wake cut meets the airfoil at the trailing edge: a feature in i.
      EXPECT_FALSE(result->features[0].empty());
    }
  }
}

// "Not meeting the tolerance is not an error" (adaptive_fit.h): the paper's wall tolerance,
// 0.15e-3 chords, on a shared C-grid, with or without feature detection, must give a result
// (met, or unmet with a reason), never an error.
void ExpectResultAtWallTolerance(const std::string& file) {
  const StructuredBlock block = SharedPlanarBlock(file);
  for (bool detect_features : {true, false}) {
    SCOPED_TRACE(absl::StrCat(file, detect_features ? ", features" : ", no features"));
    ToleranceFitOptions options;
    options.features.detect = detect_features;
    const absl::StatusOr<ToleranceFitResult> result = Fit(block, 1.5e-4, options);
    ASSERT_TRUE(result.ok()) << result.status();
    ExpectConsistentSummary(*result, block, 1.5e-4);
  }
}

TEST(FitToToleranceTest, Naca0012AtWallToleranceReturnsAResult) {
  ExpectResultAtWallTolerance("grids/n0012_113-33.p2dfmt");
}

TEST(FitToToleranceTest, Rae2822AtWallToleranceReturnsAResult) {
  ExpectResultAtWallTolerance("grids/rae2822_257x97.fmt");
}

// ----- Errors -----------------------------------------------------------------------------------

TEST(FitToToleranceTest, RejectsInvalidTolerancesNamingFieldAndValue) {
  const StructuredBlock block = SmoothSurface();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    std::vector<double> tolerance;
    std::string message;
  };
  std::vector<double> one_nan(block.num_points(), 1e-3);
  one_nan[7] = nan;
  std::vector<double> one_negative(block.num_points(), 1e-3);
  one_negative[block.num_points() - 1] = -2.0;
  const std::vector<Case> cases = {
      {{0.0}, "tolerance = 0;"},
      {{-1e-3}, "tolerance = -0.001;"},
      {{nan}, "tolerance = nan;"},
      {{inf}, "tolerance = inf;"},
      {one_nan, "tolerance[7] = nan;"},
      {one_negative, absl::StrCat("tolerance[", block.num_points() - 1, "] = -2;")},
      {{1e-3, 1e-3, 1e-3}, absl::StrCat("tolerance: 3 values for ", block.num_points(), " points")},
      {{}, absl::StrCat("tolerance: 0 values for ", block.num_points(), " points")},
  };
  for (const Case& c : cases) {
    const absl::StatusOr<ToleranceFitResult> result =
        FitToTolerance(block, c.tolerance, ToleranceFitOptions());
    EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument) << c.message;
    EXPECT_THAT(result.status().message(), HasSubstr(c.message));
  }
}

TEST(FitToToleranceTest, RejectsInvalidOptionsAndData) {
  StructuredBlock block = SmoothSurface();
  ToleranceFitOptions options;
  options.order = 1;
  EXPECT_THAT(Fit(block, 1e-3, options).status().message(), HasSubstr("order = 1"));
  options.order = kMaxOrder + 1;
  EXPECT_THAT(Fit(block, 1e-3, options).status().message(),
              HasSubstr(absl::StrCat("order = ", kMaxOrder + 1)));
  options = ToleranceFitOptions();
  options.max_controls_per_direction = -3;
  EXPECT_THAT(Fit(block, 1e-3, options).status().message(),
              HasSubstr("max_controls_per_direction = -3"));
  block.Point(4, 9, 0)[2] = std::numeric_limits<double>::infinity();
  const absl::Status status = Fit(block, 1e-3).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("point (4, 9, 0) coordinate z is inf"));
}

TEST(FitToToleranceTest, HonoursCancellation) {
  const StructuredBlock block = SharedPlanarBlock("grids/rae2822_257x97.fmt");
  // The number of polls of a whole fit.
  int total_polls = 0;
  ToleranceFitOptions counting;
  counting.cancel = [&total_polls] {
    ++total_polls;
    return false;
  };
  ASSERT_TRUE(Fit(block, 1e-3, counting).ok());
  ASSERT_GT(total_polls, 20);
  // Cancelled from the start, and after a number of polls (inside the refinement or the knot
  // removal): always CANCELLED, never a partial result.
  for (int allowed_polls : {0, 1, total_polls / 4, total_polls / 2}) {
    ToleranceFitOptions options;
    int polls = 0;
    options.cancel = [&polls, allowed_polls] { return ++polls > allowed_polls; };
    const absl::StatusOr<ToleranceFitResult> result = Fit(block, 1e-3, options);
    EXPECT_EQ(result.status().code(), absl::StatusCode::kCancelled)
        << "after " << allowed_polls << " polls: " << result.status();
  }
}

// A check that fires during the last trial fit of the knot removal must still end the fit with
// CANCELLED (tensor_fit.h: "a fired check ends the fit with CANCELLED"), not be taken for a
// knot that cannot be removed. Scans every poll of a small fit.
TEST(FitToToleranceTest, CancellationIsNeverSwallowed) {
  const StructuredBlock block = SmoothSurface();
  int total_polls = 0;
  ToleranceFitOptions counting;
  counting.cancel = [&total_polls] {
    ++total_polls;
    return false;
  };
  const absl::StatusOr<ToleranceFitResult> full = Fit(block, 1e-4, counting);
  ASSERT_TRUE(full.ok()) << full.status();
  ASSERT_GT(full->knots_removed, 0);  // the scan covers the knot removal
  for (int allowed_polls = 0; allowed_polls < total_polls; ++allowed_polls) {
    ToleranceFitOptions options;
    int polls = 0;
    options.cancel = [&polls, allowed_polls] { return ++polls > allowed_polls; };
    EXPECT_EQ(Fit(block, 1e-4, options).status().code(), absl::StatusCode::kCancelled)
        << "the check fired from poll " << allowed_polls + 1 << " of " << total_polls;
  }
}

}  // namespace
}  // namespace splinegrid
