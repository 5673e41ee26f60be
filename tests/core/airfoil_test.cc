// Airfoil coordinate files: Selig and Lednicer formats, duplicates, errors.
#include "core/io/airfoil.h"

#include <algorithm>
#include <ostream>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io_test_util.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

// Point `p` of `airfoil` as {x, y}.
std::array<double, 2> PointOf(const AirfoilCoordinates& airfoil, int p) {
  const double* xy = airfoil.points.Point(p, 0, 0);
  return {xy[0], xy[1]};
}

// Parses `text` expecting INVALID_ARGUMENT naming "test.dat"; the message.
std::string ParseError(const std::string& text) {
  absl::StatusOr<AirfoilCoordinates> airfoil = ParseAirfoil(text, "test.dat");
  EXPECT_EQ(airfoil.status().code(), absl::StatusCode::kInvalidArgument) << text;
  EXPECT_THAT(MessageOf(airfoil.status()), HasSubstr("airfoil 'test.dat': "));
  return MessageOf(airfoil.status());
}

// A shared Selig file and what it must contain.
struct SeligCase {
  std::string file;             // relative to the shared data directory
  std::string name;             // the name line, trimmed
  int num_points;               // points in the file
  std::array<double, 2> first;  // the trailing edge, upper side
  std::array<double, 2> last;   // the trailing edge, lower side
};

// Prints the file name of a SeligCase in test output.
void PrintTo(const SeligCase& c, std::ostream* os) { *os << c.file; }

class AirfoilSeligTest : public testing::TestWithParam<SeligCase> {};

// Test name of a SeligCase: the file's stem.
std::string SeligCaseName(const testing::TestParamInfo<SeligCase>& info) {
  std::string name = info.param.file.substr(info.param.file.find('/') + 1);
  return name.substr(0, name.find('.'));
}

TEST_P(AirfoilSeligTest, ReadsSharedFile) {
  const SeligCase& c = GetParam();
  absl::StatusOr<AirfoilCoordinates> airfoil = ReadAirfoilFile(SharedDataPath(c.file));
  ASSERT_TRUE(airfoil.ok()) << airfoil.status();
  EXPECT_EQ(airfoil->name, c.name);
  EXPECT_EQ(airfoil->format, AirfoilFileFormat::kSelig);
  EXPECT_EQ(airfoil->duplicates_dropped, 0);
  const StructuredBlock& points = airfoil->points;
  EXPECT_EQ(points.extents(), Extents({c.num_points, 1, 1}));
  EXPECT_EQ(points.spatial_dim(), 2);
  EXPECT_EQ(PointOf(*airfoil, 0), c.first);
  EXPECT_EQ(PointOf(*airfoil, c.num_points - 1), c.last);
  // Selig order: x falls to the leading edge (0, 0) over the upper side, then rises.
  int leading_edge = 0;
  for (int p = 0; p < c.num_points; ++p) {
    if (PointOf(*airfoil, p)[0] < PointOf(*airfoil, leading_edge)[0]) leading_edge = p;
  }
  EXPECT_EQ(PointOf(*airfoil, leading_edge), (std::array<double, 2>{0.0, 0.0}));
  for (int p = 1; p < c.num_points; ++p) {
    const double dx = PointOf(*airfoil, p)[0] - PointOf(*airfoil, p - 1)[0];
    if (p <= leading_edge) {
      EXPECT_LT(dx, 0.0) << p;
    } else {
      EXPECT_GT(dx, 0.0) << p;
    }
  }
  EXPECT_GT(PointOf(*airfoil, leading_edge / 2)[1], PointOf(*airfoil, leading_edge * 3 / 2)[1]);
}

INSTANTIATE_TEST_SUITE_P(
    AirfoilSharedFiles, AirfoilSeligTest,
    testing::Values(SeligCase{"airfoils/naca0012.dat",
                              "Naca 0012 By Naca.exe D. LEDNICER",
                              69,
                              {1.0, 0.00126},
                              {1.0, -0.00126}},
                    SeligCase{
                        "airfoils/rae2822.dat", "RAE 2822 AIRFOIL", 129, {1.0, 0.0}, {1.0, 0.0}},
                    SeligCase{"airfoils/sc20714.dat",
                              "NASA SC(2)-0714 AIRFOIL",
                              205,
                              {1.0, -0.0095},
                              {1.0, -0.0165}}),
    SeligCaseName);

