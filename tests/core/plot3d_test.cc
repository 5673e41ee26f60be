// Plot3D reading of the shared grids, layout detection, and bit-exact round trips.
#include "core/io/plot3d.h"

#include <cstdlib>
#include <filesystem>
#include <ostream>
#include <string>
#include <tuple>

#include "absl/strings/str_cat.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io_test_util.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

// Relative tolerance for values parsed from decimal text against hand-copied decimals.
constexpr double kDecimalTolerance = 1e-15;

// Reads shared file `relative`, failing the test on error.
MultiBlockGrid ReadShared(const std::string& relative, Plot3dFormat* format = nullptr) {
  absl::StatusOr<MultiBlockGrid> grid = ReadPlot3dFile(SharedDataPath(relative), format);
  EXPECT_TRUE(grid.ok()) << grid.status();
  return grid.ok() ? *std::move(grid) : MultiBlockGrid{};
}

// Coordinate `s` of point (i, j, k) of block `b`.
double Coord(const MultiBlockGrid& grid, int b, int i, int j, int k, int s) {
  return grid.blocks[b].Point(i, j, k)[s];
}

TEST(Plot3dSharedDataTest, DirectoryExists) {
  const std::string root = SharedDataPath("");
  ASSERT_TRUE(std::filesystem::is_directory(root))
      << "shared test data not found at '" << root
      << "'; set SPLINEGRID_SHARED_DATA to the shared/data directory";
  EXPECT_TRUE(std::filesystem::is_regular_file(SharedDataPath("grids/rae2822_257x97.fmt")));
}

TEST(Plot3dSharedDataTest, EnvironmentVariableOverridesTheRoot) {
  const char* old = std::getenv("SPLINEGRID_SHARED_DATA");
  const std::string saved = old != nullptr ? old : "";
  setenv("SPLINEGRID_SHARED_DATA", "/somewhere/data", 1);
  EXPECT_EQ(SharedDataPath("grids/a.fmt"), "/somewhere/data/grids/a.fmt");
  if (old != nullptr) {
    setenv("SPLINEGRID_SHARED_DATA", saved.c_str(), 1);
  } else {
    unsetenv("SPLINEGRID_SHARED_DATA");
  }
  EXPECT_NE(SharedDataPath("x"), "/somewhere/data/x");
}

// A shared grid file and what it must contain.
struct SharedGridCase {
  std::string file;       // relative to the shared data directory
  int num_blocks;         // blocks in the file
  int spatial_dim;        // 2 or 3
  Extents first_extents;  // extents of block 0
  int64_t total_points;   // over all blocks
};

// Prints the file name of a SharedGridCase in test output.
void PrintTo(const SharedGridCase& c, std::ostream* os) { *os << c.file; }

class Plot3dSharedGridTest : public testing::TestWithParam<SharedGridCase> {};

