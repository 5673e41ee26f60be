// Default tolerances by kind relative to the grid's reference length, through the service
// (issue 13, point 1): the NACA 0012 C-grid as Plot3D files in chords, millimetres and inches
// fits to the same control count and cell quality; FitSpec.reference_length overrides the
// detected length; given tolerances stay absolute; the report states all of it.
#include <cmath>
#include <string>

#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::testing {
namespace {

using ::testing::HasSubstr;

class ReferenceLengthServiceTest : public ServiceTest {
 protected:
  // Imports the 225 x 65 C-grid scaled by `factor` as a Plot3D text file under `id`.
  void ImportScaled(double factor, const std::string& id) {
    absl::StatusOr<MultiBlockGrid> grid =
        ReadPlot3dFile(SharedDataPath("grids/n0012_225-65.p2dfmt"));
    ASSERT_TRUE(grid.ok()) << grid.status();
    for (StructuredBlock& block : grid->blocks) {
      for (double& x : block.coords()) x *= factor;
    }
    absl::StatusOr<std::string> bytes =
        EncodePlot3d(*grid, DefaultPlot3dFormat(*grid, Plot3dEncoding::kAscii));
    ASSERT_TRUE(bytes.ok()) << bytes.status();
    ASSERT_TRUE(client_->ImportPlot3d(*bytes, id, id + ".p2dfmt", false).ok());
  }

  v1::FitGridResponse Fit(const std::string& id, const v1::FitSpec& spec) {
    absl::StatusOr<v1::FitGridResponse> fit = client_->Fit(id, spec);
    EXPECT_TRUE(fit.ok()) << fit.status();
    return fit.ok() ? *fit : v1::FitGridResponse();
  }
};

// The defaults by kind (an empty boundary_tolerances): same control count, same bad and folded
// cells in every unit; the report states the chord found and the tolerances held.
TEST_F(ReferenceLengthServiceTest, SameFitInChordsMillimetresAndInches) {
  v1::FitSpec spec;
  spec.mutable_boundary_tolerances();
  spec.set_allow_folds(true);  // compare what the fits reach
  v1::FitGridResponse chords;
  for (double factor : {1.0, 1000.0, 39.37}) {
    const std::string id = "naca" + std::to_string(static_cast<int>(factor));
    ImportScaled(factor, id);
    const v1::FitGridResponse fit = Fit(id, spec);
    const v1::FitReport& r = fit.report();
    EXPECT_NEAR(r.reference_length(), factor, 1e-9 * factor);
    EXPECT_EQ(r.reference_length_source(), v1::REFERENCE_LENGTH_SOURCE_WALL);
    EXPECT_THAT(r.reference_length_description(), HasSubstr("largest extent of 1 wall"));
    ASSERT_TRUE(r.has_tolerances());
    EXPECT_NEAR(r.tolerances().wall(), 0.15e-3 * factor, 1e-12 * factor);
    EXPECT_NEAR(r.tolerances().interface(), 2e-3 * factor, 1e-12 * factor);
    EXPECT_NEAR(r.tolerances().outer(), 8e-3 * factor, 1e-12 * factor);
    EXPECT_EQ(r.tolerances().interior(), 0.0);  // none
    // The spec kept with the revision still says "defaults" (relative), not the lengths.
    const v1::Grid grid = client_->Get(id).value();
    EXPECT_EQ(grid.revision().fit_spec().boundary_tolerances().wall(), 0.0);
    EXPECT_EQ(grid.revision().report().reference_length(), r.reference_length());
    if (factor == 1.0) {
      chords = fit;
      continue;
    }
    EXPECT_EQ(fit.num_control_points(), chords.num_control_points()) << "x" << factor;
    EXPECT_EQ(r.bad_cells(), chords.report().bad_cells()) << "x" << factor;
    EXPECT_EQ(r.folded_cells(), chords.report().folded_cells()) << "x" << factor;
    EXPECT_EQ(r.tolerance_met(), chords.report().tolerance_met()) << "x" << factor;
  }
}

// reference_length overrides the detected chord; a tolerance given is a length.
TEST_F(ReferenceLengthServiceTest, GivenReferenceAndGivenTolerances) {
  ImportScaled(1000.0, "mm");
  v1::FitSpec spec;
  spec.mutable_boundary_tolerances()->set_wall(0.3);  // mm
  spec.set_reference_length(2000.0);
  spec.set_allow_folds(true);
  const v1::FitReport r = Fit("mm", spec).report();
  EXPECT_EQ(r.reference_length(), 2000.0);
  EXPECT_EQ(r.reference_length_source(), v1::REFERENCE_LENGTH_SOURCE_GIVEN);
  EXPECT_EQ(r.tolerances().wall(), 0.3);
  EXPECT_DOUBLE_EQ(r.tolerances().outer(), 8e-3 * 2000.0);
  const v1::FitSpec kept = client_->Get("mm").value().revision().fit_spec();
  EXPECT_EQ(kept.reference_length(), 2000.0);
  EXPECT_EQ(kept.boundary_tolerances().wall(), 0.3);
  EXPECT_EQ(kept.boundary_tolerances().outer(), 0.0);

  // One tolerance is absolute: no reference length with it, nor with control counts.
  v1::FitSpec tol;
  tol.set_tolerance(1.0);
  tol.set_reference_length(1000.0);
  absl::StatusOr<v1::FitGridResponse> refused = client_->Fit("mm", tol);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(refused.status().message()), HasSubstr("reference_length"));
  v1::FitSpec negative;
  negative.mutable_boundary_tolerances();
  negative.set_reference_length(-1.0);
  EXPECT_EQ(client_->Fit("mm", negative).status().code(), absl::StatusCode::kInvalidArgument);

  // A fit to control counts reports the reference length too, and no tolerances.
  v1::FitSpec ctl;
  ctl.mutable_control_counts()->set_i(40);
  ctl.mutable_control_counts()->set_j(20);
  ctl.set_allow_folds(true);
  const v1::FitGridResponse counts = Fit("mm", ctl);
  EXPECT_NEAR(counts.report().reference_length(), 1000.0, 1e-6);
  EXPECT_FALSE(counts.report().has_tolerances());
}

}  // namespace
}  // namespace splinegrid::testing
