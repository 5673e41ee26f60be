// Plot3D C-stream binary files and the planes layout: files written by Debian's cgns_to_plot3d
// (the real tool), constructed variants of every byte order, precision, iblank, block count,
// dimension and layout, Fortran planes records, and malformed streams.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <limits>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/file_util.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io_test_util.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

constexpr char kSource[] = "stream.x";

std::string Encode(const MultiBlockGrid& grid, const Plot3dFormat& format) {
  absl::StatusOr<std::string> bytes = EncodePlot3d(grid, format);
  EXPECT_TRUE(bytes.ok()) << bytes.status();
  return bytes.ok() ? *bytes : std::string();
}

Plot3dFormat StreamFormat(Plot3dEncoding encoding, int dim, bool count, bool iblank, int real,
                          Plot3dLayout layout) {
  Plot3dFormat format{encoding, dim, count, iblank, real};
  format.framing = Plot3dFraming::kCStream;
  format.layout = layout;
  return format;
}

void ExpectSameFormat(const Plot3dFormat& expected, const Plot3dFormat& actual) {
  EXPECT_EQ(DescribePlot3dFormat(expected), DescribePlot3dFormat(actual));
  EXPECT_EQ(expected.encoding, actual.encoding);
  EXPECT_EQ(expected.framing, actual.framing);
  EXPECT_EQ(expected.bytes_per_real, actual.bytes_per_real);
  EXPECT_EQ(expected.has_iblank, actual.has_iblank);
  EXPECT_EQ(expected.has_block_count, actual.has_block_count);
  EXPECT_EQ(expected.spatial_dim, actual.spatial_dim);
  EXPECT_EQ(expected.layout, actual.layout);
}

// MakeAwkwardGrid without its subnormal values (a C stream with them is refused: see
// plot3d.h), so 0 in their place.
MultiBlockGrid StreamableAwkwardGrid(int dim, int num_blocks, bool iblank) {
  MultiBlockGrid grid = MakeAwkwardGrid(dim, num_blocks, iblank);
  for (StructuredBlock& block : grid.blocks) {
    for (double& c : block.coords()) {
      if (std::fpclassify(c) == FP_SUBNORMAL) c = 0.0;
    }
  }
  return grid;
}

// Every combination written as a C stream reads back bit-identical (double) with its format
// detected; the planes layout needs the read option (both layouts hold the same bytes count).
TEST(Plot3dStreamTest, EveryVariantRoundTrips) {
  for (Plot3dEncoding encoding :
       {Plot3dEncoding::kBinaryLittleEndian, Plot3dEncoding::kBinaryBigEndian}) {
    for (int dim : {2, 3}) {
      for (int real : {4, 8}) {
        for (bool count : {true, false}) {
          for (bool iblank : {false, true}) {
            for (Plot3dLayout layout : {Plot3dLayout::kWhole, Plot3dLayout::kPlanes}) {
              if (dim == 2 && layout == Plot3dLayout::kPlanes) continue;
              const Plot3dFormat format = StreamFormat(encoding, dim, count, iblank, real, layout);
              const int nk = dim == 3 ? 3 : 1;
              SCOPED_TRACE(DescribePlot3dFormat(format));
              // Single precision holds the simple grid's values exactly.
              const MultiBlockGrid grid =
                  real == 8 ? StreamableAwkwardGrid(dim, count ? 3 : 1, iblank)
                            : MakeSimpleGrid(dim,
                                             count ? std::vector<Extents>{{4, 3, nk}, {2, 2, 1}}
                                                   : std::vector<Extents>{{4, 3, nk}},
                                             iblank);
              const std::string bytes = Encode(grid, format);
              Plot3dReadOptions options;
              options.layout = layout;
              Plot3dFormat detected;
              absl::StatusOr<MultiBlockGrid> read = ParsePlot3d(bytes, kSource, options, &detected);
              ASSERT_TRUE(read.ok()) << read.status();
              ExpectBitIdentical(grid, *read);
              ExpectSameFormat(format, detected);
            }
          }
        }
      }
    }
  }
}

