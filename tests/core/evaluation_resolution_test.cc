// Evaluating fitted shared grids at other resolutions: the original parameters reproduce the
// grid within the fit deviation, refinement keeps every original point bit for bit, a sub-box is
// a bitwise slice of the whole block, and GridEvaluator's derivatives match finite differences.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/bspline/evaluation.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/io/planar_view.h"
#include "core/io/plot3d.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

// Rounding of one evaluated point, relative to the largest coordinate magnitude of the block.
constexpr double kRoundingRelTol = 1e-13;
// Central differences with a step of kStepFraction times the local parameter spacing: the
// truncation error is ~(step / spacing)^2 / 6 of the derivative, the rounding error
// ~|X| eps / step.
constexpr double kStepFraction = 1e-3;
constexpr double kFiniteDifferenceRelTol = 2e-5;
// The rounding part of a central difference: kRoundingUlps units of |X| eps over the step.
constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
constexpr double kRoundingUlps = 8.0;

// A fitted shared block and the data it was fitted to.
struct FittedShared {
  std::string name;
  StructuredBlock block;
  FittedBlock fitted;
};

// Least-squares fits (about a third of the points, interpolated ends) of the NACA 0012 113 x 33
// C-grid (2D) and of the raw two-plane RAE 2822 block (3D: 2 x 257 x 97, linear between the
// planes), so that every direction and both spatial dimensions are covered.
const std::vector<FittedShared>& FittedSharedBlocks() {
  static const std::vector<FittedShared>* fits = [] {
    auto* out = new std::vector<FittedShared>;
    for (const auto& [file, counts] :
         std::vector<std::pair<std::string, Extents>>{{"grids/n0012_113-33.p2dfmt", {38, 12, 0}},
                                                      {"grids/rae2822_257x97.fmt", {0, 86, 33}}}) {
      absl::StatusOr<MultiBlockGrid> grid = ReadPlot3dFile(SharedDataPath(file));
      EXPECT_TRUE(grid.ok()) << grid.status();
      if (!grid.ok()) continue;
      FitOptions options;
      options.control_counts = counts;
      absl::StatusOr<FittedBlock> fitted = FitBlock(grid->blocks[0], options);
      EXPECT_TRUE(fitted.ok()) << fitted.status();
      if (!fitted.ok()) continue;
      out->push_back({file, grid->blocks[0], *std::move(fitted)});
    }
    return out;
  }();
  return *fits;
}

double MaxAbsCoordinate(const StructuredBlock& block) {
  double m = 0.0;
  for (double x : block.coords()) m = std::max(m, std::abs(x));
  return m;
}

double Distance(const double* a, const double* b, int s) {
  double sum = 0.0;
  for (int c = 0; c < s; ++c) sum += (a[c] - b[c]) * (a[c] - b[c]);
  return std::sqrt(sum);
}

// Parameters of refinement `level` over the index box [begin, end] (inclusive).
std::array<std::vector<double>, 3> RefinedParams(const PointDistribution& dist,
                                                 const Extents& begin, const Extents& end,
                                                 int level) {
  std::array<std::vector<double>, 3> params;
  for (int d = 0; d < 3; ++d) params[d] = dist.Refined(d, begin[d], end[d], level);
  return params;
}

Extents LastIndex(const StructuredBlock& block) {
  return {block.extent(0) - 1, block.extent(1) - 1, block.extent(2) - 1};
}

TEST(EvaluationResolutionTest, ReadsAndFitsTheSharedBlocks) {
  ASSERT_EQ(FittedSharedBlocks().size(), 2u);
  for (const FittedShared& f : FittedSharedBlocks()) {
    // A real least-squares fit: the deviation is well above rounding.
    EXPECT_GT(f.fitted.summary.deviation.max, 1e-6 * MaxAbsCoordinate(f.block)) << f.name;
  }
}