// Test name of a SharedGridCase: the file's stem with '-' as '_'.
std::string SharedGridCaseName(const testing::TestParamInfo<SharedGridCase>& info) {
  std::string name = std::filesystem::path(info.param.file).stem().string();
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

TEST_P(Plot3dSharedGridTest, ReadsWithExactExtents) {
  const SharedGridCase& c = GetParam();
  Plot3dFormat format;
  const MultiBlockGrid grid = ReadShared(c.file, &format);
  ASSERT_EQ(grid.blocks.size(), c.num_blocks);
  EXPECT_EQ(grid.blocks[0].extents(), c.first_extents);
  int64_t points = 0;
  for (const StructuredBlock& block : grid.blocks) {
    EXPECT_EQ(block.spatial_dim(), c.spatial_dim);
    EXPECT_TRUE(block.iblank().empty());
    points += block.num_points();
  }
  EXPECT_EQ(points, c.total_points);
  EXPECT_EQ(format.encoding, Plot3dEncoding::kAscii);
  EXPECT_EQ(format.spatial_dim, c.spatial_dim);
  EXPECT_TRUE(format.has_block_count);
  EXPECT_FALSE(format.has_iblank);
}

TEST_P(Plot3dSharedGridTest, RoundTripsThroughEveryEncodingBitExactly) {
  const MultiBlockGrid grid = ReadShared(GetParam().file);
  for (Plot3dEncoding encoding : {Plot3dEncoding::kAscii, Plot3dEncoding::kBinaryLittleEndian,
                                  Plot3dEncoding::kBinaryBigEndian}) {
    const Plot3dFormat format = DefaultPlot3dFormat(grid, encoding);
    SCOPED_TRACE(DescribePlot3dFormat(format));
    absl::StatusOr<std::string> bytes = EncodePlot3d(grid, format);
    ASSERT_TRUE(bytes.ok()) << bytes.status();
    Plot3dFormat detected;
    absl::StatusOr<MultiBlockGrid> back = ParsePlot3d(*bytes, "round trip", &detected);
    ASSERT_TRUE(back.ok()) << back.status();
    ExpectBitIdentical(grid, *back);
    EXPECT_EQ(detected.encoding, encoding);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Plot3dSharedGrids, Plot3dSharedGridTest,
    testing::Values(SharedGridCase{"grids/n0012_113-33.p2dfmt", 1, 2, {113, 33, 1}, 113 * 33},
                    SharedGridCase{"grids/n0012_225-65.p2dfmt", 1, 2, {225, 65, 1}, 225 * 65},
                    SharedGridCase{"grids/rae2822_257x97.fmt", 1, 3, {2, 257, 97}, 2 * 257 * 97},
                    SharedGridCase{
                        "grids/n0012_pitch_257x129.fmt", 1, 3, {2, 257, 129}, 2 * 257 * 129},
                    SharedGridCase{"surfaces/m6_small.fmt", 9, 3, {65, 17, 1}, 16001},
                    SharedGridCase{"surfaces/even_sphere.fmt", 6, 3, {5, 5, 1}, 150},
                    SharedGridCase{"surfaces/ffd_box_6x2x6.fmt", 1, 3, {6, 2, 6}, 72}),
    SharedGridCaseName);

TEST(Plot3dSharedDataTest, NacaCGridMatchesHandReadValues) {
  const MultiBlockGrid grid = ReadShared("grids/n0012_113-33.p2dfmt");
  ASSERT_EQ(grid.blocks.size(), 1);
  EXPECT_NEAR(Coord(grid, 0, 0, 0, 0, 0), 501.000007802345, 501 * kDecimalTolerance);
  EXPECT_NEAR(Coord(grid, 0, 1, 0, 0, 0), 327.869339790829, 328 * kDecimalTolerance);
  EXPECT_NEAR(Coord(grid, 0, 56, 16, 0, 0), -0.250314401395105, kDecimalTolerance);
  EXPECT_NEAR(Coord(grid, 0, 112, 32, 0, 0), 501.000007802345, 501 * kDecimalTolerance);
  EXPECT_NEAR(Coord(grid, 0, 0, 0, 0, 1), 5.3522026295e-08, 1e-8 * kDecimalTolerance);
  EXPECT_NEAR(Coord(grid, 0, 112, 32, 0, 1), 493.522687677627, 494 * kDecimalTolerance);
}

TEST(Plot3dSharedDataTest, Cfl3dGridsWithRepeatCountsMatchHandReadValues) {
  const MultiBlockGrid rae = ReadShared("grids/rae2822_257x97.fmt");
  ASSERT_EQ(rae.blocks.size(), 1);
  // "2*20.,  2*17.33634, ...": x of both planes (i = 0, 1), then j = 1.
  EXPECT_EQ(Coord(rae, 0, 0, 0, 0, 0), 20.0);
  EXPECT_EQ(Coord(rae, 0, 1, 0, 0, 0), 20.0);
  EXPECT_EQ(Coord(rae, 0, 0, 1, 0, 0), 17.33634);
  EXPECT_EQ(Coord(rae, 0, 0, 5, 40, 1), 0.0);   // y is 0 on plane i = 0 ...
  EXPECT_EQ(Coord(rae, 0, 1, 5, 40, 1), -1.0);  // ... and -1 on plane i = 1
  EXPECT_EQ(Coord(rae, 0, 0, 0, 0, 2), 0.01443046);
  EXPECT_EQ(Coord(rae, 0, 1, 256, 96, 2), 19.999939999999999);  // last value of the file

  const MultiBlockGrid pitch = ReadShared("grids/n0012_pitch_257x129.fmt");
  ASSERT_EQ(pitch.blocks.size(), 1);
  EXPECT_EQ(Coord(pitch, 0, 0, 0, 0, 0), 51.0);
  EXPECT_EQ(Coord(pitch, 0, 1, 1, 0, 0), 42.110259999999997);
  EXPECT_EQ(Coord(pitch, 0, 1, 256, 128, 2), 49.356070000000003);
}

TEST(Plot3dSharedDataTest, SurfaceGridsMatchHandReadValues) {
  const MultiBlockGrid m6 = ReadShared("surfaces/m6_small.fmt");
  ASSERT_EQ(m6.blocks.size(), 9);
  const Extents expected[9] = {{65, 17, 1}, {73, 65, 1}, {17, 65, 1}, {65, 73, 1}, {73, 17, 1},
                               {17, 73, 1}, {17, 17, 1}, {17, 17, 1}, {73, 17, 1}};
  for (int b = 0; b < 9; ++b) EXPECT_EQ(m6.blocks[b].extents(), expected[b]) << "block " << b;
  EXPECT_EQ(Coord(m6, 0, 0, 0, 0, 0), 4.9504432827234268E-003);
  EXPECT_EQ(Coord(m6, 0, 1, 0, 0, 0), 9.9386250658026493E-003);
  EXPECT_EQ(Coord(m6, 8, 72, 16, 0, 2), 1.170026886614441);

  const MultiBlockGrid sphere = ReadShared("surfaces/even_sphere.fmt");
  ASSERT_EQ(sphere.blocks.size(), 6);
  for (const StructuredBlock& block : sphere.blocks) EXPECT_EQ(block.extents(), Extents({5, 5, 1}));
  EXPECT_EQ(Coord(sphere, 0, 0, 0, 0, 0), -0.5741094689950418);
  EXPECT_EQ(Coord(sphere, 5, 4, 4, 0, 2), 0.5837754790950025);

  const MultiBlockGrid ffd = ReadShared("surfaces/ffd_box_6x2x6.fmt");
  ASSERT_EQ(ffd.blocks.size(), 1);
  EXPECT_EQ(Coord(ffd, 0, 0, 0, 0, 0), -1.1766643020000001E-002);
  EXPECT_EQ(Coord(ffd, 0, 5, 1, 5, 2), 14.05358864);
}

// Round trip parameters: encoding, spatial_dim, number of blocks, block count, iblank.
using RoundTripCase = std::tuple<Plot3dEncoding, int, int, bool, bool>;

class Plot3dRoundTripTest : public testing::TestWithParam<RoundTripCase> {};

TEST_P(Plot3dRoundTripTest, IsBitExactAndDetectsTheLayout) {
  const auto [encoding, dim, num_blocks, block_count, iblank] = GetParam();
  const MultiBlockGrid grid = MakeAwkwardGrid(dim, num_blocks, iblank);
  const Plot3dFormat format{encoding, dim, block_count, iblank, 8};
  absl::StatusOr<std::string> bytes = EncodePlot3d(grid, format);
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  Plot3dFormat detected;
  absl::StatusOr<MultiBlockGrid> back = ParsePlot3d(*bytes, "round trip", &detected);
  ASSERT_TRUE(back.ok()) << back.status();
  ExpectBitIdentical(grid, *back);
  EXPECT_EQ(detected.encoding, encoding);
  EXPECT_EQ(detected.spatial_dim, dim);
  EXPECT_EQ(detected.has_block_count, block_count);
  EXPECT_EQ(detected.has_iblank, iblank);
  EXPECT_EQ(detected.bytes_per_real, 8);
}

// Every layout; a file without block count holds a single block.
std::vector<RoundTripCase> AllRoundTripCases() {
  std::vector<RoundTripCase> cases;
  for (Plot3dEncoding encoding : {Plot3dEncoding::kAscii, Plot3dEncoding::kBinaryLittleEndian,
                                  Plot3dEncoding::kBinaryBigEndian}) {
    for (int dim : {2, 3}) {
      for (int num_blocks : {1, 3}) {
        for (bool block_count : {true, false}) {
          for (bool iblank : {false, true}) {
            if (num_blocks == 1 || block_count) {
              cases.emplace_back(encoding, dim, num_blocks, block_count, iblank);
            }
          }
        }
      }
    }
  }
  return cases;
}

// Test name of a RoundTripCase, e.g. BinaryLE_3D_1Blocks_Count_Iblank.
std::string RoundTripCaseName(const testing::TestParamInfo<RoundTripCase>& info) {
  const auto [encoding, dim, num_blocks, block_count, iblank] = info.param;
  const char* names[] = {"Ascii", "BinaryLE", "BinaryBE"};
  return absl::StrCat(names[static_cast<int>(encoding)], "_", dim, "D_", num_blocks, "Blocks",
                      block_count ? "_Count" : "_NoCount", iblank ? "_Iblank" : "_NoIblank");
}

INSTANTIATE_TEST_SUITE_P(Plot3dAllLayouts, Plot3dRoundTripTest,
                         testing::ValuesIn(AllRoundTripCases()), RoundTripCaseName);

TEST(Plot3dBinaryTest, DetectsSingleAndDoublePrecision) {
  const MultiBlockGrid grid = MakeSimpleGrid(3, {{4, 3, 2}, {2, 2, 2}}, /*with_iblank=*/true);
  for (Plot3dEncoding encoding :
       {Plot3dEncoding::kBinaryLittleEndian, Plot3dEncoding::kBinaryBigEndian}) {
    for (int bytes_per_real : {4, 8}) {
      for (bool iblank : {false, true}) {
        const Plot3dFormat format{encoding, 3, true, iblank, bytes_per_real};
        SCOPED_TRACE(DescribePlot3dFormat(format));
        absl::StatusOr<std::string> bytes = EncodePlot3d(grid, format);
        ASSERT_TRUE(bytes.ok()) << bytes.status();
        // count + dims records, then 24 + 8 points of 3 reals (+ iblank).
        EXPECT_EQ(bytes->size(), 12 + (8 + 24) + 2 * 8 + 32 * (3 * bytes_per_real + 4 * iblank));
        Plot3dFormat detected;
        absl::StatusOr<MultiBlockGrid> back = ParsePlot3d(*bytes, "precision", &detected);
        ASSERT_TRUE(back.ok()) << back.status();
        EXPECT_EQ(detected.bytes_per_real, bytes_per_real);
        EXPECT_EQ(detected.has_iblank, iblank);
        EXPECT_EQ(detected.encoding, encoding);
        // The simple grid's values are exact in single precision.
        MultiBlockGrid expected = grid;
        if (!iblank) {
          for (StructuredBlock& block : expected.blocks) block.iblank().clear();
        }
        ExpectBitIdentical(expected, *back);
      }
    }
  }
}

TEST(Plot3dBinaryTest, SinglePrecisionRoundsToFloat) {
  MultiBlockGrid grid = MakeSimpleGrid(2, {{3, 2, 1}});
  grid.blocks[0].coords()[1] = 0.1;
  const Plot3dFormat format{Plot3dEncoding::kBinaryBigEndian, 2, false, false, 4};
  absl::StatusOr<std::string> bytes = EncodePlot3d(grid, format);
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  absl::StatusOr<MultiBlockGrid> back = ParsePlot3d(*bytes, "float");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->blocks[0].coords()[1], static_cast<double>(0.1f));
}

TEST(Plot3dTextTest, ReadsFortranListSyntax) {
  // Commas, repeat counts, D and d exponents, an exponent without letter, a leading '+'.
  const std::string text =
      "1\n 2, 2, 1\n"
      " 2*1.0D0, 3.0d-1,4E0\n"
      "  1.5-1 +2.  .5 3\n"
      " 4*0.\n";
  Plot3dFormat detected;
  absl::StatusOr<MultiBlockGrid> grid = ParsePlot3d(text, "syntax", &detected);
  ASSERT_TRUE(grid.ok()) << grid.status();
  ASSERT_EQ(grid->blocks.size(), 1);
  const StructuredBlock& block = grid->blocks[0];
  EXPECT_EQ(block.extents(), Extents({2, 2, 1}));
  const double x[] = {1.0, 1.0, 0.3, 4.0};
  const double y[] = {0.15, 2.0, 0.5, 3.0};
  for (int p = 0; p < 4; ++p) {
    EXPECT_EQ(block.coords()[3 * p], x[p]) << p;
    EXPECT_EQ(block.coords()[3 * p + 1], y[p]) << p;
    EXPECT_EQ(block.coords()[3 * p + 2], 0.0) << p;
  }
  EXPECT_TRUE(detected.has_block_count);
  EXPECT_EQ(detected.spatial_dim, 3);
}

TEST(Plot3dTextTest, ReadsTwoDimensionalFileWithoutBlockCountWithIblank) {
  const std::string text = "3 2\n0 1 2 0 1 2\n0. 0. 0. 1. 1. 1.\n1 1 0 1 -2 1\n";
  Plot3dFormat detected;
  absl::StatusOr<MultiBlockGrid> grid = ParsePlot3d(text, "2d", &detected);
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_EQ(DescribePlot3dFormat(detected), "ASCII 2D, no block-count line, iblank");
  EXPECT_EQ(grid->blocks[0].extents(), Extents({3, 2, 1}));
  EXPECT_EQ(grid->blocks[0].iblank(), std::vector<int>({1, 1, 0, 1, -2, 1}));
  EXPECT_EQ(grid->blocks[0].Point(2, 1, 0)[0], 2.0);
  EXPECT_EQ(grid->blocks[0].Point(2, 1, 0)[1], 1.0);
}

TEST(Plot3dTextTest, HeaderMustEndAtALineBreakUnlessTheFileIsOneLine) {
  const std::string one_line = "1 2 1 1 0.5 1.5 2.5 3.5 4.5 5.5\n";
  Plot3dFormat detected;
  absl::StatusOr<MultiBlockGrid> grid = ParsePlot3d(one_line, "one line", &detected);
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_EQ(grid->blocks[0].extents(), Extents({2, 1, 1}));
  EXPECT_EQ(grid->blocks[0].Point(1, 0, 0)[2], 5.5);
  EXPECT_TRUE(detected.has_block_count);

  const absl::Status status = ParsePlot3d("1 2 1 1 0.5 1.5\n2.5 3.5 4.5 5.5\n", "wrapped").status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(MessageOf(status), HasSubstr("the header should end at a line break after the "
                                           "value at line 1, column 7"));
}

TEST(Plot3dTextTest, PrefersBlockCountWhenTwoLayoutsFit) {
  // Read with a block-count line: 1 block of 1 x 1 x 1, point (0.5, 0.25, 2). Read without: a
  // 1 x 1 x 1 block at (1, 0.5, 0.25) with iblank 2. The documented preference picks the first.
  const std::string text = "1\n1\n1\n1\n0.5\n0.25\n2.0\n";
  Plot3dFormat detected;
  absl::StatusOr<MultiBlockGrid> grid = ParsePlot3d(text, "ambiguous", &detected);
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_TRUE(detected.has_block_count);
  EXPECT_FALSE(detected.has_iblank);
  EXPECT_EQ(grid->blocks[0].coords()[2], 2.0);
}

TEST(Plot3dTextTest, WritesCountLineDimsAndShortestRoundTripNumbers) {
  MultiBlockGrid grid = MakeSimpleGrid(2, {{2, 1, 1}});
  grid.blocks[0].coords()[0] = 0.1;
  grid.blocks[0].coords()[2] = 3.0;
  absl::StatusOr<std::string> text =
      EncodePlot3d(grid, DefaultPlot3dFormat(grid, Plot3dEncoding::kAscii));
  ASSERT_TRUE(text.ok()) << text.status();
  EXPECT_EQ(*text, "1\n2 1\n0.1 3.0\n-0.5 -0.5\n");
}

TEST(Plot3dWriterTest, RejectsGridsTheFormatCannotHold) {
  const MultiBlockGrid two_d = MakeSimpleGrid(2, {{2, 2, 1}});
  Plot3dFormat format = DefaultPlot3dFormat(two_d, Plot3dEncoding::kAscii);
  format.spatial_dim = 3;
  EXPECT_EQ(EncodePlot3d(two_d, format).status().code(), absl::StatusCode::kInvalidArgument);

  MultiBlockGrid mixed = MakeSimpleGrid(3, {{2, 2, 2}});
  mixed.blocks.push_back(two_d.blocks[0]);
  absl::Status status =
      EncodePlot3d(mixed, DefaultPlot3dFormat(mixed, Plot3dEncoding::kAscii)).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(MessageOf(status), HasSubstr("block 1 has spatial_dim 2"));

  EXPECT_EQ(EncodePlot3d(MultiBlockGrid{}, Plot3dFormat{}).status().code(),
            absl::StatusCode::kInvalidArgument);

  const MultiBlockGrid two_blocks = MakeSimpleGrid(3, {{2, 2, 2}, {2, 2, 2}});
  format = DefaultPlot3dFormat(two_blocks, Plot3dEncoding::kBinaryLittleEndian);
  format.has_block_count = false;
  EXPECT_EQ(EncodePlot3d(two_blocks, format).status().code(), absl::StatusCode::kInvalidArgument);

  format = DefaultPlot3dFormat(two_blocks, Plot3dEncoding::kBinaryLittleEndian);
  format.has_iblank = true;  // the blocks have none
  status = EncodePlot3d(two_blocks, format).status();
  EXPECT_THAT(MessageOf(status), HasSubstr("iblank"));

  MultiBlockGrid with_nan = MakeSimpleGrid(3, {{2, 2, 2}});
  with_nan.blocks[0].coords()[4] = std::nan("");
  status = EncodePlot3d(with_nan, DefaultPlot3dFormat(with_nan, Plot3dEncoding::kAscii)).status();
  EXPECT_THAT(MessageOf(status), HasSubstr("must be finite"));

  MultiBlockGrid huge = MakeSimpleGrid(3, {{2, 2, 2}});
  huge.blocks[0].coords()[0] = 1e300;
  format = DefaultPlot3dFormat(huge, Plot3dEncoding::kBinaryLittleEndian);
  format.bytes_per_real = 4;
  status = EncodePlot3d(huge, format).status();
  EXPECT_THAT(MessageOf(status), HasSubstr("does not fit single precision"));
}

TEST(Plot3dFileTest, WritesAtomicallyAndReadsBack) {
  const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "plot3d_file_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "grid.xyz").string();
  const MultiBlockGrid grid = MakeAwkwardGrid(3, 2, true);
  for (Plot3dEncoding encoding : {Plot3dEncoding::kAscii, Plot3dEncoding::kBinaryBigEndian}) {
    ASSERT_TRUE(WritePlot3dFile(path, grid, DefaultPlot3dFormat(grid, encoding)).ok());
    Plot3dFormat detected;
    absl::StatusOr<MultiBlockGrid> back = ReadPlot3dFile(path, &detected);
    ASSERT_TRUE(back.ok()) << back.status();
    ExpectBitIdentical(grid, *back);
    EXPECT_EQ(detected.encoding, encoding);
  }
  // Only the file itself is left: the temporary files were renamed.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir),
                          std::filesystem::directory_iterator()),
            1);
  const absl::Status unwritable =
      WritePlot3dFile((dir / "grid.xyz" / "inside_a_file.xyz").string(), grid,
                      DefaultPlot3dFormat(grid, Plot3dEncoding::kAscii));
  EXPECT_FALSE(unwritable.ok());
  EXPECT_THAT(MessageOf(unwritable), HasSubstr("inside_a_file.xyz"));
}

TEST(Plot3dFileTest, MissingFileIsNotFound) {
  const absl::StatusOr<MultiBlockGrid> grid = ReadPlot3dFile("/nonexistent/dir/grid.fmt");
  EXPECT_EQ(grid.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(MessageOf(grid.status()), HasSubstr("/nonexistent/dir/grid.fmt"));
}

}  // namespace
}  // namespace splinegrid
