// Airfoil fits of dense, noisy profiles (issue 13, point 4): the shared outlines densified to
// 10k-20k points with an interpolating spline and noise of 1e-6 chord fit within the tolerance,
// with no cusp, and with no more controls than the same profile at a quarter of the density
// plus 10%.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <numbers>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/bspline/evaluation.h"
#include "core/bspline/knot_vector.h"
#include "core/bspline/parametrization.h"
#include "core/bspline/tensor_spline.h"
#include "core/fit/airfoil/airfoil_fit.h"
#include "core/fit/solve/direction_fit.h"
#include "core/io/airfoil.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

// Noise of the dense profiles, in chords (the issue's).
constexpr double kNoise = 1e-6;
// The noise is tapered to 0 over this length (in chords) at the trailing edge.
constexpr double kTaper = 0.01;
// Controls of the dense fit may exceed those of the quarter-density fit by this fraction.
constexpr double kControlSlack = 0.10;

StructuredBlock Shared(const std::string& name) {
  absl::StatusOr<AirfoilCoordinates> airfoil =
      ReadAirfoilFile(SharedDataPath("airfoils/" + name + ".dat"));
  EXPECT_TRUE(airfoil.ok()) << airfoil.status();
  return airfoil.ok() ? airfoil->points : StructuredBlock();
}

// Largest distance of a point of `block` from its first point: the chord for an outline in
// Selig order.
double Chord(const StructuredBlock& block) {
  const double* te = block.Point(0, 0, 0);
  double chord = 0.0;
  for (int i = 0; i < block.extent(0); ++i) {
    const double* p = block.Point(i, 0, 0);
    chord = std::max(chord, std::hypot(p[0] - te[0], p[1] - te[1]));
  }
  return chord;
}

// Turning angle of the polyline at point r (0 at the ends).
double Turning(const StructuredBlock& block, int r) {
  if (r <= 0 || r + 1 >= block.extent(0)) return 0.0;
  const double *a = block.Point(r - 1, 0, 0), *b = block.Point(r, 0, 0),
               *c = block.Point(r + 1, 0, 0);
  const double ux = b[0] - a[0], uy = b[1] - a[1], vx = c[0] - b[0], vy = c[1] - b[1];
  return std::abs(std::atan2(ux * vy - uy * vx, ux * vx + uy * vy));
}