// Level 0 is the original parameters; evaluated there the spline is the fitted grid, within the
// reported deviation, with the reported worst point at the reported distance.
TEST(EvaluationResolutionTest, LevelZeroReproducesTheOriginalPoints) {
  for (const FittedShared& f : FittedSharedBlocks()) {
    SCOPED_TRACE(f.name);
    const PointDistribution& dist = f.fitted.distribution;
    const auto params = RefinedParams(dist, {0, 0, 0}, LastIndex(f.block), 0);
    for (int d = 0; d < 3; ++d) EXPECT_EQ(params[d], dist.params(d));
    const StructuredBlock grid = EvaluateGrid(f.fitted.spline, params);
    ASSERT_EQ(grid.extents(), f.block.extents());
    const Deviation& dev = f.fitted.summary.deviation;
    const double rounding = kRoundingRelTol * MaxAbsCoordinate(f.block);
    const int s = f.block.spatial_dim();
    double worst = 0.0;
    for (int64_t p = 0; p < f.block.num_points(); ++p) {
      const double d = Distance(grid.coords().data() + s * p, f.block.coords().data() + s * p, s);
      ASSERT_LE(d, dev.max + rounding) << "point " << p;
      worst = std::max(worst, d);
    }
    EXPECT_NEAR(worst, dev.max, rounding);
    const Extents at = dev.max_at;
    EXPECT_NEAR(Distance(grid.Point(at[0], at[1], at[2]), f.block.Point(at[0], at[1], at[2]), s),
                dev.max, rounding);
  }
}

// At refinement level l every original point reappears, bit for bit, at index i 2^l.
TEST(EvaluationResolutionTest, RefinedGridsKeepTheOriginalPointsBitwise) {
  for (const FittedShared& f : FittedSharedBlocks()) {
    const PointDistribution& dist = f.fitted.distribution;
    const Extents last = LastIndex(f.block);
    const StructuredBlock coarse =
        EvaluateGrid(f.fitted.spline, RefinedParams(dist, {0, 0, 0}, last, 0));
    for (int level : {1, 2}) {
      SCOPED_TRACE(absl::StrCat(f.name, ", level ", level));
      const int per = 1 << level;
      const StructuredBlock fine =
          EvaluateGrid(f.fitted.spline, RefinedParams(dist, {0, 0, 0}, last, level));
      for (int d = 0; d < 3; ++d) ASSERT_EQ(fine.extent(d), last[d] * per + 1);
      const int s = f.block.spatial_dim();
      for (int k = 0; k <= last[2]; ++k) {
        for (int j = 0; j <= last[1]; ++j) {
          for (int i = 0; i <= last[0]; ++i) {
            const double* a = coarse.Point(i, j, k);
            const double* b = fine.Point(i * per, j * per, k * per);
            for (int c = 0; c < s; ++c) {
              ASSERT_EQ(b[c], a[c]) << "original point " << i << ", " << j << ", " << k;
            }
          }
        }
      }
      // Between two original neighbours along i the inserted points are closer to that pair
      // than the pair is long (no overshoot into a neighbouring cell).
      const double rounding = kRoundingRelTol * MaxAbsCoordinate(f.block);
      for (int k = 0; k < fine.extent(2); k += per) {
        for (int j = 0; j < fine.extent(1); j += per) {
          for (int i = 0; i + per < fine.extent(0); i += per) {
            const double* left = fine.Point(i, j, k);
            const double* right = fine.Point(i + per, j, k);
            const double length = Distance(left, right, s);
            for (int q = 1; q < per; ++q) {
              const double* mid = fine.Point(i + q, j, k);
              ASSERT_LE(std::min(Distance(mid, left, s), Distance(mid, right, s)),
                        length + rounding)
                  << i + q << ", " << j << ", " << k;
            }
          }
        }
      }
    }
  }
}

// Evaluating an index sub-box at level l gives exactly the corresponding slice of the whole
// block at level l: the per-point arithmetic does not depend on which other points are asked for.
TEST(EvaluationResolutionTest, SubBoxIsABitwiseSliceOfTheWholeBlock) {
  for (const FittedShared& f : FittedSharedBlocks()) {
    const PointDistribution& dist = f.fitted.distribution;
    const Extents last = LastIndex(f.block);
    const int s = f.block.spatial_dim();
    // Boxes: interior, touching the far ends, a single index line, a single point, the corner.
    std::vector<std::pair<Extents, Extents>> boxes = {
        {{last[0] / 4, last[1] / 3, 0}, {last[0] / 2, 2 * last[1] / 3, last[2]}},
        {{last[0] / 2, last[1] / 2, last[2]}, last},
        {{0, last[1] / 5, 0}, {last[0], last[1] / 5, 0}},
        {{last[0] / 3, last[1] / 7, last[2]}, {last[0] / 3, last[1] / 7, last[2]}},
        {{0, 0, 0}, {1, 1, last[2]}},
    };
    for (int level : {0, 1, 2}) {
      const int per = 1 << level;
      const StructuredBlock whole =
          EvaluateGrid(f.fitted.spline, RefinedParams(dist, {0, 0, 0}, last, level));
      for (const auto& [begin, end] : boxes) {
        SCOPED_TRACE(absl::StrCat(f.name, ", level ", level, ", box (", begin[0], ", ", begin[1],
                                  ", ", begin[2], ") - (", end[0], ", ", end[1], ", ", end[2],
                                  ")"));
        const StructuredBlock sub =
            EvaluateGrid(f.fitted.spline, RefinedParams(dist, begin, end, level));
        for (int d = 0; d < 3; ++d) ASSERT_EQ(sub.extent(d), (end[d] - begin[d]) * per + 1);
        for (int k = 0; k < sub.extent(2); ++k) {
          for (int j = 0; j < sub.extent(1); ++j) {
            for (int i = 0; i < sub.extent(0); ++i) {
              const double* a = sub.Point(i, j, k);
              const double* b =
                  whole.Point(begin[0] * per + i, begin[1] * per + j, begin[2] * per + k);
              for (int c = 0; c < s; ++c) ASSERT_EQ(a[c], b[c]) << i << ", " << j << ", " << k;
            }
          }
        }
      }
    }
  }
}

