// Grids with collapsed edges (poles, poles.h): polar disks of one to four blocks (the j = 0 edge
// of every block at the centre) and a wing-tip cap closing the tip of the shared M6 wing
// (surfaces/m6_small.fmt) with a dome whose last ring is its pole. For each: the pole is no match,
// the tolerance fit by kind succeeds with every point within its kind's tolerance (re-measured,
// multiblock_checks.h), no sub-cell folds at levels 0-2 (signed areas computed here from
// evaluated points, not by the quality code), matched boundaries coincide at levels 0-2, and the
// pole stays one point at every level, bitwise shared by the blocks that meet there. The fits go
// through FitGrid (grid_fit.h); the poles are found here as the fit finds them (FindPoles).
// Volumes around a polar axis and off the nose of a body of revolution check the same in 3D,
// and that a held first layer leaves the pole out (the fit keeps it collapsed instead).
#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/bspline/evaluation.h"
#include "core/fit/grid_fit.h"
#include "core/grid/poles.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/multiblock_checks.h"
#include "tests/core/synthetic_grids.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

// Sub-cells whose |area| is at most this fraction of the level's median |area| are exactly
// degenerate (a cell collapsed to a line or point) and skipped, as grid_quality.h does.
constexpr double kDegenerateArea = 1e-12;
// Evaluated pole points coincide up to rounding, relative to the coordinates.
constexpr double kPoleRounding = 1e-12;

// A polar disk of `blocks` blocks: block b covers the angles [b, b + 1] 2 pi / blocks with
// `ni` points, i counter-clockwise; j runs outwards from the centre (0.3, -0.2) (j = 0: every
// point at the centre, bitwise) with a radius clustered towards the rim; the rim is wobbly so
// that fits need knots. With blocks = 1 the edges i = 0 and i = max coincide (a periodic seam).
MultiBlockGrid PolarDisk(int blocks, int ni, int nj, double inner = 0.0) {
  MultiBlockGrid grid;
  const int n = blocks * (ni - 1);
  for (int b = 0; b < blocks; ++b) {
    grid.blocks.push_back(PlanarBlock(ni, nj, [=](int i, int j) {
      const double t = 2.0 * std::numbers::pi * ((b * (ni - 1) + i) % n) / n;
      const double s = static_cast<double>(j) / (nj - 1);
      const double r = inner + (1.0 - inner) * (std::exp(2.0 * s) - 1.0) / (std::exp(2.0) - 1.0);
      return std::array<double, 2>{0.3 + r * std::cos(t) * (1.0 + 0.1 * r * std::sin(2.0 * t)),
                                   -0.2 + r * std::sin(t) * (1.0 + 0.05 * std::cos(3.0 * t))};
    }));
  }
  return grid;
}

// The rim (j = max) of every block is a wall, so each fit binds three kinds: wall on the rim,
// interface on the radial edges, outer at the centre (the pole's unmatched edge).
GridFitOptions DiskOptions(int blocks) {
  BoundaryTolerances tolerances;
  tolerances.wall = 1e-5;
  tolerances.interface = 1e-4;
  tolerances.outer = 4e-4;
  GridFitOptions options = KindToleranceOptions(tolerances);
  for (int b = 0; b < blocks; ++b)
    options.face_kinds.push_back({{b, 1, true}, BoundaryKind::kWall});
  return options;
}

Point3 At(const StructuredBlock& block, int i, int j, int k = 0) {
  const double* p = block.Point(i, j, k);
  return {p[0], p[1], block.spatial_dim() == 3 ? p[2] : 0.0};
}

// 0.5 (x3 - x0) x (x2 - x1) of the cell with lower corner (i, j): the signed area (z) of a planar
// cell, the area vector of a surface cell. With x1 = x0 (a sub-cell on a pole) this is exactly
// the area (vector) of the triangle x0 x3 x2.
Point3 AreaVector(const StructuredBlock& block, int i, int j) {
  const Point3 x0 = At(block, i, j), x1 = At(block, i + 1, j), x2 = At(block, i, j + 1),
               x3 = At(block, i + 1, j + 1);
  const Point3 a = {x3[0] - x0[0], x3[1] - x0[1], x3[2] - x0[2]};
  const Point3 b = {x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2]};
  return {0.5 * (a[1] * b[2] - a[2] * b[1]), 0.5 * (a[2] * b[0] - a[0] * b[2]),
          0.5 * (a[0] * b[1] - a[1] * b[0])};
}

