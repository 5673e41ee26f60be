// Malformed Plot3D input: every problem is an INVALID_ARGUMENT naming source, block and position.
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "core/io/file_util.h"
#include "core/io/plot3d.h"
#include "core/io/plot3d_internal.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io_test_util.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

constexpr char kSource[] = "bad.fmt";

// Parses `bytes` expecting INVALID_ARGUMENT with a message that names kSource; the message.
std::string ParseError(std::string_view bytes) {
  const absl::StatusOr<MultiBlockGrid> grid = ParsePlot3d(bytes, kSource);
  EXPECT_FALSE(grid.ok()) << "parsed without error: " << bytes.substr(0, 200);
  if (grid.ok()) return "";
  EXPECT_EQ(grid.status().code(), absl::StatusCode::kInvalidArgument) << grid.status();
  EXPECT_THAT(MessageOf(grid.status()), HasSubstr("plot3d 'bad.fmt': "));
  return MessageOf(grid.status());
}

// `grid` encoded in `format`, failing the test on error.
std::string Encode(const MultiBlockGrid& grid, const Plot3dFormat& format) {
  absl::StatusOr<std::string> bytes = EncodePlot3d(grid, format);
  EXPECT_TRUE(bytes.ok()) << bytes.status();
  return bytes.ok() ? *bytes : std::string();
}

// Byte offset where the last whitespace/comma-separated token of `text` starts.
size_t LastTokenStart(const std::string& text) {
  const size_t last = text.find_last_not_of(" \t\r\n,");
  return text.find_last_of(" \t\r\n,", last) + 1;
}

// Expects every prefix of `text` that ends before its last token to be rejected. (A cut inside
// the last number leaves a valid shorter number: text truncation there is undetectable.)
void ExpectEveryTextCutFails(const std::string& text) {
  ASSERT_TRUE(ParsePlot3d(text, kSource).ok());
  const size_t limit = LastTokenStart(text);
  for (size_t cut = 0; cut < limit; ++cut) {
    SCOPED_TRACE(testing::Message() << "cut at byte " << cut << " of " << text.size());
    ParseError(std::string_view(text).substr(0, cut));
  }
  for (size_t cut = limit; cut < text.size(); ++cut) {
    (void)ParsePlot3d(std::string_view(text).substr(0, cut), kSource);  // must not crash
  }
}

TEST(Plot3dMalformedTextTest, TruncatedSharedFileSaysExpectedAndFound) {
  absl::StatusOr<std::string> text = ReadFileToString(SharedDataPath("grids/n0012_113-33.p2dfmt"));
  ASSERT_TRUE(text.ok()) << text.status();
  const std::string message = ParseError(text->substr(0, LastTokenStart(*text)));
  EXPECT_THAT(message,
              HasSubstr("expected 2*113*33 = 7458 coordinates after the header, found 7457"));
  EXPECT_THAT(message, HasSubstr("the file ends before block 0, y of point (112, 32, 0)"));
}

// A header that declares two blocks but gives one block's dimensions (a trial's file): read
// without a block-count line it misses values, read with one the second block's dimensions are
// coordinates. The message gives both readings, so the missing line shows.
TEST(Plot3dMalformedTextTest, AMissingDimensionsLineShowsInBothReadings) {
  const std::string message =
      ParseError("2\n3 3\n0 1 2 0 1 2 0 1 2\n0 0 0 1 1 1 2 2 2\n");
  EXPECT_THAT(message, HasSubstr("(best-matching layout: 3D, no block-count line, no iblank)"));
  EXPECT_THAT(message, HasSubstr("; read with a block-count line instead: block 1: ni = 0 at "
                                 "line 3, column 1 must be from 1 to"));
  EXPECT_THAT(message, HasSubstr("(layout: 2D, block-count line, no iblank)"));
  // A truncated file without a block-count line gets no second reading (its first coordinate
  // is no dimension).
  EXPECT_THAT(ParseError("3 2\n0.5 1 2 0 1 2\n0 0 0 1 1\n"), Not(HasSubstr("instead")));
}

TEST(Plot3dMalformedTextTest, EveryCutOfSmallTextFilesFails) {
  const MultiBlockGrid three_d = MakeSimpleGrid(3, {{3, 2, 2}, {2, 2, 1}});
  ExpectEveryTextCutFails(Encode(three_d, DefaultPlot3dFormat(three_d, Plot3dEncoding::kAscii)));
  const MultiBlockGrid two_d = MakeSimpleGrid(2, {{4, 3, 1}});
  ExpectEveryTextCutFails(Encode(two_d, Plot3dFormat{Plot3dEncoding::kAscii, 2, false, false, 8}));
  // CFL3D style: repeat counts and commas.
  ExpectEveryTextCutFails(
      "    1\n    2    3    1\n 2*1.,  2*2.5,  2*3.25,\n 2*0.,  2*0.5, 2*1.0,\n 2*0., 2*-1., "
      "2*-1.\n");
}

