// The 2D view of two-plane (CFL3D-style) grids.
#include <ostream>
#include <string>

#include "core/io/planar_view.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io_test_util.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

// Reads shared file `relative`, failing the test on error.
MultiBlockGrid ReadShared(const std::string& relative) {
  absl::StatusOr<MultiBlockGrid> grid = ReadPlot3dFile(SharedDataPath(relative));
  EXPECT_TRUE(grid.ok()) << grid.status();
  return grid.ok() ? *std::move(grid) : MultiBlockGrid{};
}

// A two-plane CFL3D grid file and the 2D extents of its planar view.
struct TwoPlaneCase {
  std::string file;  // relative to the shared data directory
  Extents planar;    // extents of the planar view
};

// Prints the file name of a TwoPlaneCase in test output.
void PrintTo(const TwoPlaneCase& c, std::ostream* os) { *os << c.file; }

class Plot3dPlanarViewTest : public testing::TestWithParam<TwoPlaneCase> {};

// Test name of a TwoPlaneCase.
std::string TwoPlaneCaseName(const testing::TestParamInfo<TwoPlaneCase>& info) {
  return info.index == 0 ? "Rae2822" : "Naca0012Pitch";
}

TEST_P(Plot3dPlanarViewTest, ReducesCfl3dGridToItsPlane) {
  const MultiBlockGrid grid = ReadShared(GetParam().file);
  ASSERT_EQ(grid.blocks.size(), 1);
  EXPECT_TRUE(IsTwoPlaneGrid(grid));
  absl::StatusOr<TwoPlaneLayout> layout = DetectTwoPlaneBlock(grid.blocks[0]);
  ASSERT_TRUE(layout.ok()) << layout.status();
  EXPECT_EQ(layout->plane_direction, 0);    // ni = 2
  EXPECT_EQ(layout->normal_coordinate, 1);  // y = 0 and y = -1
  EXPECT_EQ(layout->plane_values[0], 0.0);
  EXPECT_EQ(layout->plane_values[1], -1.0);

  absl::StatusOr<MultiBlockGrid> planar = PlanarView(grid);
  ASSERT_TRUE(planar.ok()) << planar.status();
  ASSERT_EQ(planar->blocks.size(), 1);
  const StructuredBlock& block = planar->blocks[0];
  EXPECT_EQ(block.spatial_dim(), 2);
  EXPECT_EQ(block.extents(), GetParam().planar);
  for (int k = 0; k < grid.blocks[0].extent(2); ++k) {
    for (int j = 0; j < grid.blocks[0].extent(1); ++j) {
      const double* from = grid.blocks[0].Point(0, j, k);
      const double* to = block.Point(j, k, 0);
      ASSERT_EQ(to[0], from[0]) << j << ", " << k;  // x
      ASSERT_EQ(to[1], from[2]) << j << ", " << k;  // z
    }
  }
  // AsPlanarGrid gives the same for two-plane grids.
  absl::StatusOr<MultiBlockGrid> as_planar = AsPlanarGrid(grid);
  ASSERT_TRUE(as_planar.ok()) << as_planar.status();
  ExpectBitIdentical(*planar, *as_planar);
}

INSTANTIATE_TEST_SUITE_P(Plot3dCfl3dGrids, Plot3dPlanarViewTest,
                         testing::Values(TwoPlaneCase{"grids/rae2822_257x97.fmt", {257, 97, 1}},
                                         TwoPlaneCase{"grids/n0012_pitch_257x129.fmt",
                                                      {257, 129, 1}}),
                         TwoPlaneCaseName);