double Dot(const Point3& a, const Point3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

struct FoldCount {
  int64_t checked = 0, skipped = 0, folded = 0;
  int64_t triangles = 0;  // checked sub-cells with two coincident corners (on a pole)
};

// Folds of a fitted surface or planar block at refinement level `level`, from points evaluated
// here: the sub-cells of original cell (I, J) are those (I', J') with I' >> level = I; a sub-cell
// is folded when its area vector a does not point the way of its original cell's, A: a . A <= 0
// (planar: the signed areas differ in sign or a vanishes). Cells on a pole are triangles (two
// corners at one point): their "area vector" is the triangle's, so folded means the triangle
// flipped or went flat, the same definition. Only exactly-degenerate sub-cells are skipped:
// |a| <= kDegenerateArea * the level's median |a|.
FoldCount CountFolds(const FittedBlock& fitted, const StructuredBlock& original, int level) {
  FoldCount count;
  std::array<std::vector<double>, 3> params;
  for (int d = 0; d < 3; ++d) {
    params[d] = fitted.distribution.Refined(d, 0, original.extent(d) - 1, level);
  }
  const StructuredBlock eval = EvaluateGrid(fitted.spline, params);
  const int ni = eval.extent(0) - 1, nj = eval.extent(1) - 1;
  std::vector<Point3> areas;
  std::vector<double> sizes;
  for (int j = 0; j < nj; ++j) {
    for (int i = 0; i < ni; ++i) {
      areas.push_back(AreaVector(eval, i, j));
      sizes.push_back(std::sqrt(Dot(areas.back(), areas.back())));
    }
  }
  std::vector<double> sorted = sizes;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double threshold = kDegenerateArea * sorted[sorted.size() / 2];
  for (int j = 0; j < nj; ++j) {
    for (int i = 0; i < ni; ++i) {
      const size_t c = static_cast<size_t>(i) + static_cast<size_t>(ni) * j;
      if (sizes[c] <= threshold) {
        ++count.skipped;
        continue;
      }
      ++count.checked;
      const Point3 parent = AreaVector(original, i >> level, j >> level);
      if (!(Dot(areas[c], parent) > 0.0)) ++count.folded;
      const Point3 x0 = At(eval, i, j), x1 = At(eval, i + 1, j), x2 = At(eval, i, j + 1),
                   x3 = At(eval, i + 1, j + 1);
      // A pole triangle: two corners one point up to rounding (relative to the longest edge).
      auto length = [](const Point3& p, const Point3& q) {
        return std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
      };
      const double edges[4] = {length(x0, x1), length(x2, x3), length(x0, x2), length(x1, x3)};
      const double longest = *std::max_element(edges, edges + 4);
      if (*std::min_element(edges, edges + 4) <= kPoleRounding * longest) ++count.triangles;
    }
  }
  return count;
}

// No folded sub-cell at levels 0-2 in any block; returns the triangles checked.
int64_t ExpectNoFolds(const MultiBlockGrid& grid, const GridFit& fit) {
  int64_t triangles = 0;
  for (size_t b = 0; b < grid.blocks.size(); ++b) {
    for (int level = 0; level <= 2; ++level) {
      SCOPED_TRACE(absl::StrCat("block ", b, " level ", level));
      const FoldCount count = CountFolds(fit.blocks[b].fitted, grid.blocks[b], level);
      EXPECT_EQ(count.folded, 0);
      EXPECT_EQ(count.skipped, 0);
      EXPECT_GT(count.checked, 0);
      triangles += count.triangles;
      std::cout << "[folds] block " << b << " level " << level << ": " << count.checked
                << " sub-cells checked (" << count.triangles << " pole triangles), " << count.folded
                << " folded, " << count.skipped << " degenerate skipped\n";
    }
  }
  return triangles;
}

// The poles of `grid`, found as the fit finds them.
std::vector<Pole> GridPoles(const MultiBlockGrid& grid) {
  return FindPoles(grid, PoleTolerance(grid));
}

// Every pole of `grid` stays collapsed in `fit` at levels 0-2: the evaluated points of every line
// along its collapsed direction coincide within rounding (relative to the coordinates).
void ExpectPolesCollapsed(const MultiBlockGrid& grid, const GridFit& fit) {
  const double scale = CoordinateScale(grid);
  for (const Pole& pole : GridPoles(grid)) {
    SCOPED_TRACE(pole.Describe());
    const FittedBlock& fitted = fit.blocks[pole.block].fitted;
    for (int level = 0; level <= 2; ++level) {
      std::array<std::vector<double>, 3> params;
      for (int d = 0; d < 3; ++d) {
        params[d] = fitted.distribution.Refined(d, pole.lo[d], pole.hi[d], level);
      }
      const StructuredBlock line = EvaluateGrid(fitted.spline, params);
      // Per line along the collapsed direction: its points' largest distance from its first.
      double spread = 0.0;
      const int d = pole.d, e1 = d == 0 ? 1 : 0, e2 = d == 2 ? 1 : 2;
      for (int y = 0; y < line.extent(e2); ++y) {
        for (int x = 0; x < line.extent(e1); ++x) {
          Extents at = {0, 0, 0};
          at[e1] = x;
          at[e2] = y;
          const double* first = line.Point(at[0], at[1], at[2]);
          for (int r = 0; r < line.extent(d); ++r) {
            at[d] = r;
            const double* p = line.Point(at[0], at[1], at[2]);
            double d2 = 0.0;
            for (int c = 0; c < line.spatial_dim(); ++c)
              d2 += (p[c] - first[c]) * (p[c] - first[c]);
            spread = std::max(spread, std::sqrt(d2));
          }
        }
      }
      EXPECT_LE(spread, kPoleRounding * scale) << "level " << level;
    }
  }
}

// The controls of the j = 0 edge of every block are bitwise one point.
void ExpectDiskPoleControlsShared(const GridFit& fit) {
  const double* pole = fit.blocks[0].fitted.spline.ControlPoint(0, 0, 0);
  for (const BlockFit& block : fit.blocks) {
    const FittedBlock& fitted = block.fitted;
    for (int a = 0; a < fitted.spline.control_extents()[0]; ++a) {
      const double* p = fitted.spline.ControlPoint(a, 0, 0);
      EXPECT_TRUE(p[0] == pole[0] && p[1] == pole[1]) << "control " << a;
    }
  }
}

TEST(PolesTest, FindsCollapsedEdgesOnly) {
  const MultiBlockGrid disk = PolarDisk(1, 33, 9);
  const std::vector<Pole> poles = FindPoles(disk, PoleTolerance(disk));
  ASSERT_EQ(poles.size(), 1u);
  EXPECT_EQ(poles[0].block, 0);
  EXPECT_EQ(poles[0].d, 0);
  EXPECT_EQ(poles[0].lo, (Extents{0, 0, 0}));
  EXPECT_EQ(poles[0].hi, (Extents{32, 0, 0}));
  EXPECT_EQ(poles[0].Describe(), "block 0 j=0 collapsed along i");
  const MultiBlockGrid annulus = PolarDisk(1, 33, 9, 0.2);
  EXPECT_TRUE(FindPoles(annulus, PoleTolerance(annulus)).empty());
  // A point of the edge moved by a millionth of the disk: no longer a pole.
  MultiBlockGrid moved = disk;
  moved.blocks[0].Point(5, 0, 0)[0] += 1e-6;
  EXPECT_TRUE(FindPoles(moved, PoleTolerance(moved)).empty());
}

TEST(PolesTest, ConnectivityDropsThePoleSelfMatches) {
  // Without the rule, the j = 0 edge "matched" itself at every shift, both ways (135 matches
  // for 33 points), and the segment model cut direction i at their ends.
  for (int blocks : {1, 2, 4}) {
    SCOPED_TRACE(absl::StrCat(blocks, " blocks"));
    const MultiBlockGrid grid = PolarDisk(blocks, 33, 9);
    const absl::StatusOr<Connectivity> connectivity = FindConnectivity(grid);
    ASSERT_TRUE(connectivity.ok()) << connectivity.status();
    ASSERT_EQ(connectivity->matches.size(), static_cast<size_t>(blocks));
    for (const BoundaryMatch& m : connectivity->matches) {
      EXPECT_EQ(m.a.face.normal, 0) << m.Describe();  // the radial edges
      EXPECT_EQ(m.b.face.normal, 0) << m.Describe();
      EXPECT_EQ(m.a.end[1] - m.a.begin[1], 8) << m.Describe();  // the whole edge, pole included
    }
  }
}

// One block, the periodic seam i = 0 ~ i = max matched to itself, the j = 0 edge at the centre.
TEST(CollapsedEdgeFitTest, PolarDiskOneBlock) {
  const MultiBlockGrid grid = PolarDisk(1, 65, 17);
  const GridFitOptions options = DiskOptions(1);
  const absl::StatusOr<GridFit> fit = FitGrid(grid, options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  ASSERT_EQ(GridPoles(grid).size(), 1u);
  ASSERT_EQ(fit->connectivity.matches.size(), 1u);
  ExpectTolerancesMet(grid, *fit, *options.boundary_tolerances);
  const KindDeviation& dev = fit->blocks[0].deviation_by_kind;
  EXPECT_GE(dev.wall, 0.0);
  EXPECT_GE(dev.interface, 0.0);
  EXPECT_GE(dev.outer, 0.0);
  EXPECT_LT(fit->report.num_control_points, fit->report.num_points);
  EXPECT_GT(ExpectNoFolds(grid, *fit), 0);
  ExpectWatertight(grid, *fit);
  ExpectPolesCollapsed(grid, *fit);
  ExpectDiskPoleControlsShared(*fit);
  EXPECT_TRUE(fit->report.quality_met);
  const Extents n = fit->blocks[0].fitted.spline.control_extents();
  std::cout << "[figures] polar disk 1 block 65 x 17: " << n[0] << " x " << n[1] << " = "
            << fit->report.num_control_points << " controls; wall " << dev.wall << ", interface "
            << dev.interface << ", outer (pole) " << dev.outer << "\n";
  // The same grid as an annulus (the centre cut out) fits too, with the same kinds.
  const MultiBlockGrid annulus = PolarDisk(1, 65, 17, 0.2);
  const absl::StatusOr<GridFit> ring = FitGrid(annulus, options);
  ASSERT_TRUE(ring.ok()) << ring.status();
  EXPECT_TRUE(GridPoles(annulus).empty());
  ExpectTolerancesMet(annulus, *ring, *options.boundary_tolerances);
}

// 2, 3 and 4 blocks around the centre: the radial edges are interfaces, the pole is shared by all.
TEST(CollapsedEdgeFitTest, PolarDiskOfSeveralBlocks) {
  for (int blocks : {2, 3, 4}) {
    SCOPED_TRACE(absl::StrCat(blocks, " blocks"));
    const MultiBlockGrid grid = PolarDisk(blocks, 65 / blocks + 1, 17);
    const GridFitOptions options = DiskOptions(blocks);
    const absl::StatusOr<GridFit> fit = FitGrid(grid, options);
    ASSERT_TRUE(fit.ok()) << fit.status();
    EXPECT_EQ(GridPoles(grid).size(), static_cast<size_t>(blocks));
    EXPECT_EQ(fit->connectivity.matches.size(), static_cast<size_t>(blocks));
    ExpectTolerancesMet(grid, *fit, *options.boundary_tolerances);
    EXPECT_GT(ExpectNoFolds(grid, *fit), 0);
    ExpectWatertight(grid, *fit);
    ExpectPolesCollapsed(grid, *fit);
    ExpectDiskPoleControlsShared(*fit);
    EXPECT_TRUE(fit->report.quality_met);
    std::cout << "[figures] polar disk " << blocks << " blocks: " << fit->report.num_control_points
              << " controls for " << fit->report.num_points << " points, max gap "
              << fit->report.max_gap << "\n";
  }
}

// The points of edge `face` of surface block `block` (direction d running along it).
std::vector<Point3> EdgePoints(const StructuredBlock& block, int normal, bool upper) {
  std::vector<Point3> points;
  const int d = 1 - normal;
  for (int r = 0; r < block.extent(d); ++r) {
    Extents x = {0, 0, 0};
    x[normal] = upper ? block.extent(normal) - 1 : 0;
    x[d] = r;
    points.push_back(At(block, x[0], x[1]));
  }
  return points;
}

// The wing of surfaces/m6_small.fmt without its five tip blocks (4-8), closed instead by one
// C-O cap: i runs once around the tip section (the tip edges of the leading-edge strip, the
// lower surface, the blunt trailing edge and the upper surface, chained into a loop; i = 0 and
// i = max coincide), j from the section (j = 0, shared with the wing) over a dome of height
// `height` to its top, where the whole edge j = max is one point (up to the rounding of
// cos(pi / 2)): rings C + cos(t) (L(i) - C) + sin(t) height z, t = pi/2 j / (nj - 1), C the
// centroid of the section.
MultiBlockGrid M6WithTipCap(int nj, double height) {
  const absl::StatusOr<MultiBlockGrid> m6 = ReadPlot3dFile(SharedDataPath("surfaces/m6_small.fmt"));
  EXPECT_TRUE(m6.ok()) << m6.status();
  if (!m6.ok() || m6->blocks.size() != 9) return {};
  MultiBlockGrid grid;
  grid.blocks.assign(m6->blocks.begin(), m6->blocks.begin() + 4);
  // The section's edges (their tip blocks matched them: 0 i=max, 1 j=max, 2 j=max, 3 i=max).
  std::vector<std::vector<Point3>> edges = {
      EdgePoints(grid.blocks[0], 0, true), EdgePoints(grid.blocks[1], 1, true),
      EdgePoints(grid.blocks[2], 1, true), EdgePoints(grid.blocks[3], 0, true)};
  std::vector<Point3> loop = edges[0];
  std::vector<bool> used = {true, false, false, false};
  for (int step = 1; step < 4; ++step) {
    for (int e = 1; e < 4; ++e) {
      if (used[e]) continue;
      if (edges[e].back() == loop.back()) std::reverse(edges[e].begin(), edges[e].end());
      if (edges[e].front() != loop.back()) continue;
      loop.insert(loop.end(), edges[e].begin() + 1, edges[e].end());
      used[e] = true;
      break;
    }
  }
  EXPECT_EQ(loop.size(), 17u + 73 + 17 + 73 - 3);
  EXPECT_TRUE(loop.front() == loop.back()) << "the tip edges do not close a loop";
  Point3 c = {0.0, 0.0, 0.0};
  for (size_t i = 0; i + 1 < loop.size(); ++i) {
    for (int x = 0; x < 3; ++x) c[x] += loop[i][x] / (loop.size() - 1);
  }
  grid.blocks.push_back(SpaceBlock(static_cast<int>(loop.size()), nj, 1, [&](int i, int j, int) {
    const double t = 0.5 * std::numbers::pi * j / (nj - 1);
    const Point3& l = loop[i];
    return std::array<double, 3>{c[0] + std::cos(t) * (l[0] - c[0]),
                                 c[1] + std::cos(t) * (l[1] - c[1]),
                                 c[2] + std::cos(t) * (l[2] - c[2]) + std::sin(t) * height};
  }));
  return grid;
}

// A wing-tip cap with one collapsed edge, fitted with the wing at the paper's tolerances (every
// point of a surface is a wall: 0.15e-3), watertight to the wing's four tip edges and its own
// seam.
TEST(CollapsedEdgeFitTest, M6WingTipCap) {
  const MultiBlockGrid grid = M6WithTipCap(9, 0.02);
  ASSERT_EQ(grid.blocks.size(), 5u);
  const GridFitOptions options = KindToleranceOptions();
  const absl::StatusOr<GridFit> fit = FitGrid(grid, options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  const std::vector<Pole> poles = GridPoles(grid);
  ASSERT_EQ(poles.size(), 1u);
  EXPECT_EQ(poles[0].Describe(), "block 4 j=8 collapsed along i");
  int cap_matches = 0;
  for (const BoundaryMatch& m : fit->connectivity.matches) {
    cap_matches += m.a.face.block == 4 || m.b.face.block == 4;
    EXPECT_FALSE(m.a.face.block == 4 && m.a.face.normal == 1 && m.a.face.upper) << m.Describe();
  }
  EXPECT_EQ(cap_matches, 5);  // four tip edges and the seam
  ExpectTolerancesMet(grid, *fit, *options.boundary_tolerances);
  EXPECT_GT(ExpectNoFolds(grid, *fit), 0);
  ExpectWatertight(grid, *fit);
  ExpectPolesCollapsed(grid, *fit);
  EXPECT_TRUE(fit->report.quality_met);
  // Not an interpolation: the pole's rounding-sized edges must not drive refinement (without
  // switching their edge ratios off, every block was refined to one control per point).
  EXPECT_LT(fit->report.num_control_points * 10, fit->report.num_points);
  EXPECT_LT(fit->blocks[4].fitted.spline.num_control_points() * 4, grid.blocks[4].num_points());
  const Extents n = fit->blocks[4].fitted.spline.control_extents();
  std::cout << "[figures] M6 wing + tip cap: " << fit->report.num_control_points << " controls for "
            << fit->report.num_points << " points; cap " << grid.blocks[4].extent(0) << " x "
            << grid.blocks[4].extent(1) << " points, " << n[0] << " x " << n[1]
            << " controls, wall deviation " << fit->blocks[4].deviation_by_kind.wall << "; max gap "
            << fit->report.max_gap << "\n";
}

// Volume of the trilinear hexahedron with corners x[a + 2b + 4c] (binary order), the integral
// of det J over the unit cube by 2-point Gauss quadrature per direction, exact here (det J has
// degree at most 2 in each variable). Computed here, independently of grid_quality.h.
double TrilinearVolume(const std::array<Point3, 8>& x) {
  const double g = 0.5 / std::sqrt(3.0);
  double volume = 0.0;
  for (double u : {0.5 - g, 0.5 + g}) {
    for (double v : {0.5 - g, 0.5 + g}) {
      for (double w : {0.5 - g, 0.5 + g}) {
        Point3 ju{}, jv{}, jw{};  // the partial derivatives of the trilinear map
        for (int c = 0; c < 8; ++c) {
          const int a = c & 1, b = (c >> 1) & 1, e = (c >> 2) & 1;
          const double wu = a ? u : 1.0 - u, wv = b ? v : 1.0 - v, ww = e ? w : 1.0 - w;
          for (int k = 0; k < 3; ++k) {
            ju[k] += (a ? 1.0 : -1.0) * wv * ww * x[c][k];
            jv[k] += (b ? 1.0 : -1.0) * wu * ww * x[c][k];
            jw[k] += (e ? 1.0 : -1.0) * wu * wv * x[c][k];
          }
        }
        const Point3 cross = {jv[1] * jw[2] - jv[2] * jw[1], jv[2] * jw[0] - jv[0] * jw[2],
                              jv[0] * jw[1] - jv[1] * jw[0]};
        volume += 0.125 * Dot(ju, cross);
      }
    }
  }
  return volume;
}

std::array<Point3, 8> HexCorners(const StructuredBlock& block, int i, int j, int k) {
  std::array<Point3, 8> x;
  for (int c = 0; c < 8; ++c) {
    const double* p = block.Point(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
    x[c] = {p[0], p[1], p[2]};
  }
  return x;
}

// A volume around a polar axis: i along the axis (z in [0, 1]), j once around it (j = 0 and
// j = max coincide: a periodic seam), k outwards from the axis (the face k = 0 collapsed along j
// to the axis line), the radius varying along the axis and clustered towards the outside.
MultiBlockGrid AxisVolume(int ni, int nj, int nk) {
  MultiBlockGrid grid;
  grid.blocks.push_back(SpaceBlock(ni, nj, nk, [=](int i, int j, int k) {
    const double z = static_cast<double>(i) / (ni - 1);
    const double t = 2.0 * std::numbers::pi * (j % (nj - 1)) / (nj - 1);
    const double s = static_cast<double>(k) / (nk - 1);
    const double r = (0.5 + 0.1 * std::sin(std::numbers::pi * z)) * std::sqrt(s) *
                     (1.0 + 0.05 * s * std::cos(2.0 * t));
    return std::array<double, 3>{r * std::cos(t) + 0.1 * z, r * std::sin(t), z};
  }));
  return grid;
}

TEST(CollapsedEdgeFitTest, VolumeAroundAPolarAxis) {
  const MultiBlockGrid grid = AxisVolume(9, 33, 9);
  BoundaryTolerances tolerances;
  tolerances.wall = 1e-4;
  tolerances.interface = 1e-3;
  tolerances.outer = 1e-3;
  const GridFitOptions options = KindToleranceOptions(tolerances);
  const absl::StatusOr<GridFit> fit = FitGrid(grid, options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  // The face k = 0, and the boundary lines k = 0 of the faces i = 0 and i = max.
  EXPECT_EQ(GridPoles(grid).size(), 3u);
  ASSERT_EQ(fit->connectivity.matches.size(), 1u);  // the seam
  ExpectTolerancesMet(grid, *fit, tolerances);
  ExpectWatertight(grid, *fit);
  ExpectPolesCollapsed(grid, *fit);
  const FittedBlock& fitted = fit->blocks[0].fitted;
  const StructuredBlock& data = grid.blocks[0];
  int64_t wedges = 0;
  for (int level = 0; level <= 2; ++level) {
    std::array<std::vector<double>, 3> params;
    for (int d = 0; d < 3; ++d)
      params[d] = fitted.distribution.Refined(d, 0, data.extent(d) - 1, level);
    const StructuredBlock eval = EvaluateGrid(fitted.spline, params);
    int64_t folded = 0, checked = 0;
    for (int k = 0; k + 1 < eval.extent(2); ++k) {
      for (int j = 0; j + 1 < eval.extent(1); ++j) {
        for (int i = 0; i + 1 < eval.extent(0); ++i) {
          // Cells on the axis are wedges (two corners at one point): their trilinear volume is
          // the wedge's, nonzero, so they are checked like every other cell.
          const double parent =
              TrilinearVolume(HexCorners(data, i >> level, j >> level, k >> level));
          const double v = TrilinearVolume(HexCorners(eval, i, j, k));
          ++checked;
          wedges += k == 0;
          if (!(v * parent > 0.0)) ++folded;
        }
      }
    }
    EXPECT_EQ(folded, 0) << "level " << level;
    std::cout << "[folds] axis volume level " << level << ": " << checked << " sub-cells, "
              << folded << " folded\n";
  }
  EXPECT_GT(wedges, 0);
  const Extents n = fitted.spline.control_extents();
  std::cout << "[figures] axis volume 9 x 33 x 9: " << n[0] << " x " << n[1] << " x " << n[2]
            << " controls, outer " << fit->blocks[0].deviation_by_kind.outer << ", interface "
            << fit->blocks[0].deviation_by_kind.interface << "\n";
}

// A volume off the nose of a body of revolution: i along the body from the nose (polar angle
// from the axis), j once around it (a periodic seam), k outwards from the wall (k = 0), the
// layers geometric from a first height of 1e-3. The face i = 0 is collapsed along j to the axis
// ahead of the nose, so the wall's first-layer edges from the nose point lie on a pole.
MultiBlockGrid NoseVolume(int ni, int nj, int nk) {
  MultiBlockGrid grid;
  const std::vector<double> heights = GeometricSpacing(nk, 1e-3, 1.3);
  grid.blocks.push_back(SpaceBlock(ni, nj, nk, [=](int i, int j, int k) {
    const double theta = 0.6 * std::numbers::pi * i / (ni - 1);
    const double phi = 2.0 * std::numbers::pi * (j % (nj - 1)) / (nj - 1);
    const double rho = 0.5 * (1.0 + 0.1 * std::sin(theta) * std::cos(2.0 * phi)) + heights[k];
    return std::array<double, 3>{rho * std::sin(theta) * std::cos(phi),
                                 rho * std::sin(theta) * std::sin(phi), -rho * std::cos(theta)};
  }));
  return grid;
}

// The first layer of a wall with a pole in 3D: held to 5% everywhere but on the pole (the fit
// keeps the pole collapsed instead), and the report's figure is the largest change over the
// other first-layer edges, measured here from the evaluated spline.
TEST(CollapsedEdgeFitTest, AHeldFirstLayerLeavesOutThePoleOfAVolume) {
  const MultiBlockGrid grid = NoseVolume(17, 25, 9);
  const StructuredBlock& data = grid.blocks[0];
  BoundaryTolerances tolerances;
  tolerances.wall = 1e-4;
  tolerances.interface = 1e-3;
  tolerances.outer = 1e-3;
  tolerances.first_layer = 0.05;
  GridFitOptions options = KindToleranceOptions(tolerances);
  options.face_kinds = {{{0, 2, false}, BoundaryKind::kWall}};
  const absl::StatusOr<GridFit> fit = FitGrid(grid, options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  ASSERT_FALSE(GridPoles(grid).empty());
  EXPECT_TRUE(fit->report.tolerance_met) << fit->report.unmet_reason;
  ExpectPolesCollapsed(grid, *fit);
  const FittedBlock& fitted = fit->blocks[0].fitted;
  std::array<std::vector<double>, 3> params;
  for (int d = 0; d < 3; ++d) params[d] = fitted.distribution.Refined(d, 0, data.extent(d) - 1, 0);
  const StructuredBlock eval = EvaluateGrid(fitted.spline, params);
  double largest = 0.0;
  for (int j = 0; j < data.extent(1); ++j) {
    for (int i = 1; i < data.extent(0); ++i) {  // i = 0: the pole
      const Point3 a = At(data, i, j, 0), b = At(data, i, j, 1);
      const Point3 fa = At(eval, i, j, 0), fb = At(eval, i, j, 1);
      const double height = std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
      const double fitted_height = std::hypot(fb[0] - fa[0], fb[1] - fa[1], fb[2] - fa[2]);
      largest = std::max(largest, std::abs(fitted_height - height) / height);
    }
  }
  const KindDeviation& dev = fit->blocks[0].deviation_by_kind;
  EXPECT_GT(largest, 0.0);
  EXPECT_LE(largest, tolerances.first_layer);
  EXPECT_NEAR(dev.first_layer, largest, 1e-12);
  EXPECT_GE(dev.first_layer_at[0], 1);
  EXPECT_EQ(dev.first_layer_at[2], 0);
}

// A wall that is all pole (the axis of AxisVolume named a wall: a wire) has no first layer the
// fit holds, so holding one is refused rather than reported as held.
TEST(CollapsedEdgeFitTest, AFirstLayerOnAWallThatIsAllPoleIsRefused) {
  BoundaryTolerances tolerances;
  tolerances.first_layer = 0.05;
  GridFitOptions options = KindToleranceOptions(tolerances);
  options.face_kinds = {{{0, 2, false}, BoundaryKind::kWall}};
  const absl::StatusOr<GridFit> fit = FitGrid(AxisVolume(9, 33, 9), options);
  EXPECT_EQ(fit.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(fit.status().message(), ::testing::HasSubstr("first layer off a pole"));
}

}  // namespace
}  // namespace splinegrid
