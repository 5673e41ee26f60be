// Writing evaluations back as their Plot3D source: TwoPlaneBlock (the inverse of the planar
// view, on the real CFL3D two-plane file), ToPlot3dSourceForm and function files.
#include <cstring>
#include <string>
#include <vector>

#include "core/io/planar_view.h"
#include "core/io/plot3d.h"
#include "core/io/plot3d_function.h"
#include "core/io/plot3d_source_format.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io_test_util.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

TEST(TwoPlaneBlockTest, RestoresTheSharedCfl3dFileFromItsPlanarView) {
  absl::StatusOr<MultiBlockGrid> file = ReadPlot3dFile(SharedDataPath("grids/rae2822_257x97.fmt"));
  ASSERT_TRUE(file.ok()) << file.status();
  std::vector<TwoPlaneLayout> layouts;
  absl::StatusOr<MultiBlockGrid> planar = PlanarView(*file, {}, &layouts);
  ASSERT_TRUE(planar.ok()) << planar.status();
  ASSERT_EQ(layouts.size(), 1u);
  EXPECT_EQ(layouts[0].plane_direction, 0);
  EXPECT_EQ(layouts[0].normal_coordinate, 1);
  EXPECT_EQ(layouts[0].plane_values[0], 0.0);
  EXPECT_EQ(layouts[0].plane_values[1], -1.0);
  absl::StatusOr<StructuredBlock> restored = TwoPlaneBlock(planar->blocks[0], layouts[0]);
  ASSERT_TRUE(restored.ok()) << restored.status();
  MultiBlockGrid again;
  again.blocks.push_back(*std::move(restored));
  ExpectBitIdentical(*file, again);
}

TEST(TwoPlaneBlockTest, RefusesWhatItCannotRestore) {
  const StructuredBlock volume = MakeSimpleGrid(3, {{3, 2, 2}}).blocks[0];
  EXPECT_THAT(MessageOf(TwoPlaneBlock(volume, TwoPlaneLayout{}).status()),
              HasSubstr("must be 2D with nk = 1"));
  const StructuredBlock planar = MakeSimpleGrid(2, {{3, 2, 1}}).blocks[0];
  EXPECT_THAT(MessageOf(TwoPlaneBlock(planar, TwoPlaneLayout{3, 1, {0, 1}}).status()),
              HasSubstr("must be from 0 to 2"));
}

TEST(ToPlot3dSourceFormTest, KeepsTheSourceLayoutAndRestoresTwoPlanes) {
  Plot3dSourceFormat source;
  source.file = Plot3dFormat{Plot3dEncoding::kBinaryBigEndian, 3, false, true, 4};
  source.file.framing = Plot3dFraming::kCStream;
  source.two_planes = {TwoPlaneLayout{2, 2, {0.5, 1.5}}};
  const MultiBlockGrid evaluated = MakeSimpleGrid(2, {{5, 4, 1}});
  const std::vector<int> indices = {0};
  absl::StatusOr<Plot3dWriteBack> binary =
      ToPlot3dSourceForm(evaluated, indices, source, Plot3dEncoding::kBinaryLittleEndian);
  ASSERT_TRUE(binary.ok()) << binary.status();
  // Binary stays the source's binary: big-endian single-precision C stream with iblank.
  EXPECT_EQ(DescribePlot3dFormat(binary->format),
            "binary big-endian C-stream single precision 3D, no block-count line, iblank");
  const StructuredBlock& block = binary->grid.blocks[0];
  ASSERT_EQ(block.extents(), (Extents{5, 4, 2}));
  EXPECT_EQ(block.Point(3, 2, 1)[2], 1.5);
  EXPECT_EQ(block.Point(3, 2, 0)[0], evaluated.blocks[0].Point(3, 2, 0)[0]);
  EXPECT_EQ(block.iblank(), std::vector<int>(40, 1));  // every evaluated point is a field point
  // The bytes parse back to the same grid and format.
  absl::StatusOr<std::string> bytes = EncodePlot3d(binary->grid, binary->format);
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  Plot3dFormat detected;
  absl::StatusOr<MultiBlockGrid> read = ParsePlot3d(*bytes, "back.x", &detected);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(DescribePlot3dFormat(detected), DescribePlot3dFormat(binary->format));
  ExpectBitIdentical(binary->grid, *read);
  // Text asked of a binary source: text with the same layout.
  absl::StatusOr<Plot3dWriteBack> text =
      ToPlot3dSourceForm(evaluated, indices, source, Plot3dEncoding::kAscii);
  ASSERT_TRUE(text.ok());
  EXPECT_EQ(DescribePlot3dFormat(text->format), "ASCII 3D, no block-count line, iblank");
  // A block index the source does not have.
  const std::vector<int> wrong = {1};
  EXPECT_THAT(
      MessageOf(ToPlot3dSourceForm(evaluated, wrong, source, Plot3dEncoding::kAscii).status()),
      HasSubstr("block 1 is not a block of the source (1 blocks)"));
  // A 3D source cannot take 2D blocks without two planes.
  source.two_planes.clear();
  EXPECT_THAT(
      MessageOf(ToPlot3dSourceForm(evaluated, indices, source, Plot3dEncoding::kAscii).status()),
      HasSubstr("it has 2 coordinates per point, the source file 3"));
}