TEST(Plot3dMalformedTextTest, CutsOfTheSharedSurfaceFileFail) {
  absl::StatusOr<std::string> text = ReadFileToString(SharedDataPath("surfaces/m6_small.fmt"));
  ASSERT_TRUE(text.ok()) << text.status();
  const size_t limit = LastTokenStart(*text);
  for (size_t cut = 0; cut < limit; cut += 1 + limit / 97) {
    SCOPED_TRACE(testing::Message() << "cut at byte " << cut);
    ParseError(std::string_view(*text).substr(0, cut));
  }
}

TEST(Plot3dMalformedTextTest, NonNumericTokenNamesBlockPointAndLine) {
  EXPECT_THAT(ParseError("1\n2 2 1\n0.0 1.0 0.0 1.0\n0.0 abc 1.0 1.0\n0 0 0 0\n"),
              HasSubstr("block 0, y of point (1, 0, 0), line 4, column 5: 'abc' is not a number"));
  EXPECT_THAT(ParseError("1\n2 x 1\n0.0 1.0 0.0 1.0\n"),
              HasSubstr("line 2, column 3: 'x' is not a number"));
  EXPECT_THAT(ParseError("1\n2 1 1\n0.0,,1.0 0 0 0\n"),
              HasSubstr("line 3, column 5: empty value between commas"));
}

TEST(Plot3dMalformedTextTest, NonPositiveDimensionsAreRejected) {
  EXPECT_THAT(ParseError("1\n-5 3 2\n1. 2. 3.\n"),
              HasSubstr("block 0: ni = -5 at line 2, column 1 must be from 1 to 16777216"));
  EXPECT_THAT(ParseError("1\n3 0 2\n1. 2. 3.\n"),
              HasSubstr("block 0: nj = 0 at line 2, column 3 must be from 1 to 16777216"));
  EXPECT_THAT(ParseError("2\n3 2 1\n3 2 -1\n1. 2. 3.\n"),
              HasSubstr("block 1: nk = -1 at line 3, column 5"));
  EXPECT_THAT(ParseError("0\n3 2 1\n1. 2. 3.\n"),
              HasSubstr("the block count = 0 at line 1, column 1 must be from 1 to 1048576"));
  EXPECT_THAT(ParseError("1\n2 2.0 1\n1. 2. 3.\n"),
              HasSubstr("block 0: nj at line 2, column 3: expected a positive integer, found "
                        "'2.0'"));
}

TEST(Plot3dMalformedTextTest, AbsurdDimensionsFailBeforeAllocating) {
  EXPECT_THAT(ParseError("1\n100000 100000 100\n1.0 2.0 3.0\n"),
              HasSubstr("block 0: 100000 x 100000 x 100 = 1e+12 points exceeds the limit"));
  // 10^9 points is under the per-block limit, so the count check must stop it (no 24 GB alloc).
  EXPECT_THAT(ParseError("1\n1000 1000 1000\n1.0 2.0 3.0\n"),
              HasSubstr("expected 3*1000*1000*1000 = 3000000000 coordinates after the header, "
                        "found 3"));
  EXPECT_THAT(ParseError("1\n99999999999 1 1\n1.0 2.0 3.0\n"),
              HasSubstr("block 0: ni = 1e+11 at line 2, column 1 must be from 1 to"));
  EXPECT_THAT(ParseError("2000000000\n1 1 1\n1.0 2.0 3.0\n"),
              HasSubstr("the block count = 2e+09 at line 1, column 1 must be from 1 to 1048576"));
}

TEST(Plot3dMalformedTextTest, NonFiniteCoordinatesAreRejected) {
  for (const char* token : {"nan", "NaN", "-inf", "Infinity", "1e999", "1.0D+400", "2*nan"}) {
    SCOPED_TRACE(token);
    const std::string text = absl::StrCat("1\n2 1 1\n0.0 1.0\n0.0 ", token, "\n0 0\n");
    const std::string message = ParseError(text);
    EXPECT_THAT(message, HasSubstr("line 4, column 5"));
    EXPECT_THAT(message, HasSubstr("not a finite number"));
    // A bad token counts as one value, so the layout is still found and names the point.
    EXPECT_THAT(message, HasSubstr("block 0, y of point (1, 0, 0)"));
  }
}

