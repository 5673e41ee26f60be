// The reference length of the default tolerances by kind (issue 13, point 1): detected from the
// walls, given, or the bounding box; and a grid in chords, millimetres and inches fitted alike.
#include "core/grid/reference_length.h"

#include <cmath>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/fit/grid_fit.h"
#include "core/grid/connectivity.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

MultiBlockGrid ReadShared(const std::string& relative) {
  absl::StatusOr<MultiBlockGrid> grid = ReadPlot3dFile(SharedDataPath(relative));
  EXPECT_TRUE(grid.ok()) << grid.status();
  return grid.ok() ? *std::move(grid) : MultiBlockGrid{};
}

MultiBlockGrid Scaled(MultiBlockGrid grid, double factor) {
  for (StructuredBlock& block : grid.blocks) {
    for (double& x : block.coords()) x *= factor;
  }
  return grid;
}

ReferenceLength Detect(const MultiBlockGrid& grid) {
  absl::StatusOr<Connectivity> connectivity = FindConnectivity(grid);
  EXPECT_TRUE(connectivity.ok()) << connectivity.status();
  absl::StatusOr<BoundaryKinds> kinds = ClassifyBoundaries(grid, *connectivity);
  EXPECT_TRUE(kinds.ok()) << kinds.status();
  return DetectReferenceLength(grid, *kinds);
}

// A 2D block of ni x nj points on [x0, x0 + w] x [0, h], clustered towards j = 0 when `wall`.
StructuredBlock Rectangle(int ni, int nj, double x0, double w, double h, bool wall) {
  StructuredBlock block({ni, nj, 1}, 2);
  for (int j = 0; j < nj; ++j) {
    const double t = static_cast<double>(j) / (nj - 1);
    const double y = h * (wall ? t * t * t * t : t);
    for (int i = 0; i < ni; ++i) {
      double* p = block.Point(i, j, 0);
      p[0] = x0 + w * i / (ni - 1);
      p[1] = y;
    }
  }
  return block;
}

constexpr char kC0012[] = "grids/n0012_225-65.p2dfmt";

TEST(ReferenceLengthTest, ChordOfTheNaca0012CGridInEveryUnit) {
  const MultiBlockGrid chords = ReadShared(kC0012);
  ASSERT_FALSE(chords.blocks.empty());
  for (double factor : {1.0, 1000.0, 39.37}) {
    const ReferenceLength r = Detect(Scaled(chords, factor));
    EXPECT_EQ(r.source, ReferenceLengthSource::kWall) << factor;
    EXPECT_NEAR(r.length, factor, 1e-9 * factor) << r.description;
    EXPECT_THAT(r.description, HasSubstr("largest extent of 1 wall"));
  }
}

TEST(ReferenceLengthTest, NoWallIsTheBoundingBoxDiagonal) {
  MultiBlockGrid grid;
  grid.blocks.push_back(Rectangle(9, 7, 0.0, 3.0, 4.0, /*wall=*/false));
  const ReferenceLength r = Detect(grid);
  EXPECT_EQ(r.source, ReferenceLengthSource::kBoundingBox);
  EXPECT_DOUBLE_EQ(r.length, 5.0);
  EXPECT_THAT(r.description, HasSubstr("no wall point"));
}

TEST(ReferenceLengthTest, LargestOfSeparateWallsAndJoinedAcrossBlocks) {
  // Two blocks side by side, both clustered to j = 0: their walls meet at x = 2 and are one wall
  // of extent 5; a third block apart (x in [10, 11]) is a wall of its own.
  MultiBlockGrid grid;
  grid.blocks.push_back(Rectangle(9, 17, 0.0, 2.0, 1.0, true));
  grid.blocks.push_back(Rectangle(9, 17, 2.0, 3.0, 1.0, true));
  grid.blocks.push_back(Rectangle(9, 17, 10.0, 1.0, 1.0, true));
  const ReferenceLength r = Detect(grid);
  EXPECT_EQ(r.source, ReferenceLengthSource::kWall);
  EXPECT_NEAR(r.length, 5.0, 1e-12) << r.description;
  EXPECT_THAT(r.description, HasSubstr("of 2 walls"));
  // The joined wall's points come from both blocks (it said "from block 0").
  EXPECT_THAT(r.description, HasSubstr("18 points from 2 blocks (0, 1)"));
}

TEST(ReferenceLengthTest, ScaleTolerancesScalesOnlyTheRelativeKinds) {
  BoundaryTolerances t;
  const BoundaryTolerances all = ScaleTolerances(t, kAllKindsRelative, 1000.0);
  EXPECT_DOUBLE_EQ(all.wall, 0.15);
  EXPECT_DOUBLE_EQ(all.interface, 2.0);
  EXPECT_DOUBLE_EQ(all.outer, 8.0);
  EXPECT_TRUE(std::isinf(all.interior));
  EXPECT_DOUBLE_EQ(all.edge, t.edge);
  t.wall = 1e-4;
  const BoundaryTolerances mixed = ScaleTolerances(t, kAllKindsRelative & ~kRelativeWall, 10.0);
  EXPECT_DOUBLE_EQ(mixed.wall, 1e-4);
  EXPECT_DOUBLE_EQ(mixed.outer, 8e-2);
}

