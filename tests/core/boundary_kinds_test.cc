// ClassifyBoundaries (geometry, connectivity and overrides, in that order of precedence),
// BoundaryTolerances and PointTolerances, on small grids built here and on the shared C-grid
// and wing surface.
#include "core/grid/boundary_kinds.h"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/planar_view.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/synthetic_grids.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr uint8_t kWall = static_cast<uint8_t>(BoundaryKind::kWall);
constexpr uint8_t kInterface = static_cast<uint8_t>(BoundaryKind::kInterface);
constexpr uint8_t kOuter = static_cast<uint8_t>(BoundaryKind::kOuter);
constexpr double kInf = std::numeric_limits<double>::infinity();

// A planar block of ni x 11 points over [x0, x0 + 1] x [0, ~1], clustered towards y = 0: the
// spacing starts at 1e-3 and doubles per layer, so the first layer is 1/32 of the median one.
StructuredBlock WallBlock(double x0, int ni) {
  const std::vector<double> y = GeometricSpacing(11, 1e-3, 2.0);
  return PlanarBlock(ni, 11, [=](int i, int j) { return Bend(x0 + i / (ni - 1.0), y[j]); });
}

BoundaryKinds Classify(const MultiBlockGrid& grid, std::span<const FaceKindOverride> overrides = {},
                       const BoundaryKindOptions& options = {}) {
  absl::StatusOr<Connectivity> c = FindConnectivity(grid);
  EXPECT_TRUE(c.ok()) << c.status();
  absl::StatusOr<BoundaryKinds> kinds =
      ClassifyBoundaries(grid, c.ok() ? *c : Connectivity{}, overrides, options);
  EXPECT_TRUE(kinds.ok()) << kinds.status();
  return kinds.ok() ? *std::move(kinds) : BoundaryKinds{};
}

uint8_t KindAt(const MultiBlockGrid& grid, const BoundaryKinds& kinds, int b, int i, int j,
               int k = 0) {
  return kinds.point_kinds[b][grid.blocks[b].Index(i, j, k)];
}

TEST(BoundaryKindsTest, ClusteringMakesAWallOtherFacesAreOuter) {
  MultiBlockGrid grid;
  grid.blocks.push_back(WallBlock(0.0, 9));
  const BoundaryKinds kinds = Classify(grid);
  // Faces in BlockFaces order: i=0, i=max, j=0, j=max.
  EXPECT_THAT(kinds.face_kinds[0], ElementsAre(BoundaryKind::kOuter, BoundaryKind::kOuter,
                                               BoundaryKind::kWall, BoundaryKind::kOuter));
  EXPECT_EQ(KindAt(grid, kinds, 0, 4, 0), kWall);
  EXPECT_EQ(KindAt(grid, kinds, 0, 4, 10), kOuter);
  EXPECT_EQ(KindAt(grid, kinds, 0, 0, 5), kOuter);
  EXPECT_EQ(KindAt(grid, kinds, 0, 4, 5), 0);
  EXPECT_EQ(KindAt(grid, kinds, 0, 0, 0), kWall | kOuter);  // a corner carries both faces' kinds
  EXPECT_EQ(KindAt(grid, kinds, 0, 8, 10), kOuter);
  // The threshold: at a ratio of 0.02 the first layer (1/32 of the median) is no wall.
  BoundaryKindOptions strict;
  strict.wall_spacing_ratio = 0.02;
  EXPECT_EQ(Classify(grid, {}, strict).face_kinds[0][2], BoundaryKind::kOuter);
}

