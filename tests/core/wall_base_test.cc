// ClassifyBoundaries on a blunt base between two walls (issue 13, point 5): three blocks around
// a thick lip, whose base is one block's imin face with no clustering towards it, classify the
// base as wall automatically; the inflow face between a wall and the far field, the far field
// and the interfaces keep their kinds; an explicit override still wins. The same in 3D: the lip
// grid extruded along z into volume blocks.
#include <algorithm>
#include <vector>

#include "core/grid/boundary_kinds.h"
#include "core/grid/connectivity.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/synthetic_grids.h"

namespace splinegrid {
namespace {

using ::testing::ElementsAre;

constexpr uint8_t kWall = static_cast<uint8_t>(BoundaryKind::kWall);
constexpr uint8_t kInterface = static_cast<uint8_t>(BoundaryKind::kInterface);
constexpr uint8_t kOuter = static_cast<uint8_t>(BoundaryKind::kOuter);

// Lip half thickness, far-field height, points per block direction and base points.
constexpr double kHalf = 0.05;
constexpr int kNi = 9, kNj = 11, kBase = 16;

// The lip occupies x <= 0, |y| <= kHalf. Block 0 lies above it (x in [-1, 0], y from kHalf up to
// about 1, clustered towards the lip: its jmin is a wall), block 1 below it (mirrored, j going
// down), block 2 behind it (x in [0, 1], uniform in x), whose imin face is the lip's base
// (kBase points on |y| <= kHalf) between the two interfaces with blocks 0 and 1.
MultiBlockGrid LipGrid() {
  const std::vector<double> t = GeometricSpacing(kNj, 1e-3, 2.0);  // 0 .. ~1
  MultiBlockGrid grid;
  grid.blocks.push_back(PlanarBlock(kNi, kNj, [&](int i, int j) {
    return std::array{-1.0 + i / (kNi - 1.0), kHalf + t[j]};
  }));
  grid.blocks.push_back(PlanarBlock(kNi, kNj, [&](int i, int j) {
    return std::array{-1.0 + i / (kNi - 1.0), -kHalf - t[j]};
  }));
  std::vector<double> y;
  for (int j = kNj - 1; j > 0; --j) y.push_back(-kHalf - t[j]);
  for (int j = 0; j < kBase; ++j) y.push_back(-kHalf + 2.0 * kHalf * j / (kBase - 1));
  for (int j = 1; j < kNj; ++j) y.push_back(kHalf + t[j]);
  grid.blocks.push_back(PlanarBlock(kNi, static_cast<int>(y.size()), [&](int i, int j) {
    return std::array{i / (kNi - 1.0), y[j]};
  }));
  return grid;
}

BoundaryKinds Classify(const MultiBlockGrid& grid, size_t matches,
                       std::span<const FaceKindOverride> overrides = {}) {
  absl::StatusOr<Connectivity> c = FindConnectivity(grid);
  EXPECT_TRUE(c.ok()) << c.status();
  EXPECT_EQ(c.ok() ? c->matches.size() : 0u, matches);
  absl::StatusOr<BoundaryKinds> kinds =
      ClassifyBoundaries(grid, c.ok() ? *c : Connectivity{}, overrides);
  EXPECT_TRUE(kinds.ok()) << kinds.status();
  return kinds.ok() ? *std::move(kinds) : BoundaryKinds{};
}

uint8_t KindAt(const MultiBlockGrid& grid, const BoundaryKinds& kinds, int b, int i, int j,
               int k = 0) {
  return kinds.point_kinds[b][grid.blocks[b].Index(i, j, k)];
}

// Every planar block of `grid` extruded along z over [0, 1] with `nk` points.
MultiBlockGrid Extruded(const MultiBlockGrid& grid, int nk) {
  MultiBlockGrid out;
  for (const StructuredBlock& b : grid.blocks) {
    out.blocks.push_back(SpaceBlock(b.extent(0), b.extent(1), nk, [&](int i, int j, int k) {
      const double* p = b.Point(i, j, 0);
      return std::array{p[0], p[1], k / (nk - 1.0)};
    }));
  }
  return out;
}

TEST(WallBaseTest, BluntBaseBetweenTwoWallsIsWall) {
  const MultiBlockGrid grid = LipGrid();
  const BoundaryKinds kinds = Classify(grid, 2);
  const int base0 = kNj - 1, base1 = base0 + kBase - 1;  // block 2's j range of the base
  // Block 2, faces i=0, i=max, j=0, j=max: the base face is a wall now; the rest outer.
  EXPECT_THAT(kinds.face_kinds[2], ElementsAre(BoundaryKind::kWall, BoundaryKind::kOuter,
                                               BoundaryKind::kOuter, BoundaryKind::kOuter));
  for (int j = base0 + 1; j < base1; ++j) EXPECT_EQ(KindAt(grid, kinds, 2, 0, j), kWall) << j;
  // The base's ends are the lip's corners: interface (matched) and wall.
  EXPECT_EQ(KindAt(grid, kinds, 2, 0, base0), kInterface | kWall);
  EXPECT_EQ(KindAt(grid, kinds, 2, 0, base1), kInterface | kWall);
  // The interfaces stay interface only.
  EXPECT_EQ(KindAt(grid, kinds, 2, 0, 3), kInterface);
  EXPECT_EQ(KindAt(grid, kinds, 0, kNi - 1, 5), kInterface);
  // Blocks 0 and 1: lip wall at j=0, inflow (i=0, between the wall and the far field) and far
  // field outer.
  for (int b : {0, 1}) {
    EXPECT_EQ(kinds.face_kinds[b][0], BoundaryKind::kOuter) << b;  // i=0; i=max is matched
    EXPECT_EQ(kinds.face_kinds[b][2], BoundaryKind::kWall) << b;
    EXPECT_EQ(kinds.face_kinds[b][3], BoundaryKind::kOuter) << b;
    EXPECT_EQ(KindAt(grid, kinds, b, 0, 5), kOuter) << b;
    EXPECT_EQ(KindAt(grid, kinds, b, 4, kNj - 1), kOuter) << b;
    EXPECT_EQ(KindAt(grid, kinds, b, 4, 0), kWall) << b;
  }
  // The outflow face of block 2 stays outer.
  EXPECT_EQ(KindAt(grid, kinds, 2, kNi - 1, base0 + 3), kOuter);
}

TEST(WallBaseTest, OverrideWinsAndAChannelInletStaysOuter) {
  const MultiBlockGrid grid = LipGrid();
  const std::vector<FaceKindOverride> outer = {{{2, 0, false}, BoundaryKind::kOuter}};
  const BoundaryKinds kinds = Classify(grid, 2, outer);
  EXPECT_EQ(kinds.face_kinds[2][0], BoundaryKind::kOuter);
  EXPECT_EQ(KindAt(grid, kinds, 2, 0, kNj + 2), kOuter);
  // A channel: one block with walls at j=0 and j=max (clustered at both), its inlet i=0 between
  // them. The walls run along the block, not behind the inlet: the inlet stays outer.
  const std::vector<double> t = GeometricSpacing(kNj, 1e-3, 2.0);
  std::vector<double> y = t;
  for (int j = static_cast<int>(t.size()) - 2; j >= 0; --j) y.push_back(2.0 * t.back() - t[j]);
  MultiBlockGrid channel;
  channel.blocks.push_back(PlanarBlock(kNi, static_cast<int>(y.size()), [&](int i, int j) {
    return std::array{i / (kNi - 1.0), y[j]};
  }));
  const BoundaryKinds inlet = Classify(channel, 0);
  EXPECT_THAT(inlet.face_kinds[0], ElementsAre(BoundaryKind::kOuter, BoundaryKind::kOuter,
                                               BoundaryKind::kWall, BoundaryKind::kWall));
}

// The lip extruded: the base (block 2's imin face between the two interfaces) is a wall across
// the span; along the span its lines end on the side planes kmin and kmax, which stay outer and
// keep that kind on their edges with the base.
TEST(WallBaseTest, BluntBaseOfAVolumeGridIsWall) {
  constexpr int kNk = 5;
  const MultiBlockGrid grid = Extruded(LipGrid(), kNk);
  const BoundaryKinds kinds = Classify(grid, 2);
  const int base0 = kNj - 1, base1 = base0 + kBase - 1;
  EXPECT_THAT(kinds.face_kinds[2],
              ElementsAre(BoundaryKind::kWall, BoundaryKind::kOuter, BoundaryKind::kOuter,
                          BoundaryKind::kOuter, BoundaryKind::kOuter, BoundaryKind::kOuter));
  for (int k = 0; k < kNk; ++k) {
    const uint8_t side = k == 0 || k == kNk - 1 ? kOuter : 0;
    for (int j = base0 + 1; j < base1; ++j) {
      EXPECT_EQ(KindAt(grid, kinds, 2, 0, j, k), kWall | side) << j << " " << k;
    }
    EXPECT_EQ(KindAt(grid, kinds, 2, 0, base0, k), kInterface | kWall | side) << k;
    EXPECT_EQ(KindAt(grid, kinds, 2, 0, 3, k), kInterface | side) << k;
    EXPECT_EQ(KindAt(grid, kinds, 2, kNi - 1, base0 + 3, k), kOuter) << k;  // outflow
  }
  for (int b : {0, 1}) {
    // i=max is matched (its face kind applies to no point).
    EXPECT_EQ(kinds.face_kinds[b][0], BoundaryKind::kOuter) << b;
    EXPECT_EQ(kinds.face_kinds[b][2], BoundaryKind::kWall) << b;
    for (int f : {3, 4, 5}) EXPECT_EQ(kinds.face_kinds[b][f], BoundaryKind::kOuter) << b << f;
    EXPECT_EQ(KindAt(grid, kinds, b, 0, 5, 2), kOuter) << b;  // inflow
    EXPECT_EQ(KindAt(grid, kinds, b, 4, 0, 2), kWall) << b;
  }
}

TEST(WallBaseTest, InletOfAVolumeChannelStaysOuter) {
  const std::vector<double> t = GeometricSpacing(kNj, 1e-3, 2.0);
  std::vector<double> y = t;
  for (int j = static_cast<int>(t.size()) - 2; j >= 0; --j) y.push_back(2.0 * t.back() - t[j]);
  MultiBlockGrid channel;
  channel.blocks.push_back(PlanarBlock(kNi, static_cast<int>(y.size()), [&](int i, int j) {
    return std::array{i / (kNi - 1.0), y[j]};
  }));
  const BoundaryKinds inlet = Classify(Extruded(channel, 4), 0);
  EXPECT_THAT(inlet.face_kinds[0],
              ElementsAre(BoundaryKind::kOuter, BoundaryKind::kOuter, BoundaryKind::kWall,
                          BoundaryKind::kWall, BoundaryKind::kOuter, BoundaryKind::kOuter));
}

}  // namespace
}  // namespace splinegrid
