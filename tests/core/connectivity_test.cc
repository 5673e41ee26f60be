// FindConnectivity on small grids built here (full, partial, reversed and hanging-node edges, a
// C-grid's wake cut, a volume split in two with permuted directions, tolerances, errors) and on
// the shared grids, where every match must be point-coincident and the counts follow from the
// geometry.
#include "core/grid/connectivity.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/io/planar_view.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/synthetic_grids.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

// Coinciding points of the synthetic grids are computed from the same expression: bitwise equal
// or within a few rounding errors.
constexpr double kSameExpressionTol = 1e-14;

Connectivity Find(const MultiBlockGrid& grid, const ConnectivityOptions& options = {}) {
  absl::StatusOr<Connectivity> c = FindConnectivity(grid, options);
  EXPECT_TRUE(c.ok()) << c.status();
  return c.ok() ? *c : Connectivity{};
}

// Every index pair of `m` is inside both blocks and coincides (within `tol`); the ranges of a
// and b have consistent extents (b = step * a along every mapped direction).
void ExpectCoincident(const MultiBlockGrid& grid, const BoundaryMatch& m, double tol) {
  SCOPED_TRACE(m.Describe());
  int pairs = 0;
  EXPECT_LE(MatchGap(grid, m, &pairs), tol);
  EXPECT_GE(pairs, 2);
  for (int d = 0; d < 3; ++d) {
    const int e = m.b_direction[d];
    if (e < 0) continue;
    EXPECT_NE(d, m.a.face.normal);
    EXPECT_NE(e, m.b.face.normal);
    EXPECT_EQ(m.b.end[e] - m.b.begin[e], m.step * (m.a.end[d] - m.a.begin[d]));
  }
  const auto on_face = [&](const FaceRange& r) {
    const int n = grid.blocks[r.face.block].extent(r.face.normal);
    const int at = r.face.upper ? n - 1 : 0;
    return r.begin[r.face.normal] == at && r.end[r.face.normal] == at;
  };
  EXPECT_TRUE(on_face(m.a));
  EXPECT_TRUE(on_face(m.b));
}

TEST(ConnectivityTest, FullEdgeBetweenTwoBlocks) {
  const MultiBlockGrid grid = SideBySide(5);
  const Connectivity c = Find(grid);
  ASSERT_EQ(c.matches.size(), 1u);  // corners shared with no edge are not matches
  const BoundaryMatch& m = c.matches[0];
  EXPECT_EQ(m.a.face, (Face{0, 0, true}));
  EXPECT_EQ(m.b.face, (Face{1, 0, false}));
  EXPECT_EQ(m.a.begin, (Extents{4, 0, 0}));
  EXPECT_EQ(m.a.end, (Extents{4, 4, 0}));
  EXPECT_EQ(m.b.begin, (Extents{0, 0, 0}));
  EXPECT_EQ(m.b.end, (Extents{0, 4, 0}));
  EXPECT_EQ(m.b_direction, (std::array<int, 3>{-1, 1, -1}));
  EXPECT_FALSE(m.reversed[1]);
  EXPECT_EQ(m.step, 1);
  ExpectCoincident(grid, m, 0.0);
  EXPECT_EQ(m.Describe(), "block 0 i=max j[0..4] ~ block 1 i=0 j[0..4] j->j");
}

// Two blocks of 3 x `n` points sharing their long edge: 4n boundary points, enough for several
// polls of the cancel check (once per 2^16 points).
MultiBlockGrid LongSideBySide(int n) {
  MultiBlockGrid grid;
  for (int b = 0; b < 2; ++b) {
    StructuredBlock block({3, n, 1}, 2);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < 3; ++i) {
        block.Point(i, j, 0)[0] = 0.5 * (2 * b + i);
        block.Point(i, j, 0)[1] = 1e-3 * j;
      }
    }
    grid.blocks.push_back(std::move(block));
  }
  return grid;
}