TEST(BoundaryKindsTest, MatchedPointsAreInterfaceAndKeepTheirOtherFacesKinds) {
  MultiBlockGrid grid;
  grid.blocks.push_back(WallBlock(0.0, 5));
  grid.blocks.push_back(WallBlock(1.0, 5));
  const BoundaryKinds kinds = Classify(grid);
  for (int j = 1; j < 10; ++j) {
    EXPECT_EQ(KindAt(grid, kinds, 0, 4, j), kInterface) << j;
    EXPECT_EQ(KindAt(grid, kinds, 1, 0, j), kInterface) << j;
  }
  // Where the wall meets the interface the point is on both faces: wall and interface, so it
  // gets the wall's (tighter) tolerance.
  EXPECT_EQ(KindAt(grid, kinds, 0, 4, 0), kWall | kInterface);
  EXPECT_EQ(KindAt(grid, kinds, 1, 0, 0), kWall | kInterface);
  EXPECT_EQ(KindAt(grid, kinds, 0, 4, 10), kOuter | kInterface);
  BoundaryTolerances tolerances;
  EXPECT_EQ(PointTolerances(kinds, 0, tolerances)[grid.blocks[0].Index(4, 0, 0)], tolerances.wall);
  // The face's kind is still recorded for the face (its unmatched points).
  EXPECT_EQ(kinds.face_kinds[0][1], BoundaryKind::kOuter);
}

TEST(BoundaryKindsTest, CGridWakeIsInterfaceTheBodyIsWall) {
  const CGrid c = MakeCGrid();
  const BoundaryKinds kinds = Classify(c.grid);
  const int upper_wake = c.ni - 1 - c.wake_cells;
  for (int i = 0; i < c.ni; ++i) {
    const bool wake = i <= c.wake_cells || i >= upper_wake;
    const bool end = i == 0 || i == c.ni - 1;  // also on the outflow faces i=0, i=max
    // The trailing edge points end the wake cut and begin the airfoil: both kinds.
    const bool trailing_edge = i == c.wake_cells || i == upper_wake;
    const uint8_t expected = trailing_edge ? kInterface | kWall
                             : wake        ? (end ? kInterface | kOuter : kInterface)
                                           : kWall;
    EXPECT_EQ(KindAt(c.grid, kinds, 0, i, 0), expected) << i;
  }
}

TEST(BoundaryKindsTest, OverridesApplyToUnmatchedPoints) {
  const MultiBlockGrid grid = SideBySide(5);
  // A's i=0 (outer by geometry) made a wall; A's i=max is matched and stays interface; B's
  // j=max made an interface by hand.
  const std::vector<FaceKindOverride> overrides = {{{0, 0, false}, BoundaryKind::kWall},
                                                   {{0, 0, true}, BoundaryKind::kWall},
                                                   {{1, 1, true}, BoundaryKind::kInterface}};
  const BoundaryKinds kinds = Classify(grid, overrides);
  EXPECT_EQ(kinds.face_kinds[0][0], BoundaryKind::kWall);
  EXPECT_EQ(kinds.face_kinds[0][1], BoundaryKind::kWall);
  EXPECT_EQ(kinds.face_kinds[1][3], BoundaryKind::kInterface);
  EXPECT_EQ(KindAt(grid, kinds, 0, 0, 2), kWall);
  EXPECT_EQ(KindAt(grid, kinds, 0, 4, 2), kInterface);
  EXPECT_EQ(KindAt(grid, kinds, 1, 2, 4), kInterface);
  EXPECT_EQ(KindAt(grid, kinds, 0, 0, 0), kWall | kOuter);
  // Without overrides the same points are outer.
  const BoundaryKinds plain = Classify(grid);
  EXPECT_EQ(KindAt(grid, plain, 0, 0, 2), kOuter);
  EXPECT_EQ(KindAt(grid, plain, 1, 2, 4), kOuter);
}