TEST(Plot3dMalformedTextTest, BadRepeatCountsAreRejected) {
  for (const char* token : {"0*1.", "-3*2", "1e9*1.", "99999999999*1.", "*1.", "1.5*2."}) {
    SCOPED_TRACE(token);
    const std::string message = ParseError(absl::StrCat("1\n2 1 1\n0.0 ", token, "\n0 0\n0 0\n"));
    EXPECT_THAT(message, HasSubstr("block 0, x of point (1, 0, 0), line 3, column 5"));
    EXPECT_THAT(message, HasSubstr("bad repeat count"));
  }
  EXPECT_THAT(ParseError("1\n2 1 1\n0.0 3*\n0 0\n0 0\n"),
              HasSubstr("line 3, column 5: '3*' repeats a null value"));
  EXPECT_THAT(ParseError("1\n2 1 1\n0.0 2*x\n0 0\n0 0\n"),
              HasSubstr("line 3, column 5: '2*x': the repeated value is not a number"));
}

TEST(Plot3dMalformedTextTest, NonIntegerIblankIsRejected) {
  EXPECT_THAT(ParseError("1\n2 1 1\n0. 1.\n0. 0.\n0. 0.\n1 0.5\n"),
              HasSubstr("block 0, iblank of point (1, 0, 0) at line 6, column 3: 0.5 is not an "
                        "integer"));
}

TEST(Plot3dMalformedTextTest, TrailingGarbageIsRejected) {
  const MultiBlockGrid grid = MakeSimpleGrid(3, {{2, 2, 1}});
  const std::string text = Encode(grid, DefaultPlot3dFormat(grid, Plot3dEncoding::kAscii));
  EXPECT_THAT(ParseError(text + "7.0\n"),
              HasSubstr("unexpected values after the last block start at line 6, column 1"));
  EXPECT_THAT(ParseError(text + "  END\n"), HasSubstr("line 6, column 3: 'END' is not a number"));
  EXPECT_THAT(ParseError(text + std::string("\0\0\0", 3)),
              HasSubstr("line 6, column 1: '\\x00\\x00\\x00' is not a number"));
}

TEST(Plot3dMalformedTextTest, EmptyAndBlankFilesAreRejected) {
  EXPECT_THAT(ParseError(""), HasSubstr("the file is empty"));
  EXPECT_THAT(ParseError("  \n\n  \n"),
              HasSubstr("the file ends in the header, where the block count was expected"));
}

// A binary file of `grid` in `format`, and helpers to corrupt it.
class Plot3dMalformedBinaryTest : public testing::Test {
 protected:
  // Little-endian double precision, 3D, block count, 1 block of 2 x 2 x 1 points:
  // record 0 (count) at byte 0, record 1 (dims) at 12, record 2 (block 0, 96 bytes) at 32.
  void SetUp() override {
    grid_ = MakeSimpleGrid(3, {{2, 2, 1}});
    bytes_ = Encode(grid_, DefaultPlot3dFormat(grid_, Plot3dEncoding::kBinaryLittleEndian));
    ASSERT_EQ(bytes_.size(), 12u + 20u + 104u);
  }
  // Overwrites the `size` bytes at `offset` with the little-endian bytes of `bits`.
  void PutLittleEndian(size_t offset, uint64_t bits, int size) {
    for (int i = 0; i < size; ++i) bytes_[offset + i] = static_cast<char>((bits >> (8 * i)) & 0xff);
  }
  // Overwrites the int32 at `offset`.
  void PutInt32(size_t offset, int32_t value) {
    PutLittleEndian(offset, static_cast<uint32_t>(value), 4);
  }

  MultiBlockGrid grid_;
  std::string bytes_;
};

TEST_F(Plot3dMalformedBinaryTest, EveryCutFails) {
  for (Plot3dEncoding encoding :
       {Plot3dEncoding::kBinaryLittleEndian, Plot3dEncoding::kBinaryBigEndian}) {
    for (int dim : {2, 3}) {
      for (int real : {4, 8}) {
        for (bool count : {false, true}) {
          for (bool iblank : {false, true}) {
            const MultiBlockGrid grid = count ? MakeSimpleGrid(dim, {{3, 2, 1}, {2, 2, 1}}, true)
                                              : MakeSimpleGrid(dim, {{3, 2, 1}}, true);
            const Plot3dFormat format{encoding, dim, count, iblank, real};
            SCOPED_TRACE(DescribePlot3dFormat(format));
            const std::string bytes = Encode(grid, format);
            ASSERT_TRUE(ParsePlot3d(bytes, kSource).ok());
            for (size_t cut = 0; cut < bytes.size(); ++cut) {
              SCOPED_TRACE(testing::Message() << "cut at byte " << cut);
              ParseError(std::string_view(bytes).substr(0, cut));
            }
          }
        }
      }
    }
  }
}

TEST_F(Plot3dMalformedBinaryTest, TruncationNamesTheRecordAndOffset) {
  EXPECT_THAT(ParseError(bytes_.substr(0, 100)),
              HasSubstr("block 0 of 1 (record 2): record 2 at byte offset 32: the record marker "
                        "says 96 bytes but only 64 bytes follow it"));
  EXPECT_THAT(ParseError(bytes_.substr(0, 32)),
              HasSubstr("block 0 of 1 (record 2): the file ends after 2 records (byte offset 32)"));
}