TEST(ConnectivityTest, PollsTheCancelCheckWhileHashingAndWhileMatching) {
  const MultiBlockGrid grid = LongSideBySide(60000);
  int polls = 0;
  const absl::StatusOr<Connectivity> never =
      FindConnectivity(grid, {}, [&polls] { return ++polls < 0; });
  ASSERT_TRUE(never.ok()) << never.status();
  EXPECT_EQ(*never, Find(grid));  // the same matches as without a check
  ASSERT_EQ(never->matches.size(), 1u);
  // 240,000 boundary points are hashed (3 polls), then visited (27 units each: about 100 polls)
  // and the 60,000 matched pairs grown and marked (about 2).
  EXPECT_GE(polls, 6);
  // Cancelled at the first poll (hashing) and at the last (matching): CANCELLED either way.
  for (const int fire_at : {1, polls}) {
    SCOPED_TRACE(fire_at);
    int count = 0;
    const absl::StatusOr<Connectivity> stopped =
        FindConnectivity(grid, {}, [&] { return ++count >= fire_at; });
    EXPECT_EQ(stopped.status().code(), absl::StatusCode::kCancelled);
    EXPECT_EQ(count, fire_at);  // stopped at once
  }
}

TEST(ConnectivityTest, PartialEdgeCoversOnlyTheOverlap) {
  // B starts half way up A's edge: A's j 4..8 are B's j 0..4.
  const MultiBlockGrid grid = SideBySide(9, 0.5);
  const Connectivity c = Find(grid);
  ASSERT_EQ(c.matches.size(), 1u);
  const BoundaryMatch& m = c.matches[0];
  EXPECT_EQ(m.a.begin, (Extents{8, 4, 0}));
  EXPECT_EQ(m.a.end, (Extents{8, 8, 0}));
  EXPECT_EQ(m.b.begin, (Extents{0, 0, 0}));
  EXPECT_EQ(m.b.end, (Extents{0, 4, 0}));
  EXPECT_EQ(m.MapToB({8, 6, 0}), (Extents{0, 2, 0}));
  ExpectCoincident(grid, m, 0.0);
}

TEST(ConnectivityTest, ReversedOrientation) {
  const MultiBlockGrid grid = SideBySide(5, 0.0, 0, /*reversed=*/true);
  const Connectivity c = Find(grid);
  ASSERT_EQ(c.matches.size(), 1u);
  const BoundaryMatch& m = c.matches[0];
  EXPECT_EQ(m.b_direction[1], 1);
  EXPECT_TRUE(m.reversed[1]);
  EXPECT_EQ(m.MapToB({4, 0, 0}), (Extents{0, 4, 0}));
  EXPECT_EQ(m.MapToB({4, 1, 0}), (Extents{0, 3, 0}));
  ExpectCoincident(grid, m, kSameExpressionTol);
  EXPECT_THAT(m.Describe(), HasSubstr("j->j reversed"));
}

TEST(ConnectivityTest, HangingNodesOnEverySecondPointOfTheFineEdge) {
  // B has 9 points on the edge where A has 5: A's points are B's even points.
  const MultiBlockGrid grid = SideBySide(5, 0.0, 9);
  const Connectivity c = Find(grid);
  ASSERT_EQ(c.matches.size(), 1u);
  const BoundaryMatch& m = c.matches[0];
  EXPECT_EQ(m.step, 2);
  EXPECT_EQ(m.a.face.block, 0);  // the coarse side first
  EXPECT_EQ(m.b.begin, (Extents{0, 0, 0}));
  EXPECT_EQ(m.b.end, (Extents{0, 8, 0}));
  EXPECT_EQ(m.MapToB({4, 3, 0}), (Extents{0, 6, 0}));
  ExpectCoincident(grid, m, kSameExpressionTol);
  EXPECT_THAT(m.Describe(), HasSubstr("(hanging nodes)"));

  // The coarse side given second: the match still names it first.
  MultiBlockGrid swapped;
  swapped.blocks = {grid.blocks[1], grid.blocks[0]};
  const Connectivity cs = Find(swapped);
  ASSERT_EQ(cs.matches.size(), 1u);
  EXPECT_EQ(cs.matches[0].a.face, (Face{1, 0, true}));
  EXPECT_EQ(cs.matches[0].step, 2);
  ExpectCoincident(swapped, cs.matches[0], kSameExpressionTol);
}

TEST(ConnectivityTest, HangingNodesMustLieOnTheCoarseEdge) {
  // The fine edge's odd points pushed sideways by 0.3 of the coarse spacing: its even points
  // still coincide with the coarse edge, but it is not the same edge.
  MultiBlockGrid grid = SideBySide(5, 0.0, 9);
  StructuredBlock& fine = grid.blocks[1];
  for (int j = 1; j < 9; j += 2) fine.Point(0, j, 0)[0] -= 0.3 * 0.25;
  EXPECT_TRUE(Find(grid).matches.empty());
}