TEST(AirfoilLednicerTest, ReordersToSeligAndDropsTheSharedLeadingEdge) {
  const std::string text =
      "LEDNICER TEST\n"
      "       5.       4.\n"
      "\n"
      " 0.0  0.0\n 0.25 0.05\n 0.5 0.06\n 0.75 0.04\n 1.0 0.0\n"
      "\n"
      " 0.0  0.0\n 0.3 -0.04\n 0.6 -0.03\n 1.0 0.0\n";
  absl::StatusOr<AirfoilCoordinates> airfoil = ParseAirfoil(text, "lednicer.dat");
  ASSERT_TRUE(airfoil.ok()) << airfoil.status();
  EXPECT_EQ(airfoil->name, "LEDNICER TEST");
  EXPECT_EQ(airfoil->format, AirfoilFileFormat::kLednicer);
  EXPECT_EQ(airfoil->duplicates_dropped, 1);
  const std::vector<std::array<double, 2>> expected = {{1.0, 0.0},   {0.75, 0.04}, {0.5, 0.06},
                                                       {0.25, 0.05}, {0.0, 0.0},   {0.3, -0.04},
                                                       {0.6, -0.03}, {1.0, 0.0}};
  ASSERT_EQ(airfoil->points.num_points(), expected.size());
  for (size_t p = 0; p < expected.size(); ++p) EXPECT_EQ(PointOf(*airfoil, p), expected[p]) << p;
}

TEST(AirfoilSeligSyntaxTest, AcceptsCommasFortranExponentsAndDropsDuplicates) {
  const std::string text =
      "  comma test \r\n1.0, 0.0\r\n0.5D0, 0.1\r\n0.5D0, 0.1\r\n0.0 0.0\r\n0.5 -1.0d-1\r\n"
      "1.0 0.0\r\n\r\n";
  absl::StatusOr<AirfoilCoordinates> airfoil = ParseAirfoil(text, "commas.dat");
  ASSERT_TRUE(airfoil.ok()) << airfoil.status();
  EXPECT_EQ(airfoil->name, "comma test");
  EXPECT_EQ(airfoil->duplicates_dropped, 1);
  EXPECT_EQ(airfoil->points.num_points(), 5);
  EXPECT_EQ(PointOf(*airfoil, 3), (std::array<double, 2>{0.5, -0.1}));
}

TEST(AirfoilErrorTest, NamesFileAndLine) {
  const std::string header = "test\n1.0 0.0\n0.5 0.1\n";
  EXPECT_THAT(ParseError(header + "0.0 nan\n0.5 -0.1\n1.0 0.0\n"),
              HasSubstr("line 4: 'nan' is not a finite number"));
  EXPECT_THAT(ParseError(header + "0.0 abc\n0.5 -0.1\n1.0 0.0\n"),
              HasSubstr("line 4: 'abc' is not a number"));
  EXPECT_THAT(ParseError(header + "0.0 0.0 0.0\n0.5 -0.1\n1.0 0.0\n"),
              HasSubstr("line 4: expected two numbers \"x y\", found 3 fields"));
  EXPECT_THAT(ParseError(header + "0.0 0.0\n"),
              HasSubstr("found 3 distinct points, an airfoil needs at least 5"));
  EXPECT_THAT(ParseError(header + "0.5 0.1\n0.5 0.1\n0.5 0.1\n"), HasSubstr("found 2 distinct"));
  EXPECT_THAT(ParseError(""), HasSubstr("the file is empty"));
  EXPECT_THAT(ParseError("\n1.0 0.0\n"), HasSubstr("line 1: expected the airfoil name"));
  EXPECT_THAT(ParseError("lednicer\n 3. 3.\n0 0\n0.5 0.1\n1 0\n0 0\n0.5 -0.1\n"),
              HasSubstr("line 2: Lednicer point counts 3 + 3 do not match the 5 points"));
}

TEST(AirfoilErrorTest, MissingFileIsNotFound) {
  EXPECT_EQ(ReadAirfoilFile("/nonexistent/airfoil.dat").status().code(),
            absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace splinegrid
