// Independent checks of a multi-block fit to tolerances (FitGrid, grid_fit.h), shared by its tests:
// every point within its kind's tolerance, re-measured; the report's per-kind maxima; shared
// boundary controls bitwise equal, found without the segment model through the control whose basis
// function is exactly 1 at each end of a matched range; and the gaps between the two sides of
// every match evaluated point by point at refinement levels 0..2.
#ifndef SPLINEGRID_TESTS_CORE_MULTIBLOCK_CHECKS_H_
#define SPLINEGRID_TESTS_CORE_MULTIBLOCK_CHECKS_H_

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/bspline/basis.h"
#include "core/bspline/evaluation.h"
#include "core/fit/grid_fit.h"
#include "gtest/gtest.h"

namespace splinegrid {

// Re-measured deviations round differently from the fit's own test (relative).
inline constexpr double kToleranceRounding = 1e-12;
// Shared boundaries evaluated in two blocks: the same controls, but knots and parameters that
// are affine images of each other (mirrored when reversed) and different summation orders, so
// equal up to rounding, relative to the largest coordinate.
inline constexpr double kGapRounding = 1e-14;

// The tolerance mode of FitGrid held to `tolerances` by kind as absolute lengths in the grid's
// unit (no kind relative to the reference length): the defaults are the QUADFLOW paper's
// 0.15e-3, 2e-3 and 8e-3 in the grid's unit, none inside.
inline GridFitOptions KindToleranceOptions(const BoundaryTolerances& tolerances = {}) {
  GridFitOptions options;
  options.boundary_tolerances = tolerances;
  options.relative_kinds = 0;
  return options;
}

inline double CoordinateScale(const MultiBlockGrid& grid) {
  double scale = 0.0;
  for (const StructuredBlock& b : grid.blocks) {
    for (double x : b.coords()) scale = std::max(scale, std::abs(x));
  }
  return scale;
}

// Every point within its kind's tolerance, and the report's per-kind maxima, re-measured; the
// report holds the tolerances (in the grid's unit) the fit was held to.
inline void ExpectTolerancesMet(const MultiBlockGrid& grid, const GridFit& fit,
                                const BoundaryTolerances& tolerances) {
  EXPECT_TRUE(fit.report.tolerance_met) << fit.report.unmet_reason;
  ASSERT_EQ(fit.blocks.size(), grid.blocks.size());
  ASSERT_TRUE(fit.report.tolerances.has_value());
  EXPECT_EQ(fit.report.tolerances->wall, tolerances.wall);
  EXPECT_EQ(fit.report.tolerances->interface, tolerances.interface);
  EXPECT_EQ(fit.report.tolerances->outer, tolerances.outer);
  EXPECT_EQ(fit.report.tolerances->interior, tolerances.interior);
  int64_t points = 0, controls = 0;
  for (size_t b = 0; b < grid.blocks.size(); ++b) {
    SCOPED_TRACE(absl::StrCat("block ", b));
    const StructuredBlock& data = grid.blocks[b];
    const FittedBlock& fitted = fit.blocks[b].fitted;
    const PointDistribution& dist = fitted.distribution;
    const StructuredBlock eval =
        EvaluateGrid(fitted.spline, {dist.params(0), dist.params(1), dist.params(2)});
    ASSERT_EQ(eval.extents(), data.extents());
    const std::vector<double> tol = PointTolerances(fit.kinds, static_cast<int>(b), tolerances);
    KindDeviation dev;
    for (int64_t p = 0; p < data.num_points(); ++p) {
      double d2 = 0.0;
      for (int c = 0; c < data.spatial_dim(); ++c) {
        const double diff =
            eval.coords()[data.spatial_dim() * p + c] - data.coords()[data.spatial_dim() * p + c];
        d2 += diff * diff;
      }
      const double d = std::sqrt(d2);
      ASSERT_LE(d, tol[p] * (1.0 + kToleranceRounding)) << "point " << p;
      const uint8_t k = fit.kinds.point_kinds[b][p];
      if (k == 0) dev.interior = std::max(dev.interior, d);
      if (k & static_cast<uint8_t>(BoundaryKind::kWall)) dev.wall = std::max(dev.wall, d);
      if (k & static_cast<uint8_t>(BoundaryKind::kInterface))
        dev.interface = std::max(dev.interface, d);
      if (k & static_cast<uint8_t>(BoundaryKind::kOuter)) dev.outer = std::max(dev.outer, d);
    }
    const KindDeviation& reported = fit.blocks[b].deviation_by_kind;
    for (auto [mine, theirs] : {std::pair{dev.wall, reported.wall},
                                {dev.interface, reported.interface},
                                {dev.outer, reported.outer},
                                {dev.interior, reported.interior}}) {
      EXPECT_NEAR(theirs, mine, kToleranceRounding * (1.0 + std::abs(mine)));
    }
    EXPECT_TRUE(fit.blocks[b].tolerance_met) << fit.blocks[b].unmet_reason;
    EXPECT_EQ(fitted.summary.num_points, data.num_points());
    EXPECT_EQ(fitted.summary.num_control_points, fitted.spline.num_control_points());
    points += data.num_points();
    controls += fitted.spline.num_control_points();
  }
  EXPECT_EQ(fit.report.num_points, points);
  EXPECT_EQ(fit.report.num_control_points, controls);
  // Quality met: every block's cells measured and none folded or resized.
  bool quality = true;
  for (const BlockFit& block : fit.blocks) {
    quality = quality && block.quality.ok() && block.quality.measured();
  }
  EXPECT_EQ(fit.report.quality_met, quality);
}

// The control index of `knots` whose basis function is exactly 1 at u (a clamped end or a knot
// of multiplicity order - 1), or -1.
inline int ControlAt(const KnotVector& knots, double u) {
  const SampledBasis basis = SampleBasis(knots, std::vector<double>{u});
  for (int t = 0; t < knots.order(); ++t) {
    if (basis.Row(0)[t] == 1.0) return basis.first[0] + t;
  }
  return -1;
}

// The controls of both sides of every match (the box of controls between those at the range
// ends, mapped with the match's orientation) are bitwise equal. Returns how many were compared.
inline int ExpectSharedControlsBitwiseEqual(const GridFit& fit) {
  int compared = 0;
  for (const BoundaryMatch& m : fit.connectivity.matches) {
    SCOPED_TRACE(m.Describe());
    const FittedBlock& fa = fit.blocks[m.a.face.block].fitted;
    const FittedBlock& fb = fit.blocks[m.b.face.block].fitted;
    const Extents na = fa.spline.control_extents(), nb = fb.spline.control_extents();
    Extents lo = {0, 0, 0}, hi = {0, 0, 0}, blo = {0, 0, 0};
    std::array<int, 3> bhi = {0, 0, 0};
    lo[m.a.face.normal] = hi[m.a.face.normal] = m.a.face.upper ? na[m.a.face.normal] - 1 : 0;
    for (int d = 0; d < 3; ++d) {
      const int e = m.b_direction[d];
      if (e < 0) continue;
      lo[d] = ControlAt(fa.spline.knots(d), fa.distribution.params(d)[m.a.begin[d]]);
      hi[d] = ControlAt(fa.spline.knots(d), fa.distribution.params(d)[m.a.end[d]]);
      blo[e] = ControlAt(fb.spline.knots(e), fb.distribution.params(e)[m.b.begin[e]]);
      bhi[e] = ControlAt(fb.spline.knots(e), fb.distribution.params(e)[m.b.end[e]]);
      if (std::min({lo[d], hi[d], blo[e], bhi[e]}) < 0 || hi[d] - lo[d] != bhi[e] - blo[e]) {
        ADD_FAILURE() << "range ends not pinned or different control counts";
        return -1;
      }
    }
    for (int z = lo[2]; z <= hi[2]; ++z) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        for (int x = lo[0]; x <= hi[0]; ++x) {
          const Extents ca = {x, y, z};
          Extents cb = {0, 0, 0};
          cb[m.b.face.normal] = m.b.face.upper ? nb[m.b.face.normal] - 1 : 0;
          for (int d = 0; d < 3; ++d) {
            const int e = m.b_direction[d];
            if (e >= 0) cb[e] = m.reversed[d] ? bhi[e] - (ca[d] - lo[d]) : blo[e] + (ca[d] - lo[d]);
          }
          const double* p = fa.spline.ControlPoint(ca[0], ca[1], ca[2]);
          const double* q = fb.spline.ControlPoint(cb[0], cb[1], cb[2]);
          bool equal = true;
          for (int c = 0; c < fa.spline.spatial_dim(); ++c) equal = equal && p[c] == q[c];
          EXPECT_TRUE(equal) << "control " << x << " " << y << " " << z;
          ++compared;
        }
      }
    }
  }
  return compared;
}