// `coarse` densified to about `target` points: the outline is cut at its kinks (turning by more
// than 5 degrees and twice both neighbours, as a cove corner does), each piece interpolated by
// a cubic spline (centripetal parameters, knot averaging) and sampled between consecutive data
// points uniformly in its parameter, each interval getting samples in proportion to its length
// (at least its start point, so the coarse points are all kept); then every coordinate of every
// point gets Gaussian noise of standard deviation kNoise chords (fixed seed), tapered to 0 over
// kTaper chords at the trailing edge (where the surfaces are closer than the noise).
// With `own_spacing` every interval gets the same number of samples instead: the file's own
// spacing, refined (very dense where the file is dense, at the nose).
StructuredBlock Densify(const StructuredBlock& coarse, int target, uint64_t seed,
                        bool own_spacing = false) {
  const int m = coarse.extent(0);
  const double chord = Chord(coarse);
  std::vector<double> length(m - 1);
  for (int i = 0; i + 1 < m; ++i) {
    const double *p = coarse.Point(i, 0, 0), *q = coarse.Point(i + 1, 0, 0);
    length[i] = std::hypot(q[0] - p[0], q[1] - p[1]);
  }
  const double total = std::accumulate(length.begin(), length.end(), 0.0);
  std::vector<int> cuts = {0};
  for (int r = 1; r + 1 < m; ++r) {
    const double t = Turning(coarse, r);
    if (t > 5.0 * std::numbers::pi / 180.0 &&
        t > 2.0 * std::max(Turning(coarse, r - 1), Turning(coarse, r + 1)) &&
        r - cuts.back() >= 4 && m - 1 - r >= 4) {
      cuts.push_back(r);
    }
  }
  cuts.push_back(m - 1);
  std::vector<double> xy;
  for (size_t c = 0; c + 1 < cuts.size(); ++c) {
    const int r0 = cuts[c], n = cuts[c + 1] - r0 + 1;
    StructuredBlock piece({n, 1, 1}, 2);
    for (int i = 0; i < n; ++i) std::copy_n(coarse.Point(r0 + i, 0, 0), 2, piece.Point(i, 0, 0));
    const std::vector<double> u = ParametrizeBlock(piece, Parametrization::kCentripetal)[0];
    absl::StatusOr<KnotVector> knots = KnotVector::Averaged(4, n, u);
    EXPECT_TRUE(knots.ok()) << knots.status();
    absl::StatusOr<DirectionFit> fit = DirectionFit::Create(*knots, u, EndCondition::kInterpolate);
    EXPECT_TRUE(fit.ok()) << fit.status();
    std::vector<double> control(2 * n);
    EXPECT_TRUE(fit->Apply(piece.coords().data(), 2, 1, control.data()).ok());
    absl::StatusOr<TensorSpline> spline =
        TensorSpline::Create({*knots, KnotVector(), KnotVector()}, 2, control);
    EXPECT_TRUE(spline.ok()) << spline.status();
    std::vector<double> samples;
    for (int i = 0; i + 1 < n; ++i) {
      const double share = own_spacing ? 1.0 / (m - 1) : length[r0 + i] / total;
      const int per = std::max(1, static_cast<int>(std::lround(target * share)));
      for (int j = 0; j < per; ++j) samples.push_back(u[i] + (u[i + 1] - u[i]) * j / per);
    }
    if (c + 2 == cuts.size()) samples.push_back(1.0);  // the last piece ends the outline
    const StructuredBlock dense = EvaluateGrid(*spline, {samples, {0.0}, {0.0}});
    xy.insert(xy.end(), dense.coords().begin(), dense.coords().end());
  }
  std::mt19937_64 random(seed);
  std::normal_distribution<double> noise(0.0, kNoise * chord);
  for (size_t i = 2; i + 2 < xy.size(); i += 2) {  // the trailing-edge points stay
    const double taper =
        std::min(1.0, std::hypot(xy[i] - xy[0], xy[i + 1] - xy[1]) / (kTaper * chord));
    xy[i] += taper * noise(random);
    xy[i + 1] += taper * noise(random);
  }
  StructuredBlock block({static_cast<int>(xy.size() / 2), 1, 1}, 2);
  std::copy(xy.begin(), xy.end(), block.coords().begin());
  return block;
}

// Every `stride`-th point of `block`, and its last.
StructuredBlock Thin(const StructuredBlock& block, int stride) {
  std::vector<double> xy;
  const int m = block.extent(0);
  for (int i = 0; i < m; i += stride)
    xy.insert(xy.end(), block.Point(i, 0, 0), block.Point(i, 0, 0) + 2);
  if ((m - 1) % stride != 0)
    xy.insert(xy.end(), block.Point(m - 1, 0, 0), block.Point(m - 1, 0, 0) + 2);
  StructuredBlock out({static_cast<int>(xy.size() / 2), 1, 1}, 2);
  std::copy(xy.begin(), xy.end(), out.coords().begin());
  return out;
}

// Fits `data` at `tolerance` (in the data's unit) and checks the contract of point 4: met,
// within the tolerance, no cusp (peak curvature within kCurvatureGuard times the reference's).
struct Measured {
  int points = 0;
  int controls = 0;
  double deviation = 0.0;  // in chords
  double ms = 0.0;
};
Measured FitAndCheck(const StructuredBlock& data, double tolerance, double chord,
                     const std::string& what) {
  AirfoilFitOptions options;
  options.tolerance = tolerance;
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<AirfoilFit> fit = FitAirfoil(data, options);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(fit.ok()) << what << ": " << fit.status();
  if (!fit.ok()) return {};
  EXPECT_TRUE(fit->met) << what << ": " << fit->unmet_reason;
  EXPECT_LE(fit->max_deviation, tolerance) << what;
  EXPECT_LE(fit->curvature.total.max_abs_curvature,
            2.0 * fit->reference_curvature.total.max_abs_curvature)
      << what;
  const Measured out{data.extent(0), fit->num_control_points, fit->max_deviation / chord, ms};
  std::cout << what << ": " << out.points << " points, " << out.controls << " controls, "
            << fit->features.size() << " features, " << fit->fits << " fits, "
            << out.deviation << " chords, " << ms << " ms\n";
  return out;
}

