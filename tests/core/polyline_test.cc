#include "core/grid/polyline.h"

#include <vector>

#include "gtest/gtest.h"

namespace splinegrid {
namespace {

TEST(PolylineTest, SimpleOpenAndClosedOutlinesHaveNoCrossing) {
  const std::vector<double> square = {0, 0, 1, 0, 1, 1, 0, 1, 0, 0};
  EXPECT_FALSE(FindPolylineCrossing(square, /*closed=*/true).has_value());
  // Open, the repeated end point touches the first segment's start.
  EXPECT_TRUE(FindPolylineCrossing(square, /*closed=*/false).has_value());
  const std::vector<double> zigzag = {0, 0, 1, 1, 2, 0, 3, 1, 4, 0};
  EXPECT_FALSE(FindPolylineCrossing(zigzag, false).has_value());
  EXPECT_FALSE(FindPolylineCrossing(std::vector<double>{0, 0, 1, 1}, false).has_value());
}

TEST(PolylineTest, ACrossingNamesBothSegments) {
  // A figure eight: segment 0-1 crosses segment 2-3.
  const std::vector<double> eight = {0, 0, 2, 2, 2, 0, 0, 2};
  const std::optional<PolylineCrossing> crossing = FindPolylineCrossing(eight, false);
  ASSERT_TRUE(crossing.has_value());
  EXPECT_EQ(crossing->first, 0);
  EXPECT_EQ(crossing->second, 2);
}

TEST(PolylineTest, TouchingAndFoldingBackAreNotSimple) {
  // Point 3 lies on segment 0-1.
  const std::vector<double> touch = {0, 0, 2, 0, 2, 1, 1, 0, 1, -1};
  EXPECT_TRUE(FindPolylineCrossing(touch, false).has_value());
  // Neighbours 1-2 and 2-3 fold back onto each other.
  const std::vector<double> fold = {0, 0, 1, 0, 2, 0, 1.5, 0, 1.5, 1};
  const std::optional<PolylineCrossing> crossing = FindPolylineCrossing(fold, false);
  ASSERT_TRUE(crossing.has_value());
  EXPECT_EQ(crossing->second - crossing->first, 1);
}

}  // namespace
}  // namespace splinegrid