TEST(ConnectivityTest, CGridWakeCutIsAReversedSelfMatch) {
  const CGrid c = MakeCGrid();
  const Connectivity conn = Find(c.grid);
  ASSERT_EQ(conn.matches.size(), 1u);
  const BoundaryMatch& m = conn.matches[0];
  EXPECT_EQ(m.a.face, (Face{0, 1, false}));
  EXPECT_EQ(m.b.face, (Face{0, 1, false}));
  EXPECT_EQ(m.a.begin[0], 0);
  EXPECT_EQ(m.a.end[0], c.wake_cells);  // up to and including the trailing edge
  EXPECT_EQ(m.b.begin[0], c.ni - 1 - c.wake_cells);
  EXPECT_EQ(m.b.end[0], c.ni - 1);
  EXPECT_TRUE(m.reversed[0]);
  EXPECT_EQ(m.MapToB({0, 0, 0}), (Extents{c.ni - 1, 0, 0}));
  ExpectCoincident(c.grid, m, 0.0);
  EXPECT_THAT(m.Describe(), HasSubstr("block 0 j=0 i[0..6] ~ block 0 j=0 i[38..44]"));
}

// The classical C-grid of a parabola, z = w^2 with w = s + i t: its wall line t = 0 is the
// positive real axis traversed twice, folding back at the single point s = 0, so the whole line
// is the wake cut, each half matching the other reversed. The two ranges share only the fold
// point; grown further, every point would map onto its own line (the whole face onto itself).
TEST(ConnectivityTest, LineFoldingAtOnePointMatchesItsOtherHalf) {
  MultiBlockGrid grid;
  grid.blocks.push_back(PlanarBlock(17, 5, [](int i, int j) -> std::array<double, 2> {
    const double s = -2.0 + 0.25 * i, t = 0.25 * j;
    return {s * s - t * t, 2.0 * s * t};
  }));
  const Connectivity c = Find(grid);
  ASSERT_EQ(c.matches.size(), 1u);
  const BoundaryMatch& m = c.matches[0];
  EXPECT_EQ(m.a.face, (Face{0, 1, false}));
  EXPECT_EQ(m.b.face, (Face{0, 1, false}));
  EXPECT_EQ(m.a.begin[0], 0);
  EXPECT_EQ(m.a.end[0], 8);
  EXPECT_EQ(m.b.begin[0], 8);
  EXPECT_EQ(m.b.end[0], 16);
  EXPECT_TRUE(m.reversed[0]);
  ExpectCoincident(grid, m, kSameExpressionTol);
}

TEST(ConnectivityTest, VolumeFaceWithPermutedAndReversedDirections) {
  const MultiBlockGrid grid = SplitBox(4);
  const Connectivity c = Find(grid);
  // Only the face x = 1: the neighbouring faces of the two blocks share a line, not a range.
  ASSERT_EQ(c.matches.size(), 1u);
  const BoundaryMatch& m = c.matches[0];
  EXPECT_EQ(m.a.face, (Face{0, 0, true}));
  EXPECT_EQ(m.b.face, (Face{1, 1, false}));
  EXPECT_EQ(m.b_direction, (std::array<int, 3>{-1, 0, 2}));
  EXPECT_FALSE(m.reversed[1]);
  EXPECT_TRUE(m.reversed[2]);
  EXPECT_EQ(m.MapToB({3, 1, 0}), (Extents{1, 0, 3}));
  ExpectCoincident(grid, m, kSameExpressionTol);
}

TEST(ConnectivityTest, SurfacesInSpace) {
  // The Moebius strip: both seams, one forwards and one reversed.
  const MultiBlockGrid grid = MoebiusStrip();
  const Connectivity c = Find(grid);
  ASSERT_EQ(c.matches.size(), 2u);
  int reversed = 0;
  for (const BoundaryMatch& m : c.matches) {
    ExpectCoincident(grid, m, kSameExpressionTol);
    EXPECT_EQ(m.b_direction[1], 1);
    reversed += m.reversed[1];
  }
  EXPECT_EQ(reversed, 1);
}

