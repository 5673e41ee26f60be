#include "core/bspline/parametrization.h"

#include "gtest/gtest.h"

namespace splinegrid {
namespace {

TEST(ParametrizationTest, ChordLengthAndCentripetalOfOneLine) {
  // Points at x = 0, 1, 3, 7: chords 1, 2, 4.
  StructuredBlock line({4, 1, 1}, 2);
  const double xs[] = {0, 1, 3, 7};
  for (int i = 0; i < 4; ++i) line.Point(i, 0, 0)[0] = xs[i];
  const auto chord = ParametrizeBlock(line, Parametrization::kChordLength)[0];
  EXPECT_DOUBLE_EQ(chord[1], 1.0 / 7);
  EXPECT_DOUBLE_EQ(chord[2], 3.0 / 7);
  EXPECT_EQ(chord[3], 1.0);
  const auto centripetal = ParametrizeBlock(line, Parametrization::kCentripetal)[0];
  const double total = 1 + std::sqrt(2.0) + 2;
  EXPECT_DOUBLE_EQ(centripetal[1], 1 / total);
  EXPECT_DOUBLE_EQ(centripetal[2], (1 + std::sqrt(2.0)) / total);
  const auto uniform = ParametrizeBlock(line, Parametrization::kUniform)[0];
  EXPECT_DOUBLE_EQ(uniform[1], 1.0 / 3);
  EXPECT_EQ(ParametrizeBlock(line, Parametrization::kChordLength)[1], std::vector<double>{0.0});
}

TEST(ParametrizationTest, AveragesOverGridLinesAndSkipsCollapsedLines) {
  // Direction j of a 3 x 3 grid: line i = 0 collapsed (a singular edge), lines 1 and 2 with
  // chords (1, 3) and (1, 1): normalised (0.25, 0.75) and (0.5, 0.5), mean (0.375, 0.625).
  StructuredBlock grid({3, 3, 1}, 2);
  const double y[3][3] = {{0, 0, 0}, {0, 1, 4}, {0, 1, 2}};  // [i][j]
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      grid.Point(i, j, 0)[0] = i;
      grid.Point(i, j, 0)[1] = y[i][j];
    }
  }
  const auto v = ParametrizeBlock(grid, Parametrization::kChordLength)[1];
  EXPECT_DOUBLE_EQ(v[1], 0.375);
  // Repeated points on every line still give strictly increasing parameters.
  StructuredBlock repeated({4, 1, 1}, 3);
  repeated.Point(3, 0, 0)[0] = 1.0;
  const auto u = ParametrizeBlock(repeated, Parametrization::kChordLength)[0];
  EXPECT_GT(u[1], 0.0);
  EXPECT_GT(u[2], u[1]);
  EXPECT_EQ(u[3], 1.0);
}

}  // namespace
}  // namespace splinegrid