struct Case {
  std::string name;  // under airfoils/
  int points;        // of the dense outline
  double tolerance;  // in chords
};

// The dense outline, every 4th of its points and the shared outline densified to a quarter of
// the points with other noise (seed 29) fit within the tolerance; the dense one with at most 10%
// more controls than either quarter (plus `extra`). Measured: dense, every 4th, resampled.
void CheckDenseAgainstQuarter(const Case& c, bool own_spacing = false, int extra = 0) {
  const StructuredBlock coarse = Shared(c.name);
  const double chord = Chord(coarse);
  const StructuredBlock dense = Densify(coarse, c.points, 13, own_spacing);
  const std::string what = absl::StrCat(c.name, " at ", c.tolerance, " chord");
  const Measured full = FitAndCheck(dense, c.tolerance * chord, chord, what + ", dense");
  const Measured thinned = FitAndCheck(Thin(dense, 4), c.tolerance * chord, chord, what + ", 1/4");
  const Measured resampled = FitAndCheck(Densify(coarse, c.points / 4, 29, own_spacing),
                                         c.tolerance * chord, chord, what + ", resampled 1/4");
  EXPECT_GE(full.points, 10000) << what;
  for (const Measured& quarter : {thinned, resampled}) {
    EXPECT_LE(full.controls, std::floor((1.0 + kControlSlack) * quarter.controls) + extra)
        << what << ", against " << quarter.points << " points";
  }
}

TEST(DenseProfileTest, Rae2822At12000Points) {
  CheckDenseAgainstQuarter({"rae2822", 12000, 1e-4});  // measured 14, 14 and 15 controls
}

// The file's own spacing refined about 93 times: at the nose the dense spacing is about the
// noise, so neighbouring segments turn by tens of degrees; the noise must not make kinks.
// Measured 15, 15 and 15 controls, no feature (with the turning between neighbouring segments:
// 1 false feature and 20 controls; 1-3 and up to 26 for the seeds 2-6).
TEST(DenseProfileTest, Rae2822At12000PointsWithTheFilesSpacing) {
  CheckDenseAgainstQuarter({"rae2822", 12000, 1e-4}, /*own_spacing=*/true, /*extra=*/1);
}

// A blunt trailing edge and a nose that the file samples coarsely: without the restricted
// correction every tolerance failed with a cusp and no span left to split (35 controls).
TEST(DenseProfileTest, Naca0012At20000Points) {
  CheckDenseAgainstQuarter({"naca0012", 20000, 1e-4});  // measured 16, 16 and 15
  CheckDenseAgainstQuarter({"naca0012", 20000, 5e-4});  // measured 12, 12 and 11
}

TEST(DenseProfileTest, Sc20714At16000Points) {
  CheckDenseAgainstQuarter({"sc20714", 16000, 1e-4});  // measured 18, 18 and 17
  // Before merges and coarse-to-fine placement (airfoil_fit.h): 15 against 13, over the bound.
  CheckDenseAgainstQuarter({"sc20714", 16000, 2e-4});  // measured 13, 13 and 13
}

// The 30P30N main element in the file's units (chord about 830): tolerances relative to it,
// two cove corners kept as features.
TEST(DenseProfileTest, HighLiftMainElementAt12000Points) {
  // Before coarse-to-fine placement (airfoil_fit.h, step 3) 1e-4 needed 26 controls against 23:
  // the quarter's knots, with its parameters carried over, fit the dense outline within 0.082 of
  // the 0.083 tolerance, but greedy insertion on all points did not find them.
  CheckDenseAgainstQuarter({"30p30n/30p30n_main", 12228, 1e-4});  // measured 23, 23 and 25
  CheckDenseAgainstQuarter({"30p30n/30p30n_main", 12228, 2e-4});  // measured 19, 19 and 20
  CheckDenseAgainstQuarter({"30p30n/30p30n_main", 12228, 5e-4});  // measured 18, 18 and 18
}

}  // namespace
}  // namespace splinegrid