// The largest distance between the two sides of every match, each point evaluated on its own
// (EvaluatePoint) at the refined parameters of level 0..max_level (hanging nodes: level 0, the
// coarse side's points and every second point of the fine side).
inline double PointwiseGap(const GridFit& fit, int max_level) {
  double gap = 0.0;
  for (const BoundaryMatch& m : fit.connectivity.matches) {
    const FittedBlock& fa = fit.blocks[m.a.face.block].fitted;
    const FittedBlock& fb = fit.blocks[m.b.face.block].fitted;
    for (int level = 0; level <= (m.step == 1 ? max_level : 0); ++level) {
      std::array<std::vector<double>, 3> pa, pb;
      for (int d = 0; d < 3; ++d) {
        pa[d] = fa.distribution.Refined(d, m.a.begin[d], m.a.end[d], level);
        pb[d] = fb.distribution.Refined(d, m.b.begin[d], m.b.end[d], level);
      }
      const Extents n = {static_cast<int>(pa[0].size()), static_cast<int>(pa[1].size()),
                         static_cast<int>(pa[2].size())};
      for (int k = 0; k < n[2]; ++k) {
        for (int j = 0; j < n[1]; ++j) {
          for (int i = 0; i < n[0]; ++i) {
            const Extents x = {i, j, k};
            Point3 ub = {pb[0][0], pb[1][0], pb[2][0]};
            for (int d = 0; d < 3; ++d) {
              const int e = m.b_direction[d];
              if (e < 0) continue;
              const int y = m.step * x[d];
              ub[e] = pb[e][m.reversed[d] ? pb[e].size() - 1 - y : y];
            }
            const Point3 p = EvaluatePoint(fa.spline, {pa[0][i], pa[1][j], pa[2][k]});
            const Point3 q = EvaluatePoint(fb.spline, ub);
            gap = std::max(gap, std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]));
          }
        }
      }
    }
  }
  return gap;
}

// Watertight: shared controls bitwise equal and no gap beyond rounding at levels 0..2, as the
// fit reports it and measured point by point.
inline void ExpectWatertight(const MultiBlockGrid& grid, const GridFit& fit) {
  EXPECT_GT(ExpectSharedControlsBitwiseEqual(fit), 0);
  const double rounding = kGapRounding * CoordinateScale(grid);
  EXPECT_LE(fit.report.max_gap, rounding);
  EXPECT_LE(PointwiseGap(fit, 2), rounding);
}

}  // namespace splinegrid

#endif  // SPLINEGRID_TESTS_CORE_MULTIBLOCK_CHECKS_H_