TEST(ReferenceLengthTest, ValidateRefusesAReferenceWithoutRelativeTolerances) {
  MultiBlockGrid grid;
  grid.blocks.push_back(Rectangle(9, 7, 0.0, 1.0, 1.0, false));
  GridFitOptions options;
  options.reference_length = 1.0;
  EXPECT_THAT(std::string(options.Validate(grid).message()),
              HasSubstr("a fit to control counts has none"));
  options.tolerance = 1e-3;
  EXPECT_THAT(std::string(options.Validate(grid).message()),
              HasSubstr("tolerance is a length in the grid's unit"));
  options.tolerance.reset();
  options.boundary_tolerances = BoundaryTolerances();
  EXPECT_TRUE(options.Validate(grid).ok());
  for (double bad : {0.0, -1.0, std::nan(""), HUGE_VAL}) {
    options.reference_length = bad;
    EXPECT_EQ(options.Validate(grid).code(), absl::StatusCode::kInvalidArgument) << bad;
  }
}

// Default tolerances by kind on the NACA 0012 C-grid in chords, millimetres and inches: the
// same control count, the same bad and folded cells, and the tolerances scale with the chord.
TEST(ReferenceLengthTest, SameFitInChordsMillimetresAndInches) {
  const MultiBlockGrid chords = ReadShared(kC0012);
  ASSERT_FALSE(chords.blocks.empty());
  GridFitOptions options;
  options.boundary_tolerances = BoundaryTolerances();
  options.allow_folds = true;  // compare what the fits reach, folded or not
  int64_t controls = -1, bad = -1, folded = -1;
  for (double factor : {1.0, 1000.0, 39.37}) {
    absl::StatusOr<GridFit> fit = FitGrid(Scaled(chords, factor), options);
    ASSERT_TRUE(fit.ok()) << fit.status();
    const GridFitReport& r = fit->report;
    EXPECT_EQ(r.reference.source, ReferenceLengthSource::kWall);
    EXPECT_NEAR(r.reference.length, factor, 1e-9 * factor);
    ASSERT_TRUE(r.tolerances.has_value());
    EXPECT_NEAR(r.tolerances->wall, 0.15e-3 * factor, 1e-12 * factor);
    EXPECT_NEAR(r.tolerances->outer, 8e-3 * factor, 1e-12 * factor);
    int64_t b = 0, f = 0;
    for (const BlockFit& block : fit->blocks)
      b += block.quality.num_bad_cells, f += block.quality.folded;
    std::printf("x%g: %lld controls, %lld bad cells, %lld folded sub-cells, wall dev %.3g\n",
                factor, static_cast<long long>(r.num_control_points), static_cast<long long>(b),
                static_cast<long long>(f), fit->blocks[0].deviation_by_kind.wall / factor);
    if (controls < 0) {
      controls = r.num_control_points, bad = b, folded = f;
      continue;
    }
    EXPECT_EQ(r.num_control_points, controls) << "x" << factor;
    EXPECT_EQ(b, bad) << "x" << factor;
    EXPECT_EQ(f, folded) << "x" << factor;
  }
}

TEST(ReferenceLengthTest, GivenReferenceAndAbsoluteKinds) {
  const MultiBlockGrid mm = Scaled(ReadShared(kC0012), 1000.0);
  GridFitOptions options;
  options.boundary_tolerances = BoundaryTolerances();
  options.boundary_tolerances->wall = 0.3;  // mm, absolute
  options.relative_kinds = kAllKindsRelative & ~kRelativeWall;
  options.reference_length = 500.0;
  options.allow_folds = true;
  absl::StatusOr<GridFit> fit = FitGrid(mm, options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_EQ(fit->report.reference.source, ReferenceLengthSource::kGiven);
  EXPECT_DOUBLE_EQ(fit->report.reference.length, 500.0);
  ASSERT_TRUE(fit->report.tolerances.has_value());
  EXPECT_DOUBLE_EQ(fit->report.tolerances->wall, 0.3);
  EXPECT_DOUBLE_EQ(fit->report.tolerances->interface, 2e-3 * 500.0);
  EXPECT_DOUBLE_EQ(fit->report.tolerances->outer, 8e-3 * 500.0);
}

TEST(ReferenceLengthTest, ControlCountFitsReportTheDetectedReference) {
  const MultiBlockGrid mm = Scaled(ReadShared(kC0012), 1000.0);
  GridFitOptions options;
  options.control_counts = {40, 20, 1};
  options.allow_folds = true;
  absl::StatusOr<GridFit> fit = FitGrid(mm, options);
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_NEAR(fit->report.reference.length, 1000.0, 1e-6);
  EXPECT_FALSE(fit->report.tolerances.has_value());
}

}  // namespace
}  // namespace splinegrid
