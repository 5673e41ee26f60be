// No silent changes (issue 12, point 7), through the service: a fit the server cannot honour
// as asked is refused with the status code and a message naming the request field, value and
// limit, and nothing is stored; a degenerate grid is refused at import; a report claims no
// tolerance it did not measure.
#include <numbers>

#include "gmock/gmock.h"
#include "tests/core/synthetic_grids.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::testing {
namespace {

using ::testing::HasSubstr;

class SilentChangesTest : public ServiceTest {
 protected:
  void SetUp() override {
    ServiceTest::SetUp();
    ImportShared("grids/n0012_113-33.p2dfmt", "naca");
    FitCounts("naca", 30, 12);
  }

  int64_t Revisions() { return client_->Get("naca").value().latest_revision(); }

  // Expects FitGrid with `spec` to fail with `code` and `fragment`, storing nothing.
  void ExpectRefused(const v1::FitSpec& spec, absl::StatusCode code, const std::string& fragment) {
    const int64_t before = Revisions();
    EXPECT_THAT(client_->Fit("naca", spec).status(), StatusIs(code, fragment));
    EXPECT_EQ(Revisions(), before);
  }

  static v1::FitSpec Counts(int ci, int cj, int order = 0) {
    v1::FitSpec spec;
    spec.set_allow_folds(true);  // counts that fold the C-grid; what is tested is the counts
    spec.set_order(order);
    spec.mutable_control_counts()->set_i(ci);
    spec.mutable_control_counts()->set_j(cj);
    return spec;
  }
};

TEST_F(SilentChangesTest, ControlsBelowTheOrderAreRefusedNotFittedAtOrderTwo) {
  ExpectRefused(Counts(2, 2, 4), absl::StatusCode::kInvalidArgument,
                "spec.control_counts[0] = 2 is below order = 4: a B-spline of order k needs at "
                "least k control points per direction; give at least 4 (block 0 has 113 points "
                "in i), or order <= 2");
  // What the refusal suggests is honoured exactly.
  absl::StatusOr<v1::FitGridResponse> fit = client_->Fit("naca", Counts(2, 2, 2));
  ASSERT_TRUE(fit.ok()) << fit.status();
  const v1::Grid grid = client_->Get("naca").value();
  ASSERT_EQ(grid.revision().blocks_size(), 1);
  EXPECT_EQ(grid.revision().blocks(0).directions(0).order(), 2);
  EXPECT_EQ(grid.revision().blocks(0).directions(0).num_controls(), 2);
  EXPECT_EQ(grid.revision().fit_spec().order(), 2);
}

TEST_F(SilentChangesTest, MoreControlsThanPointsAreRefusedNotClamped) {
  ExpectRefused(Counts(1000, 1000), absl::StatusCode::kInvalidArgument,
                "spec.control_counts[0] = 1000 exceeds the 113 points of block 0 in i; give at "
                "most 113 (0: as many as points)");
  ExpectRefused(Counts(60, 34), absl::StatusCode::kInvalidArgument,
                "spec.control_counts[1] = 34 exceeds the 33 points of block 0 in j");
  v1::FitSpec twice = Counts(30, 12);
  for (int ci : {20, 21}) {
    v1::BlockControlCounts* entry = twice.add_block_control_counts();
    entry->set_block(0);
    entry->mutable_control_counts()->set_i(ci);
    entry->mutable_control_counts()->set_j(10);
  }
  ExpectRefused(twice, absl::StatusCode::kInvalidArgument,
                "spec.block_control_counts[1].block = 0 repeats block_control_counts[0]");
}

TEST_F(SilentChangesTest, MaxControlsBelowTheOrderIsRefused) {
  v1::FitSpec spec;
  spec.set_tolerance(1e-3);
  spec.set_max_controls_per_direction(3);
  ExpectRefused(spec, absl::StatusCode::kInvalidArgument,
                "spec.max_controls_per_direction = 3 is below order = 4");
}

TEST_F(SilentChangesTest, ACountFitDoesNotClaimATolerance) {
  absl::StatusOr<v1::FitGridResponse> fit = client_->Fit("naca", Counts(30, 12));
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_FALSE(fit->report().tolerance_met());
  EXPECT_FALSE(fit->report().tolerances_given());
  EXPECT_THAT(fit->report().unmet_reason(), HasSubstr("no tolerance was given"));
  EXPECT_FALSE(fit->blocks(0).has_tolerance_met());
  EXPECT_TRUE(fit->report().adjustments().empty());
  v1::FitSpec tolerance;
  tolerance.set_tolerance(1e-3);
  tolerance.set_allow_folds(true);  // 1e-3 folds this C-grid (not repaired); tested: the report
  absl::StatusOr<v1::FitGridResponse> by_tolerance = client_->Fit("naca", tolerance);
  ASSERT_TRUE(by_tolerance.ok()) << by_tolerance.status();
  EXPECT_TRUE(by_tolerance->report().tolerances_given());
}

// A grid of 3 points in j fitted at order 4: interpolated at order 3 there, and the response,
// the stored revision and an exported archive say so.
TEST_F(SilentChangesTest, AFitAtALowerOrderThanAskedSaysSo) {
  MultiBlockGrid thin;
  thin.blocks.push_back(BentRectangle(0.0, 1.0 / 19, 20, 0.0, 0.5, 3));
  ASSERT_TRUE(client_->ImportPoints(thin, "thin", "thin").ok());
  absl::StatusOr<v1::FitGridResponse> fit = client_->Fit("thin", Counts(8, 0));
  ASSERT_TRUE(fit.ok()) << fit.status();
  ASSERT_EQ(fit->report().adjustments_size(), 1);
  EXPECT_THAT(fit->report().adjustments(0), HasSubstr("direction j: 3 points"));
  EXPECT_THAT(fit->report().adjustments(0), HasSubstr("order 3 instead of 4"));
}

TEST_F(SilentChangesTest, DegenerateGridsAreRefusedAtImport) {
  const size_t grids = client_->List().value().size();
  // All points equal.
  MultiBlockGrid same;
  same.blocks.emplace_back(Extents{4, 3, 1}, 2);
  for (size_t c = 0; c < same.blocks[0].coords().size(); ++c) {
    same.blocks[0].coords()[c] = c % 2 == 0 ? 1.5 : -2.0;
  }
  EXPECT_THAT(client_->ImportPoints(same, "same", "").status(),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       "block 0: all 12 points are equal (1.5, -2): a grid collapsed to a point "
                       "cannot be fitted"));
  // A second block collapsed in j: the message names it and the direction.
  MultiBlockGrid flat;
  flat.blocks.emplace_back(Extents{3, 3, 1}, 2);
  flat.blocks.emplace_back(Extents{3, 4, 1}, 2);
  for (StructuredBlock& block : flat.blocks) {
    for (int j = 0; j < block.extent(1); ++j) {
      for (int i = 0; i < 3; ++i) {
        block.Point(i, j, 0)[0] = i;
        block.Point(i, j, 0)[1] = &block == &flat.blocks[0] ? j : 0.0;
      }
    }
  }
  EXPECT_THAT(client_->ImportPoints(flat, "flat", "").status(),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       "block 1: direction j has zero length"));
  EXPECT_EQ(client_->List().value().size(), grids);
  // A polar disc (its j = 0 edge collapsed to the centre) is a legitimate grid.
  MultiBlockGrid disc;
  disc.blocks.emplace_back(Extents{17, 6, 1}, 2);
  for (int j = 0; j < 6; ++j) {
    for (int i = 0; i < 17; ++i) {
      const double a = 2 * std::numbers::pi * i / 16;
      disc.blocks[0].Point(i, j, 0)[0] = j * std::cos(a);
      disc.blocks[0].Point(i, j, 0)[1] = j * std::sin(a);
    }
  }
  EXPECT_TRUE(client_->ImportPoints(disc, "disc", "").ok());
}

}  // namespace
}  // namespace splinegrid::testing