// GridEvaluator's dX/du, dX/dv, dX/dw against central differences of its own point output, on
// the level-1 grid (original points and midpoints). The step follows the local parameter
// spacing, which spans many orders of magnitude on these wall-clustered grids.
TEST(EvaluationResolutionTest, DerivativesMatchFiniteDifferencesOfThePoints) {
  for (const FittedShared& f : FittedSharedBlocks()) {
    SCOPED_TRACE(f.name);
    const TensorSpline& spline = f.fitted.spline;
    const auto params = RefinedParams(f.fitted.distribution, {0, 0, 0}, LastIndex(f.block), 1);
    GridEvaluator evaluator(spline, params, /*first_derivatives=*/true);
    const Extents n = evaluator.extents();
    const int s = spline.spatial_dim();
    const size_t size = evaluator.num_lines() * evaluator.line_size();
    std::vector<double> points(size);
    std::array<std::vector<double>, 3> ders = {std::vector<double>(size), std::vector<double>(size),
                                               std::vector<double>(size)};
    evaluator.EvaluateLines(0, evaluator.num_lines(), points.data(), ders[0].data(), ders[1].data(),
                            ders[2].data());
    // The points agree with EvaluateGrid's.
    const StructuredBlock grid = EvaluateGrid(spline, params);
    ASSERT_TRUE(std::equal(points.begin(), points.end(), grid.coords().begin()));
    int compared = 0;
    for (int d = 0; d < 3; ++d) {
      if (spline.knots(d).num_controls() == 1) {
        // An unused direction: the derivative is exactly zero.
        EXPECT_TRUE(std::all_of(ders[d].begin(), ders[d].end(), [](double x) { return x == 0.0; }));
        continue;
      }
      // Steps per index of direction d (interior indices only).
      const std::vector<double>& u = params[d];
      std::vector<double> step(u.size(), 0.0);
      std::array<std::vector<double>, 3> plus = params, minus = params;
      for (size_t i = 1; i + 1 < u.size(); ++i) {
        step[i] = kStepFraction * std::min(u[i] - u[i - 1], u[i + 1] - u[i]);
        plus[d][i] = u[i] + step[i];
        minus[d][i] = u[i] - step[i];
      }
      const StructuredBlock p_plus = EvaluateGrid(spline, plus);
      const StructuredBlock p_minus = EvaluateGrid(spline, minus);
      for (int k = 0; k < n[2]; ++k) {
        for (int j = 0; j < n[1]; ++j) {
          for (int i = 0; i < n[0]; ++i) {
            const int index[3] = {i, j, k};
            if (index[d] == 0 || index[d] + 1 == n[d]) continue;
            const double h = step[index[d]];
            const int64_t at = s * (i + int64_t{n[0]} * (j + int64_t{n[1]} * k));
            double magnitude = 0.0, size = 0.0;
            for (int c = 0; c < s; ++c) {
              magnitude = std::max(magnitude, std::abs(ders[d][at + c]));
              size = std::max(size, std::abs(points[at + c]));
            }
            const double rounding = kRoundingUlps * kEpsilon * size / h;
            for (int c = 0; c < s; ++c) {
              const double fd = (p_plus.coords()[at + c] - p_minus.coords()[at + c]) / (2.0 * h);
              ASSERT_NEAR(ders[d][at + c], fd, kFiniteDifferenceRelTol * magnitude + rounding)
                  << "direction " << d << " at " << i << ", " << j << ", " << k << " coordinate "
                  << c;
            }
            ++compared;
          }
        }
      }
    }
    EXPECT_GT(compared, 10000);
  }
}

}  // namespace
}  // namespace splinegrid