TEST(ConnectivityTest, AbsoluteAndRelativeTolerances) {
  MultiBlockGrid grid = SideBySide(5);
  // Shift B by 1e-6: beyond the default (1e-7 of the diagonal), within an explicit 1e-5.
  for (double& x : grid.blocks[1].coords()) x += 1e-6;
  EXPECT_TRUE(Find(grid).matches.empty());
  ConnectivityOptions loose;
  loose.absolute_tolerance = 1e-5;
  ASSERT_EQ(Find(grid, loose).matches.size(), 1u);
  ExpectCoincident(grid, Find(grid, loose).matches[0], 2e-6);
  // ... unless the grid is finer than 1000 times the distance next to the points: squeeze B's
  // first column to 1e-4 from its edge.
  for (int j = 0; j < 5; ++j) {
    const double* edge = grid.blocks[1].Point(0, j, 0);
    double* next = grid.blocks[1].Point(1, j, 0);
    next[0] = edge[0] + 1e-4;
    next[1] = edge[1];
  }
  EXPECT_TRUE(Find(grid, loose).matches.empty());
}

TEST(ConnectivityTest, MinPointsDropsShortMatches) {
  // B overlaps A's edge in two points (j 3..4 of A).
  const MultiBlockGrid grid = SideBySide(5, 0.75);
  ASSERT_EQ(Find(grid).matches.size(), 1u);
  EXPECT_EQ(Find(grid).matches[0].a.begin[1], 3);
  ConnectivityOptions options;
  options.min_points = 3;
  EXPECT_TRUE(Find(grid, options).matches.empty());
}