TEST(BoundaryKindsTest, OverridesNamingMissingFacesAreErrors) {
  const MultiBlockGrid grid = SideBySide(3);
  const Connectivity none;
  for (const Face& face : {Face{2, 0, false}, Face{-1, 0, false}, Face{0, 3, false},
                           Face{0, -1, true}, Face{1, 2, false}}) {
    const FaceKindOverride o{face, BoundaryKind::kWall};
    const absl::StatusOr<BoundaryKinds> kinds = ClassifyBoundaries(grid, none, {&o, 1});
    EXPECT_EQ(kinds.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(kinds.status().message(), HasSubstr("does not exist"));
    EXPECT_THAT(kinds.status().message(), HasSubstr(absl::StrCat("block ", face.block)));
  }
}

TEST(BoundaryKindsTest, SurfaceBlocksInSpaceAreWallEverywhere) {
  const MultiBlockGrid grid = MoebiusStrip(9, 5);
  const BoundaryKinds kinds = Classify(grid);
  for (int b = 0; b < 2; ++b) {
    EXPECT_THAT(kinds.face_kinds[b], ::testing::Each(BoundaryKind::kWall));
    EXPECT_EQ(KindAt(grid, kinds, b, 4, 2), kWall);  // inside the surface too
    EXPECT_EQ(KindAt(grid, kinds, b, 0, 2), kWall | kInterface);
    EXPECT_EQ(KindAt(grid, kinds, b, 4, 0), kWall);
  }
}

TEST(BoundaryKindsTest, VolumeFaces) {
  // 5 x 5 x 11 points clustered towards k = 0; the other faces are evenly spaced.
  const std::vector<double> z = GeometricSpacing(11, 1e-3, 2.0);
  MultiBlockGrid grid;
  grid.blocks.push_back(SpaceBlock(
      5, 5, 11, [&](int i, int j, int k) { return BendVolume(0.25 * i, 0.25 * j, z[k]); }));
  const BoundaryKinds kinds = Classify(grid);
  EXPECT_THAT(kinds.face_kinds[0],
              ElementsAre(BoundaryKind::kOuter, BoundaryKind::kOuter, BoundaryKind::kOuter,
                          BoundaryKind::kOuter, BoundaryKind::kWall, BoundaryKind::kOuter));
  EXPECT_EQ(KindAt(grid, kinds, 0, 2, 2, 0), kWall);
  EXPECT_EQ(KindAt(grid, kinds, 0, 0, 2, 0), kWall | kOuter);
  EXPECT_EQ(KindAt(grid, kinds, 0, 2, 2, 5), 0);
  EXPECT_EQ(KindAt(grid, kinds, 0, 2, 2, 10), kOuter);
  int interior = 0;
  for (uint8_t k : kinds.point_kinds[0]) interior += k == 0;
  EXPECT_EQ(interior, 3 * 3 * 9);
}

TEST(BoundaryKindsTest, ToleranceValidationNamesTheField) {
  EXPECT_TRUE(BoundaryTolerances{}.Validate().ok());
  const double nan = std::nan("");
  struct Case {
    double BoundaryTolerances::*field;
    double value;
    const char* name;
  };
  for (const Case& c : {Case{&BoundaryTolerances::wall, 0.0, "tolerances.wall"},
                        Case{&BoundaryTolerances::wall, nan, "tolerances.wall"},
                        Case{&BoundaryTolerances::interface, -1.0, "tolerances.interface"},
                        Case{&BoundaryTolerances::outer, kInf, "tolerances.outer"},
                        Case{&BoundaryTolerances::interior, 0.0, "tolerances.interior"},
                        Case{&BoundaryTolerances::interior, nan, "tolerances.interior"},
                        Case{&BoundaryTolerances::edge, 1.5, "tolerances.edge"},
                        Case{&BoundaryTolerances::edge, -0.1, "tolerances.edge"},
                        Case{&BoundaryTolerances::edge, nan, "tolerances.edge"},
                        Case{&BoundaryTolerances::first_layer, 1.5, "tolerances.first_layer"},
                        Case{&BoundaryTolerances::first_layer, -0.1, "tolerances.first_layer"},
                        Case{&BoundaryTolerances::first_layer, nan, "tolerances.first_layer"}}) {
    BoundaryTolerances t;
    t.*c.field = c.value;
    const absl::Status status = t.Validate();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << c.name << " = " << c.value;
    EXPECT_THAT(status.message(), HasSubstr(c.name));
  }
  BoundaryTolerances ok;
  ok.interior = kInf;
  ok.edge = 0.0;
  EXPECT_TRUE(ok.Validate().ok());
  ok.edge = 1.0;
  ok.interior = 1e-3;
  EXPECT_TRUE(ok.Validate().ok());
}

TEST(BoundaryKindsTest, TheTightestKindDecides) {
  BoundaryTolerances t;
  t.wall = 1.0;
  t.interface = 2.0;
  t.outer = 3.0;
  t.interior = 4.0;
  EXPECT_EQ(t.For(0), 4.0);
  EXPECT_EQ(t.For(kWall), 1.0);
  EXPECT_EQ(t.For(kInterface), 2.0);
  EXPECT_EQ(t.For(kOuter), 3.0);
  EXPECT_EQ(t.For(kInterface | kOuter), 2.0);
  EXPECT_EQ(t.For(kWall | kInterface | kOuter), 1.0);
  t.outer = 0.5;
  EXPECT_EQ(t.For(kWall | kOuter), 0.5);
  EXPECT_EQ(BoundaryTolerances{}.For(0), kInf);
  EXPECT_EQ(BoundaryKindName(BoundaryKind::kWall), "wall");
  EXPECT_EQ(BoundaryKindName(BoundaryKind::kInterface), "interface");
  EXPECT_EQ(BoundaryKindName(BoundaryKind::kOuter), "outer");

  BoundaryKinds kinds;
  kinds.point_kinds = {{0, kWall}, {kOuter, kInterface | kWall, kInterface}};
  EXPECT_THAT(PointTolerances(kinds, 1, t), ElementsAre(0.5, 1.0, 2.0));
  EXPECT_THAT(PointTolerances(kinds, 0, t), ElementsAre(4.0, 1.0));
}

// The first-layer edges go from each wall point one step into the block across its face:
// on an O-grid also at the seam, whose inner end is an interface point (the trailing edge of a
// generated grid), never along the wall, and none between two walls two points apart.
TEST(BoundaryKindsTest, FirstLayerEdgesLeaveEveryWallPointInward) {
  constexpr double kPi = 3.14159265358979323846;
  const int ni = 33, nj = 9;  // an annulus, its inner circle a wall, the first line repeated
  MultiBlockGrid ring;
  ring.blocks.emplace_back(Extents{ni, nj, 1}, 2);
  StructuredBlock& block = ring.blocks[0];
  for (int j = 0; j < nj; ++j) {
    const double r = 1.0 + 1e-3 * (std::pow(2.0, j) - 1.0);
    for (int i = 0; i < ni; ++i) {
      const double a = -2.0 * kPi * (i % (ni - 1)) / (ni - 1);  // clockwise
      block.Point(i, j, 0)[0] = r * std::cos(a);
      block.Point(i, j, 0)[1] = r * std::sin(a);
    }
  }
  const std::vector<FaceKindOverride> inner_wall = {{{0, 1, false}, BoundaryKind::kWall}};
  const BoundaryKinds kinds =
      ClassifyBoundaries(ring, FindConnectivity(ring).value(), inner_wall).value();
  ASSERT_EQ(KindAt(ring, kinds, 0, 0, 0), kWall | kInterface);
  ASSERT_EQ(KindAt(ring, kinds, 0, 0, 1), kInterface);  // the seam, inside the block
  std::vector<std::pair<int64_t, int64_t>> edges;
  ForEachFirstLayerEdge(block, kinds.point_kinds[0],
                        [&](int64_t p, int64_t q) { edges.emplace_back(p, q); });
  ASSERT_EQ(edges.size(), static_cast<size_t>(ni));
  for (int i = 0; i < ni; ++i) {
    EXPECT_EQ(edges[i], std::make_pair(block.Index(i, 0, 0), block.Index(i, 1, 0))) << i;
  }
  // Two walls two points apart: no first layer to keep.
  StructuredBlock thin(Extents{5, 2, 1}, 2);
  const std::vector<uint8_t> walls(thin.num_points(), kWall);
  int visits = 0;
  ForEachFirstLayerEdge(thin, walls, [&](int64_t, int64_t) { ++visits; });
  EXPECT_EQ(visits, 0);
}

// ----- Shared grids ----------------------------------------------------------------------------

// The NACA 0012 C-grid: the wall line j = 0 is a wall where it is not the wake cut, the wake
// cut is interface, the far field (j = max) and the outflow faces (i = 0, max) are outer.
TEST(BoundaryKindsSharedGridTest, NacaCGrid) {
  absl::StatusOr<MultiBlockGrid> read = ReadPlot3dFile(SharedDataPath("grids/n0012_113-33.p2dfmt"));
  ASSERT_TRUE(read.ok()) << read.status();
  const MultiBlockGrid grid = AsPlanarGrid(*read).value();
  const Connectivity c = FindConnectivity(grid).value();
  ASSERT_EQ(c.matches.size(), 1u);
  const BoundaryMatch& wake = c.matches[0];
  const BoundaryKinds kinds = ClassifyBoundaries(grid, c).value();
  EXPECT_THAT(kinds.face_kinds[0], ElementsAre(BoundaryKind::kOuter, BoundaryKind::kOuter,
                                               BoundaryKind::kWall, BoundaryKind::kOuter));
  const StructuredBlock& block = grid.blocks[0];
  const int ni = block.extent(0), nj = block.extent(1);
  for (int i = 1; i + 1 < ni; ++i) {
    const bool in_wake = i <= wake.a.end[0] || i >= wake.b.begin[0];
    const bool trailing_edge = i == wake.a.end[0] || i == wake.b.begin[0];
    EXPECT_EQ(KindAt(grid, kinds, 0, i, 0), trailing_edge ? kInterface | kWall
                                            : in_wake     ? kInterface
                                                          : kWall)
        << i;
    EXPECT_EQ(KindAt(grid, kinds, 0, i, nj - 1), kOuter) << i;
    EXPECT_EQ(KindAt(grid, kinds, 0, i, nj / 2), 0) << i;
  }
  for (int j = 1; j + 1 < nj; ++j) {
    EXPECT_EQ(KindAt(grid, kinds, 0, 0, j), kOuter) << j;
    EXPECT_EQ(KindAt(grid, kinds, 0, ni - 1, j), kOuter) << j;
  }
}

// The M6 wing surface: every point is wall; exactly the points of matched ranges are also
// interface.
TEST(BoundaryKindsSharedGridTest, M6SurfaceIsWallWithInterfaceSeams) {
  absl::StatusOr<MultiBlockGrid> grid = ReadPlot3dFile(SharedDataPath("surfaces/m6_small.fmt"));
  ASSERT_TRUE(grid.ok()) << grid.status();
  const Connectivity c = FindConnectivity(*grid).value();
  const BoundaryKinds kinds = ClassifyBoundaries(*grid, c).value();
  std::vector<std::vector<bool>> seam(grid->blocks.size());
  for (size_t b = 0; b < grid->blocks.size(); ++b) {
    seam[b].assign(grid->blocks[b].num_points(), false);
  }
  for (const BoundaryMatch& m : c.matches) {
    for (const FaceRange* r : {&m.a, &m.b}) {
      const StructuredBlock& block = grid->blocks[r->face.block];
      for (int j = r->begin[1]; j <= r->end[1]; ++j) {
        for (int i = r->begin[0]; i <= r->end[0]; ++i)
          seam[r->face.block][block.Index(i, j, 0)] = true;
      }
    }
  }
  int64_t seam_points = 0;
  for (size_t b = 0; b < grid->blocks.size(); ++b) {
    for (int64_t p = 0; p < grid->blocks[b].num_points(); ++p) {
      const uint8_t expected = seam[b][p] ? kWall | kInterface : kWall;
      ASSERT_EQ(kinds.point_kinds[b][p], expected) << "block " << b << " point " << p;
      seam_points += seam[b][p];
    }
  }
  EXPECT_GT(seam_points, 0);
}

}  // namespace
}  // namespace splinegrid