TEST(Plot3dPlanarViewErrorTest, RejectsBlocksWithoutTwoPlanes) {
  // m6: surfaces, no direction of extent 2.
  const MultiBlockGrid m6 = ReadShared("surfaces/m6_small.fmt");
  EXPECT_FALSE(IsTwoPlaneGrid(m6));
  absl::Status status = PlanarView(m6).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(MessageOf(status), HasSubstr("block 0: not a two-plane block: no index direction"));

  // The FFD box has nj = 2, but y varies on each of its planes.
  const MultiBlockGrid ffd = ReadShared("surfaces/ffd_box_6x2x6.fmt");
  EXPECT_FALSE(IsTwoPlaneGrid(ffd));
  status = PlanarView(ffd).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(MessageOf(status), HasSubstr("y is not constant on plane j = 0"));

  // A 2D grid is not a two-plane grid; AsPlanarGrid passes it through unchanged.
  const MultiBlockGrid naca = ReadShared("grids/n0012_113-33.p2dfmt");
  EXPECT_FALSE(IsTwoPlaneGrid(naca));
  EXPECT_THAT(MessageOf(PlanarView(naca).status()), HasSubstr("spatial_dim 2"));
  absl::StatusOr<MultiBlockGrid> same = AsPlanarGrid(naca);
  ASSERT_TRUE(same.ok()) << same.status();
  ExpectBitIdentical(naca, *same);

  EXPECT_FALSE(IsTwoPlaneGrid(MultiBlockGrid{}));
}

TEST(Plot3dPlanarViewErrorTest, NamesThePointWhereThePlanesDiffer) {
  MultiBlockGrid grid = ReadShared("grids/rae2822_257x97.fmt");
  ASSERT_EQ(grid.blocks.size(), 1);
  // Tolerance: 1e-8 x bounding-box diagonal (~57 chords for this grid), about 6e-7.
  grid.blocks[0].Point(1, 10, 20)[0] += 1e-9;  // x of plane i = 1: within tolerance
  EXPECT_TRUE(IsTwoPlaneGrid(grid));
  grid.blocks[0].Point(1, 10, 20)[0] += 1e-3;  // now beyond it
  EXPECT_FALSE(IsTwoPlaneGrid(grid));
  absl::Status status = PlanarView(grid).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(MessageOf(status),
              HasSubstr("block 0: not a two-plane block: planes i = 0 and i = 1 differ in x by"));
  EXPECT_THAT(MessageOf(status), HasSubstr("at (j, k) = (10, 20)"));

  grid = ReadShared("grids/rae2822_257x97.fmt");
  grid.blocks[0].Point(0, 3, 4)[1] = 0.5;  // y no longer constant on plane i = 0
  status = PlanarView(grid).status();
  EXPECT_THAT(MessageOf(status), HasSubstr("y is not constant on plane i = 0"));
  EXPECT_THAT(MessageOf(status), HasSubstr("(j, k) = (3, 4)"));
}

TEST(Plot3dPlanarViewSyntheticTest, KeepsInPlaneCoordinatesAndIblankForOtherNormals) {
  // A 3 x 4 x 2 block: planes k = 0 and k = 1 at z = 5 and z = 7; in-plane (x, y).
  StructuredBlock block({3, 4, 2}, 3);
  for (int k = 0; k < 2; ++k) {
    for (int j = 0; j < 4; ++j) {
      for (int i = 0; i < 3; ++i) {
        double* p = block.Point(i, j, k);
        p[0] = i + 0.1 * j;
        p[1] = j * j;
        p[2] = k == 0 ? 5.0 : 7.0;
        block.iblank().push_back(i + 10 * j + 100 * k);
      }
    }
  }
  MultiBlockGrid grid;
  grid.blocks.push_back(block);
  absl::StatusOr<MultiBlockGrid> planar = PlanarView(grid);
  ASSERT_TRUE(planar.ok()) << planar.status();
  const StructuredBlock& view = planar->blocks[0];
  EXPECT_EQ(view.extents(), Extents({3, 4, 1}));
  EXPECT_EQ(view.Point(2, 3, 0)[0], 2.0 + 0.1 * 3);
  EXPECT_EQ(view.Point(2, 3, 0)[1], 9.0);
  EXPECT_EQ(view.iblank()[view.Index(2, 3, 0)], 32);
}

}  // namespace
}  // namespace splinegrid