TEST(ConnectivityTest, Errors) {
  EXPECT_TRUE(Find(MultiBlockGrid{}).matches.empty());
  MultiBlockGrid mixed = SideBySide(3);
  mixed.blocks.push_back(StructuredBlock({3, 3, 1}, 3));
  absl::StatusOr<Connectivity> c = FindConnectivity(mixed);
  EXPECT_EQ(c.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(c.status().message(), HasSubstr("block 2"));
  MultiBlockGrid nan = SideBySide(3);
  nan.blocks[1].Point(2, 1, 0)[1] = std::nan("");
  c = FindConnectivity(nan);
  EXPECT_EQ(c.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(c.status().message(), HasSubstr("block 1"));
  EXPECT_THAT(c.status().message(), HasSubstr("(2, 1, 0)"));
}

TEST(ConnectivityTest, BlockFacesAndNames) {
  const StructuredBlock surface({4, 3, 1}, 3);
  const std::vector<Face> faces = BlockFaces(surface, 7);
  ASSERT_EQ(faces.size(), 4u);
  EXPECT_EQ(faces[0], (Face{7, 0, false}));
  EXPECT_EQ(faces[3], (Face{7, 1, true}));
  EXPECT_EQ(BlockFaces(StructuredBlock({2, 2, 2}, 3), 0).size(), 6u);
  EXPECT_EQ(FaceName({0, 2, true}), "k=max");
  EXPECT_EQ(FaceName({0, 0, false}), "i=0");
}

// ----- Shared grids ----------------------------------------------------------------------------

MultiBlockGrid ReadShared(const std::string& relative, bool planar) {
  absl::StatusOr<MultiBlockGrid> grid = ReadPlot3dFile(SharedDataPath(relative));
  EXPECT_TRUE(grid.ok()) << grid.status();
  if (!grid.ok()) return {};
  if (!planar) return *std::move(grid);
  absl::StatusOr<MultiBlockGrid> view = AsPlanarGrid(*grid);
  EXPECT_TRUE(view.ok()) << view.status();
  return view.ok() ? *std::move(view) : MultiBlockGrid{};
}

// The largest coordinate magnitude of `grid`: the scale of its rounding errors.
double CoordinateScale(const MultiBlockGrid& grid) {
  double scale = 0.0;
  for (const StructuredBlock& b : grid.blocks) {
    for (double x : b.coords()) scale = std::max(scale, std::abs(x));
  }
  return scale;
}

// The C-grids have exactly one match: the wake cut, j = 0 folding back onto itself from both
// ends of the wall line, reversed.
TEST(ConnectivitySharedGridTest, CGridsHaveTheirWakeCut) {
  for (const char* file : {"grids/n0012_113-33.p2dfmt", "grids/rae2822_257x97.fmt"}) {
    SCOPED_TRACE(file);
    const MultiBlockGrid grid = ReadShared(file, /*planar=*/true);
    ASSERT_EQ(grid.blocks.size(), 1u);
    const int ni = grid.blocks[0].extent(0);
    const Connectivity c = Find(grid);
    ASSERT_EQ(c.matches.size(), 1u);
    const BoundaryMatch& m = c.matches[0];
    EXPECT_EQ(m.a.face, (Face{0, 1, false}));
    EXPECT_EQ(m.b.face, (Face{0, 1, false}));
    EXPECT_TRUE(m.reversed[0]);
    EXPECT_EQ(m.a.begin[0], 0);
    EXPECT_EQ(m.b.end[0], ni - 1);
    // The wake is shorter than half the wall line: the airfoil lies between its two sides.
    EXPECT_LT(m.a.end[0], m.b.begin[0]);
    ExpectCoincident(grid, m, 1e-7 * CoordinateScale(grid));
  }
}

// The cube sphere: 6 blocks, 12 cube edges, each shared by exactly two blocks along its whole
// length.
TEST(ConnectivitySharedGridTest, CubeSphereHasTwelveFullEdges) {
  const MultiBlockGrid grid = ReadShared("surfaces/even_sphere.fmt", /*planar=*/false);
  ASSERT_EQ(grid.blocks.size(), 6u);
  const Connectivity c = Find(grid);
  EXPECT_EQ(c.matches.size(), 12u);
  std::vector<int> uses(6 * 4, 0);  // per block face
  for (const BoundaryMatch& m : c.matches) {
    ExpectCoincident(grid, m, 1e-7 * CoordinateScale(grid));
    EXPECT_NE(m.a.face.block, m.b.face.block);
    for (const FaceRange* r : {&m.a, &m.b}) {
      const int t = 1 - r->face.normal;  // the tangential direction of an edge
      EXPECT_EQ(r->begin[t], 0);
      EXPECT_EQ(r->end[t], grid.blocks[r->face.block].extent(t) - 1);
      ++uses[4 * r->face.block + 2 * r->face.normal + r->face.upper];
    }
  }
  EXPECT_THAT(uses, ::testing::Each(1));
}

// The M6 wing surface is closed except at the root, on the symmetry plane z = 0: every block
// edge off that plane is shared by exactly one match, the root edges by none.
TEST(ConnectivitySharedGridTest, M6WingIsClosedExceptAtTheRoot) {
  const MultiBlockGrid grid = ReadShared("surfaces/m6_small.fmt", /*planar=*/false);
  ASSERT_EQ(grid.blocks.size(), 9u);
  const Connectivity c = Find(grid);
  std::vector<int> uses(9 * 4, 0);
  for (const BoundaryMatch& m : c.matches) {
    ExpectCoincident(grid, m, 1e-7 * CoordinateScale(grid));
    for (const FaceRange* r : {&m.a, &m.b}) {
      const int t = 1 - r->face.normal;
      EXPECT_EQ(r->end[t] - r->begin[t], grid.blocks[r->face.block].extent(t) - 1);
      ++uses[4 * r->face.block + 2 * r->face.normal + r->face.upper];
    }
  }
  int root_edges = 0;
  for (int b = 0; b < 9; ++b) {
    for (const Face& f : BlockFaces(grid.blocks[b], b)) {
      const StructuredBlock& block = grid.blocks[b];
      double largest_z = 0.0;
      const int at = f.upper ? block.extent(f.normal) - 1 : 0;
      for (int t = 0; t < block.extent(1 - f.normal); ++t) {
        const double* p = f.normal == 0 ? block.Point(at, t, 0) : block.Point(t, at, 0);
        largest_z = std::max(largest_z, std::abs(p[2]));
      }
      const bool root = largest_z == 0.0;
      root_edges += root;
      EXPECT_EQ(uses[4 * b + 2 * f.normal + f.upper], root ? 0 : 1) << b << " " << FaceName(f);
    }
  }
  EXPECT_GT(root_edges, 0);
  EXPECT_EQ(static_cast<int>(c.matches.size()), (9 * 4 - root_edges) / 2);
}

}  // namespace
}  // namespace splinegrid