TEST(Plot3dStreamTest, PlanesDifferFromWholeAndAreReadWholeByDefault) {
  const MultiBlockGrid grid = MakeSimpleGrid(3, {{4, 3, 3}});
  const std::string planes = Encode(grid, StreamFormat(Plot3dEncoding::kBinaryLittleEndian, 3, true,
                                                       false, 8, Plot3dLayout::kPlanes));
  const std::string whole = Encode(grid, StreamFormat(Plot3dEncoding::kBinaryLittleEndian, 3, true,
                                                      false, 8, Plot3dLayout::kWhole));
  ASSERT_EQ(planes.size(), whole.size());
  EXPECT_NE(planes, whole);
  absl::StatusOr<MultiBlockGrid> as_whole = ParsePlot3d(planes, kSource);
  ASSERT_TRUE(as_whole.ok());
  EXPECT_NE(as_whole->blocks[0].coords()[1], grid.blocks[0].coords()[1]);  // y of point 0
}

// Fortran records show the planes layout: one record per k-plane.
TEST(Plot3dStreamTest, FortranPlanesRecordsAreDetected) {
  const MultiBlockGrid grid = MakeAwkwardGrid(3, 3, /*with_iblank=*/true);
  for (Plot3dEncoding encoding :
       {Plot3dEncoding::kBinaryLittleEndian, Plot3dEncoding::kBinaryBigEndian}) {
    Plot3dFormat format{encoding, 3, true, true, 8};
    format.layout = Plot3dLayout::kPlanes;
    const std::string bytes = Encode(grid, format);
    Plot3dFormat detected;
    absl::StatusOr<MultiBlockGrid> read = ParsePlot3d(bytes, kSource, &detected);
    ASSERT_TRUE(read.ok()) << read.status();
    ExpectBitIdentical(grid, *read);
    ExpectSameFormat(format, detected);
    // Asking for the whole layout contradicts the records.
    Plot3dReadOptions whole;
    whole.layout = Plot3dLayout::kWhole;
    absl::StatusOr<MultiBlockGrid> refused = ParsePlot3d(bytes, kSource, whole);
    ASSERT_FALSE(refused.ok());
    EXPECT_THAT(MessageOf(refused.status()), HasSubstr("the records hold the planes layout"));
  }
}

// For nk = 2 a whole single-precision block record and a double-precision k-plane record have
// the same length; the number of records decides.
TEST(Plot3dStreamTest, FortranNk2AmbiguityIsResolvedByTheRecordCount) {
  const MultiBlockGrid grid = MakeSimpleGrid(3, {{4, 3, 2}, {3, 3, 2}});
  for (const auto& [real, layout] :
       {std::pair{4, Plot3dLayout::kWhole}, std::pair{8, Plot3dLayout::kPlanes}}) {
    Plot3dFormat format{Plot3dEncoding::kBinaryLittleEndian, 3, true, false, real};
    format.layout = layout;
    SCOPED_TRACE(DescribePlot3dFormat(format));
    Plot3dFormat detected;
    absl::StatusOr<MultiBlockGrid> read = ParsePlot3d(Encode(grid, format), kSource, &detected);
    ASSERT_TRUE(read.ok()) << read.status();
    ExpectBitIdentical(grid, *read);
    ExpectSameFormat(format, detected);
  }
}

TEST(Plot3dStreamTest, TextPlanesLayoutReadsWithTheOption) {
  const MultiBlockGrid grid = MakeSimpleGrid(3, {{4, 3, 3}, {2, 2, 2}}, /*with_iblank=*/true);
  Plot3dFormat format{Plot3dEncoding::kAscii, 3, true, true, 8};
  format.layout = Plot3dLayout::kPlanes;
  const std::string text = Encode(grid, format);
  Plot3dReadOptions options;
  options.layout = Plot3dLayout::kPlanes;
  Plot3dFormat detected;
  absl::StatusOr<MultiBlockGrid> read = ParsePlot3d(text, kSource, options, &detected);
  ASSERT_TRUE(read.ok()) << read.status();
  ExpectBitIdentical(grid, *read);
  ExpectSameFormat(format, detected);
}