TEST_F(Plot3dMalformedBinaryTest, MismatchedRecordMarkersAreRejected) {
  const std::string good = bytes_;
  PutInt32(132, 97);  // trailing marker of the block record
  EXPECT_THAT(ParseError(bytes_),
              HasSubstr("block 0 of 1 (record 2): record 2 at byte offset 32: the leading record "
                        "marker says 96 bytes, the trailing marker at byte offset 132 says 97"));
  bytes_ = good;
  PutInt32(32, 88);  // leading marker of the block record
  EXPECT_THAT(ParseError(bytes_), HasSubstr("record 2 at byte offset 32: the leading record marker "
                                            "says 88 bytes"));
}

TEST_F(Plot3dMalformedBinaryTest, TrailingBytesAreRejected) {
  EXPECT_THAT(ParseError(bytes_ + "junk"),
              HasSubstr("4 unexpected bytes after the last block, from byte offset 136"));
  // A whole extra record is trailing data too.
  EXPECT_THAT(ParseError(bytes_ + bytes_.substr(0, 12)),
              HasSubstr("12 unexpected bytes after the last block, from byte offset 136"));
}

TEST_F(Plot3dMalformedBinaryTest, BadCountsAndDimensionsAreRejected) {
  const std::string good = bytes_;
  PutInt32(4, 0);
  EXPECT_THAT(ParseError(bytes_),
              HasSubstr("the block count 0 (record 0 at byte offset 0) must be from 1"));
  bytes_ = good;
  PutInt32(4, -7);
  EXPECT_THAT(ParseError(bytes_), HasSubstr("the block count -7"));
  bytes_ = good;
  PutInt32(4, 2);
  EXPECT_THAT(ParseError(bytes_), HasSubstr("the dimensions record (record 1 at byte offset 12) "
                                            "holds 12 bytes; 2 blocks need 16 (2D) or 24 (3D)"));
  bytes_ = good;
  PutInt32(20, -2);  // nj
  EXPECT_THAT(ParseError(bytes_), HasSubstr("block 0: nj = -2 at byte offset 20 (record 1)"));
  bytes_ = good;
  PutInt32(16, 1 << 20);  // ni: 2^20 x 2^11 x 1 = 2^31 points would be the limit ...
  PutInt32(20, 1 << 12);  // ... 2^32 is over it
  EXPECT_THAT(ParseError(bytes_), HasSubstr("block 0: 1048576 x 4096 x 1 = 4.29497e+09 points "
                                            "exceeds the limit"));
  bytes_ = good;
  PutInt32(16, 1000);  // 1000 x 2 x 1 points cannot fit the 96-byte record: no allocation
  EXPECT_THAT(ParseError(bytes_),
              HasSubstr("block 0 (record 2 at byte offset 32) holds 96 bytes; its 2000 points "
                        "need 24000 (single precision), 48000 (double)"));
}

TEST_F(Plot3dMalformedBinaryTest, NonFiniteValuesAreRejected) {
  // Value 5 of the block record: y of point (1, 0, 0).
  PutLittleEndian(36 + 8 * 5, std::bit_cast<uint64_t>(std::numeric_limits<double>::quiet_NaN()), 8);
  EXPECT_THAT(ParseError(bytes_),
              HasSubstr("block 0, y of point (1, 0, 0) at byte offset 76 (record 2): nan is not "
                        "finite"));
}

TEST_F(Plot3dMalformedBinaryTest, GarbageIsNeitherTextNorRecords) {
  EXPECT_THAT(ParseError(std::string("\x01\x02\x03\x04\x05\x06\x07\x08", 8)),
              HasSubstr("not a Plot3D text file (byte 0x01 at the start), not a Fortran "
                        "unformatted file in either byte order"));
  EXPECT_THAT(ParseError(std::string("\x01\x02\x03\x04\x05\x06\x07\x08", 8)),
              HasSubstr("and not a C-stream file: no combination of byte order"));
}

// Found while writing the fuzz targets (a first tests/fuzz/plot3d_binary.cc called this reader
// directly): its "neither text nor records" message read bytes[0] of empty input. ParsePlot3d
// rejects empty files before calling it; the reader itself must too.
TEST(Plot3dBinaryReaderTest, EmptyInputIsRejectedWithoutReadingIt) {
  bool looks_fortran = true;
  const absl::StatusOr<MultiBlockGrid> grid =
      plot3d_internal::ParsePlot3dBinary(std::string_view(), kSource, {}, nullptr, &looks_fortran);
  ASSERT_FALSE(grid.ok());
  EXPECT_EQ(grid.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(MessageOf(grid.status()), HasSubstr("plot3d 'bad.fmt': the file is empty"));
}

}  // namespace
}  // namespace splinegrid