TEST(Plot3dFunctionTest, WritesFortranRecordsAndText) {
  Plot3dFunctionBlock block;
  block.extents = {2, 1, 3};
  block.num_functions = 2;
  for (int p = 0; p < 6; ++p) {
    block.values.push_back(p);         // function 0
    block.values.push_back(10.0 + p);  // function 1
  }
  const std::vector<Plot3dFunctionBlock> blocks = {block};
  Plot3dFormat format{Plot3dEncoding::kBinaryLittleEndian, 3, true, false, 8};
  absl::StatusOr<std::string> bytes = EncodePlot3dFunction(blocks, format);
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  ASSERT_EQ(bytes->size(), 12u + 24u + 8u + 12 * 8u);
  int32_t header[9];
  std::memcpy(header, bytes->data(), sizeof(header));
  EXPECT_EQ(std::vector<int32_t>(header, header + 9),
            (std::vector<int32_t>{4, 1, 4, 16, 2, 1, 3, 2, 16}));
  double values[12];
  std::memcpy(values, bytes->data() + 40, sizeof(values));
  EXPECT_EQ(values[0], 0.0);
  EXPECT_EQ(values[5], 5.0);
  EXPECT_EQ(values[6], 10.0);  // function 1 after all of function 0
  // Planes layout in a C stream: per k-plane both functions.
  format.framing = Plot3dFraming::kCStream;
  format.layout = Plot3dLayout::kPlanes;
  bytes = EncodePlot3dFunction(blocks, format);
  ASSERT_TRUE(bytes.ok());
  ASSERT_EQ(bytes->size(), 4u + 16u + 12 * 8u);
  std::memcpy(values, bytes->data() + 20, sizeof(values));
  EXPECT_EQ((std::vector<double>(values, values + 6)), (std::vector<double>{0, 1, 10, 11, 2, 3}));
  // Text, 2D.
  Plot3dFunctionBlock flat = block;
  flat.extents = {3, 2, 1};
  const std::vector<Plot3dFunctionBlock> flat_blocks = {flat};
  absl::StatusOr<std::string> text =
      EncodePlot3dFunction(flat_blocks, Plot3dFormat{Plot3dEncoding::kAscii, 2, true, false, 8});
  ASSERT_TRUE(text.ok());
  EXPECT_EQ(text->substr(0, 10), "1\n3 2 2\n0 ");
  // Errors.
  flat.values.pop_back();
  const std::vector<Plot3dFunctionBlock> short_blocks = {flat};
  EXPECT_THAT(MessageOf(EncodePlot3dFunction(short_blocks, format).status()),
              HasSubstr("has 11 values; its points x functions need 12"));
  EXPECT_THAT(MessageOf(EncodePlot3dFunction({}, format).status()), HasSubstr("no blocks"));
  Plot3dFunctionBlock huge = block;
  huge.values[3] = 1e300;
  const std::vector<Plot3dFunctionBlock> huge_blocks = {huge};
  format.bytes_per_real = 4;
  EXPECT_THAT(MessageOf(EncodePlot3dFunction(huge_blocks, format).status()),
              HasSubstr("not finite in single precision"));
}

}  // namespace
}  // namespace splinegrid