// A cut stream never reads as the file it was cut from: it fails with INVALID_ARGUMENT, or
// (the documented limitation of size-only detection, plot3d.h) its size matches another
// layout, e.g. a double-precision file cut to the size of the single-precision one.
TEST(Plot3dStreamTest, EveryCutOfAStreamFailsOrReadsAsAnotherLayout) {
  int other_layouts = 0, cuts = 0;
  for (int real : {4, 8}) {
    for (bool iblank : {false, true}) {
      const MultiBlockGrid grid = MakeSimpleGrid(3, {{3, 2, 2}, {2, 2, 1}}, iblank);
      const Plot3dFormat format = StreamFormat(Plot3dEncoding::kBinaryLittleEndian, 3, true, iblank,
                                               real, Plot3dLayout::kWhole);
      const std::string bytes = Encode(grid, format);
      for (size_t cut = 1; cut < bytes.size(); ++cut, ++cuts) {
        Plot3dFormat detected;
        absl::StatusOr<MultiBlockGrid> read = ParsePlot3d(bytes.substr(0, cut), kSource, &detected);
        if (read.ok()) {
          ++other_layouts;
          EXPECT_NE(DescribePlot3dFormat(detected), DescribePlot3dFormat(format))
              << "cut at " << cut << " of " << bytes.size();
        } else {
          EXPECT_EQ(read.status().code(), absl::StatusCode::kInvalidArgument)
              << "cut at " << cut << ": " << read.status();
        }
      }
    }
  }
  // The plausibility checks (no subnormal reals, iblank within block numbers) leave few.
  EXPECT_LE(other_layouts, cuts / 50) << other_layouts << " of " << cuts << " cuts";
}

TEST(Plot3dStreamTest, SizesThatDoNotAddUpSayWhatWasTried) {
  const MultiBlockGrid grid = MakeSimpleGrid(3, {{3, 2, 2}});
  const std::string bytes = Encode(grid, StreamFormat(Plot3dEncoding::kBinaryLittleEndian, 3, true,
                                                      false, 8, Plot3dLayout::kWhole));
  absl::StatusOr<MultiBlockGrid> read = ParsePlot3d(bytes + "xyz", kSource);
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(MessageOf(read.status()),
              HasSubstr("not a C-stream file: no combination of byte order, block count, 2D/3D, "
                        "single/double precision and iblank adds up to the file's 307 bytes; "
                        "closest: little-endian, block count, 3D (1 block(s): 3 x 2 x 2): 12 "
                        "points need 144 (single), 288 (double)"));
  EXPECT_THAT(MessageOf(read.status()), HasSubstr("the file has 291"));
}

TEST(Plot3dStreamTest, NonFiniteStreamValuesAreRejected) {
  MultiBlockGrid grid = MakeSimpleGrid(3, {{3, 2, 2}});
  std::string bytes = Encode(grid, StreamFormat(Plot3dEncoding::kBinaryLittleEndian, 3, true, false,
                                                8, Plot3dLayout::kWhole));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(bytes.data() + 16 + 8 * 13, &nan, 8);  // y of point 1
  absl::StatusOr<MultiBlockGrid> read = ParsePlot3d(bytes, kSource);
  ASSERT_FALSE(read.ok());
  EXPECT_THAT(MessageOf(read.status()),
              HasSubstr("block 0, y of point (1, 0, 0) at byte offset 120 (C stream): nan is "
                        "not finite"));
}

// ---- Files written by the real tools (Debian cgns-convert) ----

