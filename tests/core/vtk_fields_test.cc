// Derived VTK fields: the Jacobian from analytic derivatives and the scaled Jacobian of cells.
#include "core/io/vtk_fields.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io_test_util.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

constexpr double kTight = 1e-12;

// A 2D block of the map (u, v) -> (a u + s v, b v) on a uniform 4 x 3 grid.
StructuredBlock Sheared(double a, double b, double s) {
  StructuredBlock block({4, 3, 1}, 2);
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 4; ++i) {
      block.Point(i, j, 0)[0] = a * i + s * j;
      block.Point(i, j, 0)[1] = b * j;
    }
  }
  return block;
}

TEST(VtkFieldsTest, JacobianOfLinearMapsIsTheirDeterminant) {
  const StructuredBlock block = Sheared(2.0, 3.0, 1.0);
  const int64_t n = block.num_points();
  std::vector<double> du, dv, dw;
  for (int64_t p = 0; p < n; ++p) {
    du.insert(du.end(), {2.0, 0.0});
    dv.insert(dv.end(), {1.0, 3.0});
  }
  absl::StatusOr<std::vector<double>> j = JacobianField(block, du, dv, dw, 2);
  ASSERT_TRUE(j.ok()) << j.status();
  for (double value : *j) EXPECT_NEAR(value, 6.0, kTight);
  // Mirrored: negative in 2D.
  for (int64_t p = 0; p < n; ++p) dv[2 * p + 1] = -3.0;
  j = JacobianField(block, du, dv, dw, 2);
  for (double value : *j) EXPECT_NEAR(value, -6.0, kTight);
  // Curves: |X_u|.
  j = JacobianField(block, du, dv, dw, 1);
  for (double value : *j) EXPECT_NEAR(value, 2.0, kTight);
  // A volume: det of three tangents; a surface in 3D: the unsigned area element.
  StructuredBlock box({2, 2, 2}, 3);
  std::vector<double> bu, bv, bw;
  for (int p = 0; p < 8; ++p) {
    bu.insert(bu.end(), {1.0, 0.0, 0.0});
    bv.insert(bv.end(), {0.0, 2.0, 0.0});
    bw.insert(bw.end(), {0.5, 0.0, -4.0});
  }
  j = JacobianField(box, bu, bv, bw, 3);
  for (double value : *j) EXPECT_NEAR(value, -8.0, kTight);
  j = JacobianField(box, bv, bu, {}, 2);
  for (double value : *j) EXPECT_NEAR(value, 2.0, kTight);
  EXPECT_THAT(MessageOf(JacobianField(box, bu, bv, {}, 3).status()),
              HasSubstr("derivative dw has 0 values, not 24"));
  EXPECT_THAT(MessageOf(JacobianField(block, du, dv, dw, 3).status()),
              HasSubstr("parametric_dim 3 must be from 1 to the spatial_dim 2"));
}

TEST(VtkFieldsTest, ScaledJacobianIsOneForRectanglesAndSeesShearAndFolds) {
  absl::StatusOr<std::vector<double>> q = ScaledJacobianCells(Sheared(2.0, 3.0, 0.0));
  ASSERT_TRUE(q.ok()) << q.status();
  ASSERT_EQ(q->size(), 6u);
  for (double value : *q) EXPECT_NEAR(value, 1.0, kTight);
  // A shear by 45 degrees: sin(45) at every corner.
  q = ScaledJacobianCells(Sheared(1.0, 1.0, 1.0));
  for (double value : *q) EXPECT_NEAR(value, std::sqrt(0.5), kTight);
  // A left-handed (mirrored) block is judged by its own orientation: still 1.
  q = ScaledJacobianCells(Sheared(2.0, -3.0, 0.0));
  for (double value : *q) EXPECT_NEAR(value, 1.0, kTight);
  // One point pushed across its neighbour folds the cells around it: negative.
  StructuredBlock folded = Sheared(1.0, 1.0, 0.0);
  folded.Point(1, 1, 0)[0] = 2.5;
  q = ScaledJacobianCells(folded);
  EXPECT_LT(*std::min_element(q->begin(), q->end()), 0.0);
  // Hexahedra of the sheared box of MakeSimpleGrid: edges e1 = (0.5, 0, 0.0625),
  // e2 = (0.25, 0.125, 0), e3 = (0, 0, 0.75) at every corner, det = 0.046875.
  q = ScaledJacobianCells(MakeSimpleGrid(3, {{3, 3, 3}}).blocks[0]);
  ASSERT_TRUE(q.ok());
  EXPECT_EQ(q->size(), 8u);
  const double lengths = std::sqrt(0.25 + 0.0625 * 0.0625) * std::sqrt(0.0625 + 0.015625) * 0.75;
  for (double value : *q) EXPECT_NEAR(value, 0.046875 / lengths, kTight);
  // Curves have no cells with an area.
  EXPECT_THAT(MessageOf(ScaledJacobianCells(StructuredBlock({5, 1, 1}, 3)).status()),
              HasSubstr("is a curve"));
}

}  // namespace
}  // namespace splinegrid
