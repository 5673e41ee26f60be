// Issue 13 point 3: a fit, fair or generate whose result folds a (sub-)cell at refinement levels
// 0..2 is repaired or refused (FAILED_PRECONDITION naming the cells, nothing stored) unless the
// request sets allow_folds, in which case it is stored and the report says so.
//
// Folds are counted here independently of the kernel's quality check (core/fit/grid_quality):
// the grid is evaluated through the service at levels 0..2 and every sub-cell's signed shoelace
// area is compared with the sign of its original ("parent") cell of the source file.
#include <cstdint>
#include <string>
#include <vector>

#include "core/io/plot3d.h"
#include "tests/core/quadrilateral_checks.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::testing {
namespace {

using ::testing::HasSubstr;

constexpr char kCGrid[] = "grids/n0012_225-65.p2dfmt";  // NACA 0012 C-grid, far field 500 c
constexpr char kSmallCGrid[] = "grids/n0012_113-33.p2dfmt";

// Folded sub-cells of revision `revision` of `name` at levels 0, 1, 2: sub-cells whose signed
// area is not of the (nonzero) sign of the original cell they lie in.
std::vector<int64_t> IndependentFolds(client::Client& client, const std::string& name,
                                      int64_t revision, const StructuredBlock& original) {
  std::vector<int64_t> folds;
  for (int level = 0; level <= 2; ++level) {
    v1::EvaluateGridRequest request;
    request.set_name(name);
    request.set_revision(revision);
    request.set_refinement_level(level);
    absl::StatusOr<client::EvaluatedGrid> grid = client.Evaluate(request);
    EXPECT_TRUE(grid.ok()) << grid.status();
    if (!grid.ok()) return {};
    const StructuredBlock& fine = grid->blocks.at(0).points;
    EXPECT_EQ(fine.spatial_dim(), 2);
    EXPECT_EQ(fine.extent(0), ((original.extent(0) - 1) << level) + 1);
    folds.push_back(FoldedSubCells(original, fine, level));
  }
  return folds;
}

StructuredBlock Original(const std::string& relative) {
  const std::string bytes = ReadFileToString(SharedDataPath(relative)).value();
  return ParsePlot3d(bytes, relative).value().blocks.at(0);
}

class FoldRefusalTest : public ServiceTest {
 protected:
  int64_t Revisions(const std::string& id) {
    absl::StatusOr<v1::Grid> grid = client_->Get(id);
    EXPECT_TRUE(grid.ok()) << grid.status();
    return grid.ok() ? grid->revisions_size() : -1;
  }

  // A tolerance fit of the real C-grid: either fold-free, checked independently, or refused
  // naming the cells with nothing stored.
  void ExpectRepairedOrRefused(double tolerance) {
    const std::string id = "c-grid";
    ImportShared(kCGrid, id);
    v1::FitSpec spec;
    spec.set_tolerance(tolerance);
    absl::StatusOr<v1::FitGridResponse> fit = client_->Fit(id, spec);
    if (fit.ok()) {
      EXPECT_EQ(fit->report().folded_cells(), 0);
      EXPECT_THAT(IndependentFolds(*client_, id, fit->revision(), Original(kCGrid)),
                  ::testing::ElementsAre(0, 0, 0));
      return;
    }
    EXPECT_EQ(fit.status().code(), absl::StatusCode::kFailedPrecondition) << fit.status();
    const std::string message(fit.status().message());
    EXPECT_THAT(message, HasSubstr("folds"));
    EXPECT_THAT(message, HasSubstr("block 0: "));
    EXPECT_THAT(message, HasSubstr("at level 2"));
    EXPECT_THAT(message, HasSubstr("the worst at cell ("));
    EXPECT_THAT(message, HasSubstr("allow_folds"));
    EXPECT_THAT(message, HasSubstr("nothing was stored"));
    EXPECT_EQ(Revisions(id), 0);
  }
};

TEST_F(FoldRefusalTest, CGridAtTolerance5e5IsFoldFreeOrRefused) { ExpectRepairedOrRefused(5e-5); }

TEST_F(FoldRefusalTest, CGridAtTolerance1e5IsFoldFreeOrRefused) { ExpectRepairedOrRefused(1e-5); }

// Control counts that fold the small C-grid: refused (no repair: it would change the counts),
// and stored with allow_folds, the report and the independent count agreeing on the folds.
TEST_F(FoldRefusalTest, CountFitThatFoldsIsRefusedUnlessAllowed) {
  const std::string id = "ctl";
  ImportShared(kSmallCGrid, id);
  v1::FitSpec spec;
  spec.mutable_control_counts()->set_i(100);
  spec.mutable_control_counts()->set_j(30);
  absl::StatusOr<v1::FitGridResponse> refused = client_->Fit(id, spec);
  EXPECT_THAT(refused.status(),
              StatusIs(absl::StatusCode::kFailedPrecondition, "control counts is not repaired"));
  EXPECT_THAT(std::string(refused.status().message()), HasSubstr("cells ("));
  EXPECT_EQ(Revisions(id), 0);

  spec.set_allow_folds(true);
  absl::StatusOr<v1::FitGridResponse> stored = client_->Fit(id, spec);
  ASSERT_TRUE(stored.ok()) << stored.status();
  EXPECT_EQ(Revisions(id), 1);
  EXPECT_FALSE(stored->report().quality_met());
  EXPECT_GT(stored->report().folded_cells(), 0);
  const std::vector<int64_t> folds =
      IndependentFolds(*client_, id, stored->revision(), Original(kSmallCGrid));
  ASSERT_EQ(folds.size(), 3u);
  EXPECT_EQ(folds[0] + folds[1] + folds[2], stored->report().folded_cells());
  // The revision keeps the request's acceptance of folds as provenance.
  absl::StatusOr<v1::Grid> grid = client_->Get(id);
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_TRUE(grid->revision().fit_spec().allow_folds());

  // A fair of it folds too: refused without the request's own allow_folds (the parent's does not
  // carry over), stored with it.
  v1::Fairing fairing;
  fairing.set_mode(v1::FAIRING_MODE_WEIGHT);
  fairing.set_weight(1e-12);
  absl::StatusOr<v1::FitGridResponse> fair = client_->Fair(id, 1, &fairing);
  EXPECT_THAT(fair.status(), StatusIs(absl::StatusCode::kFailedPrecondition, "folds"));
  EXPECT_EQ(Revisions(id), 1);
  fair = client_->Fair(id, 1, &fairing, /*allow_folds=*/true);
  ASSERT_TRUE(fair.ok()) << fair.status();
  EXPECT_GT(fair->report().folded_cells(), 0);
  EXPECT_EQ(Revisions(id), 2);
}

}  // namespace
}  // namespace splinegrid::testing