// Runs `command` through the shell; its exit status.
int RunShell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class CgnsToPlot3dTest : public testing::Test {
 protected:
  void SetUp() override {
    if (RunShell("command -v cgns_to_plot3d >/dev/null && command -v plot3d_to_cgns >/dev/null") !=
        0) {
      GTEST_FAIL() << "cgns_to_plot3d / plot3d_to_cgns missing: install cgns-convert "
                      "(.ci/setup)";
    }
    // A directory of its own: ctest runs the tests of this fixture as parallel processes.
    dir_ = std::filesystem::path(testing::TempDir()) /
           absl::StrCat("plot3d_stream_test_",
                        testing::UnitTest::GetInstance()->current_test_info()->name(), "_",
                        getpid());
    std::filesystem::create_directories(dir_);
    source_ = SharedDataPath("surfaces/ffd_box_6x2x6.fmt");
    absl::StatusOr<MultiBlockGrid> grid = ReadPlot3dFile(source_);
    ASSERT_TRUE(grid.ok()) << grid.status();
    grid_ = *std::move(grid);
    cgns_ = (dir_ / "ffd.cgns").string();
    ASSERT_EQ(RunShell(absl::StrCat("plot3d_to_cgns -f -d ", source_, " ", cgns_, " >/dev/null")),
              0);
  }

  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }

  // cgns_to_plot3d `options` of the CGNS file; the Plot3D file's path.
  std::string Convert(const std::string& options, const std::string& name) {
    const std::string path = (dir_ / name).string();
    EXPECT_EQ(
        RunShell(absl::StrCat("cgns_to_plot3d ", options, " ", cgns_, " ", path, " >/dev/null")),
        0);
    return path;
  }

  // Expects `read` to hold the shared grid within relative `tolerance` (single or double).
  void ExpectNear(const MultiBlockGrid& read, double tolerance) {
    ASSERT_EQ(read.blocks.size(), 1u);
    ASSERT_EQ(read.blocks[0].extents(), grid_.blocks[0].extents());
    for (size_t c = 0; c < grid_.blocks[0].coords().size(); ++c) {
      const double expected = grid_.blocks[0].coords()[c];
      ASSERT_NEAR(read.blocks[0].coords()[c], expected,
                  tolerance * std::max(1.0, std::abs(expected)))
          << "coordinate " << c;
    }
  }

  std::filesystem::path dir_;
  std::string source_, cgns_;
  MultiBlockGrid grid_;
};

TEST_F(CgnsToPlot3dTest, DefaultCStreamOutputIsDetected) {
  struct Case {
    std::string options;
    int bytes_per_real;
    bool block_count;
    double tolerance;
  };
  for (const Case& c : {Case{"", 4, true, 1e-6}, Case{"-d", 8, true, 1e-15},
                        Case{"-s", 4, false, 1e-6}, Case{"-s -d", 8, false, 1e-15}}) {
    SCOPED_TRACE(c.options);
    const std::string path = Convert(c.options, "ffd.x");
    Plot3dFormat detected;
    absl::StatusOr<MultiBlockGrid> read = ReadPlot3dFile(path, &detected);
    ASSERT_TRUE(read.ok()) << read.status();
    ExpectNear(*read, c.tolerance);
    EXPECT_EQ(detected.framing, Plot3dFraming::kCStream);
    EXPECT_EQ(detected.encoding, Plot3dEncoding::kBinaryLittleEndian);
    EXPECT_EQ(detected.bytes_per_real, c.bytes_per_real);
    EXPECT_EQ(detected.has_block_count, c.block_count);
    EXPECT_EQ(detected.spatial_dim, 3);
  }
}

TEST_F(CgnsToPlot3dTest, PlanarOutputInEveryEncoding) {
  // Fortran records: the planes layout is detected.
  Plot3dFormat detected;
  absl::StatusOr<MultiBlockGrid> fortran = ReadPlot3dFile(Convert("-u -p -d", "up.x"), &detected);
  ASSERT_TRUE(fortran.ok()) << fortran.status();
  ExpectNear(*fortran, 1e-15);
  EXPECT_EQ(detected.framing, Plot3dFraming::kFortranRecords);
  EXPECT_EQ(detected.layout, Plot3dLayout::kPlanes);
  // C stream and text: selected.
  Plot3dReadOptions planes;
  planes.layout = Plot3dLayout::kPlanes;
  // cgns_to_plot3d -f prints 6 significant digits.
  for (const auto& [options, tolerance] :
       {std::pair{std::string("-p"), 1e-6}, std::pair{std::string("-p -d"), 1e-15},
        std::pair{std::string("-f -p"), 1e-5}}) {
    SCOPED_TRACE(options);
    absl::StatusOr<MultiBlockGrid> read =
        ReadPlot3dFile(Convert(options, "p.x"), planes, &detected);
    ASSERT_TRUE(read.ok()) << read.status();
    ExpectNear(*read, tolerance);
    EXPECT_EQ(detected.layout, Plot3dLayout::kPlanes);
  }
}

}  // namespace
}  // namespace splinegrid
