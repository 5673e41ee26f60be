// GenerateGrid off a stored surface through the service: the shared ONERA M6 wing (9 surface
// blocks) marched to 5 chords' distance, stored and fitted; checked here independently of the
// marcher: every hexahedron right-handed at levels 0 and 1 of the fitted grid (level 2, 34
// million points, through the fit's own check of levels 0-2), the blocks' faces found matching
// again at level 1 (watertight between the grid points too), the root on z = 0; and every bad
// request refused by name with nothing stored.
#include <algorithm>
#include <cmath>

#include "core/grid/connectivity.h"
#include "gmock/gmock.h"
#include "tests/core/hexahedron_checks.h"
#include "tests/core/wedge_surface.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::testing {
namespace {

using ::testing::HasSubstr;

// The request: splinegrid offset m6 --layers 32 --first 1e-4 --far 5.
v1::GenerateGridRequest M6Request(const std::string& id) {
  v1::GenerateGridRequest r;
  r.set_grid_id(id);
  r.mutable_stored_surface()->set_name("grids/m6");
  r.set_layers(32);
  r.set_first_height(1e-4);
  r.set_distance(5.0);
  return r;
}

class GenerateVolumeTest : public ServiceTest {
 protected:
  MultiBlockGrid Evaluate(const std::string& id, int level) {
    v1::EvaluateGridRequest request;
    request.set_name("grids/" + id);
    request.set_refinement_level(level);
    absl::StatusOr<client::EvaluatedGrid> evaluated = client_->Evaluate(request);
    EXPECT_TRUE(evaluated.ok()) << evaluated.status();
    MultiBlockGrid grid;
    if (!evaluated.ok()) return grid;
    for (client::EvaluatedBlock& block : evaluated->blocks) {
      grid.blocks.push_back(std::move(block.points));
    }
    return grid;
  }

  // Imports `surface` as grids/`name`, fits it by interpolation and marches 16 layers (1e-3 to
  // 0.3) along its normals, into the L, as grids/`name`-volume; checks the crease report (33
  // vertices, smallest scaled Jacobian sin 45) and returns the volume at level 1.
  MultiBlockGrid MarchIntoTheL(const MultiBlockGrid& surface, const std::string& name) {
    EXPECT_TRUE(client_->ImportPoints(surface, name, name).ok());
    EXPECT_TRUE(client_->Fit(name, v1::FitSpec()).ok());
    v1::GenerateGridRequest request;
    request.set_grid_id(name + "-volume");
    request.mutable_stored_surface()->set_name("grids/" + name);
    request.set_layers(16);
    request.set_first_height(1e-3);
    request.set_distance(0.3);
    request.set_side(v1::MARCH_SIDE_ALONG_NORMAL);
    request.set_symmetry_planes(false);
    const absl::StatusOr<v1::GenerateGridResponse> r = client_->Generate(request);
    EXPECT_TRUE(r.ok()) << r.status();
    if (!r.ok()) return {};
    EXPECT_EQ(r->report().volume().crease_vertices(), 33);
    EXPECT_GT(r->report().volume().min_scaled_jacobian(), 0.99 * std::sqrt(0.5));
    return Evaluate(name + "-volume", 1);
  }
};

TEST_F(GenerateVolumeTest, M6WingToFiveIsWatertightAndFoldsNothing) {
  ImportShared("surfaces/m6_small.fmt", "m6");
  ASSERT_TRUE(client_->Fit("m6", v1::FitSpec()).ok());
  const v1::GenerateGridResponse r = client_->Generate(M6Request("m6-volume")).value();
  const v1::VolumeReport& v = r.report().volume();
  EXPECT_EQ(v.blocks(), 9);
  EXPECT_EQ(v.components(), 1);
  ASSERT_EQ(v.symmetry_planes_size(), 1);
  EXPECT_EQ(v.symmetry_planes(0).axis(), "z");
  EXPECT_GT(v.min_scaled_jacobian(), 0.0);
  EXPECT_EQ(v.crease_vertices(), 0);  // its edges are convex
  EXPECT_EQ(r.report().parameters().side(), v1::MARCH_SIDE_OUTWARD);
  EXPECT_EQ(r.report().parameters().normal_smoothing(), 80);
  EXPECT_EQ(r.fit().report().folded_cells(), 0);
  EXPECT_LT(r.fit().report().max_gap(), 1e-12);  // measured 1.8e-15
  const int matches = r.grid().source().num_matches();
  EXPECT_GE(matches, 16);  // the surface's 16 edges, now faces

  for (int level = 0; level <= 1; ++level) {
    SCOPED_TRACE(::testing::Message() << "level " << level);
    const MultiBlockGrid grid = Evaluate("m6-volume", level);
    ASSERT_EQ(grid.blocks.size(), 9u);
    int64_t root_points = 0;
    for (size_t b = 0; b < grid.blocks.size(); ++b) {
      const StructuredBlock& block = grid.blocks[b];
      EXPECT_EQ(block.extent(2), 32 * (1 << level) + 1);
      EXPECT_GT(MinCornerJacobian(block), 0.0) << "block " << b;  // right-handed, none folded
      // The root (z = 0 on the surface) stays on z = 0 outward.
      for (int j = 0; j < block.extent(1); ++j) {
        for (int i = 0; i < block.extent(0); ++i) {
          if (block.Point(i, j, 0)[2] != 0.0) continue;
          ++root_points;
          for (int k = 0; k < block.extent(2); ++k) {
            ASSERT_NEAR(block.Point(i, j, k)[2], 0.0, 1e-12) << "block " << b;
          }
        }
      }
    }
    // The root edges of blocks 0-3 (17 + 73 + 17 + 73 points at level 0).
    EXPECT_EQ(root_points, 180 * (1 << level) - 4 * ((1 << level) - 1));
    // Watertight at the level: the faces match again, point for point.
    const absl::StatusOr<Connectivity> found = FindConnectivity(grid);
    ASSERT_TRUE(found.ok()) << found.status();
    EXPECT_EQ(static_cast<int>(found->matches.size()), matches);
  }
}

// The inside of an L (the right-angled wedge, wedge_surface.h, the crease along y): the
// march reports the crease's 33 vertices, and the stored grid at level 1 is right-handed
// everywhere with every layer's crease point on the bisector.
TEST_F(GenerateVolumeTest, ConcaveCreaseIsReportedAndMarchedApart) {
  const MultiBlockGrid grid = MarchIntoTheL(Wedge(90.0), "l");
  ASSERT_EQ(grid.blocks.size(), 2u);
  for (size_t b = 0; b < grid.blocks.size(); ++b) {
    EXPECT_GT(MinCornerJacobian(grid.blocks[b]), 0.0) << "block " << b;
  }
  // Block 0's i = 0 is the crease: on the bisector x = z at every layer.
  const StructuredBlock& block = grid.blocks[0];
  for (int k = 1; k < block.extent(2); ++k) {
    const double* x = block.Point(0, block.extent(1) / 2, k);
    EXPECT_NEAR(x[0], x[2], 1e-9) << "layer " << k;
    EXPECT_GT(x[0], 0.0) << "layer " << k;
  }
}

// The same L as one block kinked along its grid line i = 32: the march finds the kink and treats
// it as the crease between two blocks, and the volume's fit keeps it (a C0 knot line at the
// kink of its boundary lines), so no hexahedron folds at level 1 beside it either. Before, the
// march folded at layer 15 of 16.
TEST_F(GenerateVolumeTest, ACreaseInsideOneBlockIsMarchedApart) {
  const MultiBlockGrid grid = MarchIntoTheL(FoldedWedge(90.0), "l1");
  ASSERT_EQ(grid.blocks.size(), 1u);
  EXPECT_GT(MinCornerJacobian(grid.blocks[0]), 0.0);
  // The crease, i = 64 at level 1: on the bisector x = z at every layer.
  const StructuredBlock& block = grid.blocks[0];
  ASSERT_EQ(block.extent(0), 129);
  for (int k = 1; k < block.extent(2); ++k) {
    const double* x = block.Point(64, block.extent(1) / 2, k);
    EXPECT_NEAR(x[0], x[2], 1e-9) << "layer " << k;
    EXPECT_GT(x[0], 0.0) << "layer " << k;
  }
}

TEST_F(GenerateVolumeTest, BadRequestsAreRefusedByNameAndNothingIsStored) {
  ImportShared("surfaces/m6_small.fmt", "m6");
  ASSERT_TRUE(client_->Fit("m6", v1::FitSpec()).ok());
  ImportShared("grids/n0012_113-33.p2dfmt", "planar");
  v1::FitSpec ok_with_folds;
  ok_with_folds.set_allow_folds(true);
  ASSERT_TRUE(client_->Fit("planar", ok_with_folds).ok());

  v1::GenerateGridRequest r = M6Request("bad");
  r.mutable_stored_surface()->set_name("grids/planar");
  ExpectGenerateRefused(
      r, absl::StatusCode::kInvalidArgument,
      "stored_surface.name: block 0 of grids/planar revision 1 is 113x33x1 with 2 "
      "coordinates");
  r.mutable_stored_surface()->set_name("grids/none");
  ExpectGenerateRefused(r, absl::StatusCode::kNotFound, "grids/none");
  r = M6Request("bad");
  r.mutable_stored_surface()->set_revision(7);
  ExpectGenerateRefused(r, absl::StatusCode::kNotFound, "revision 7");
  r = M6Request("bad");
  r.set_method(v1::LAYER_METHOD_ELLIPTIC);
  ExpectGenerateRefused(r, absl::StatusCode::kInvalidArgument, "method = LAYER_METHOD_ELLIPTIC");
  r = M6Request("bad");
  r.set_wall_points(129);
  ExpectGenerateRefused(r, absl::StatusCode::kInvalidArgument, "wall_points is set");
  r = M6Request("bad");
  r.set_first_height(std::nan(""));
  ExpectGenerateRefused(r, absl::StatusCode::kInvalidArgument, "first_height = nan");
  r = M6Request("bad");
  r.set_normal_smoothing(-1);
  ExpectGenerateRefused(r, absl::StatusCode::kInvalidArgument, "normal_smoothing = -1");
  r = M6Request("bad");
  r.set_side(static_cast<v1::MarchSide>(9));
  ExpectGenerateRefused(r, absl::StatusCode::kInvalidArgument, "side = 9");
  // Far beyond what the wing's layers can reach: the march refuses, nothing is stored.
  r = M6Request("bad");
  r.set_distance(1e9);
  ExpectGenerateRefused(r, absl::StatusCode::kFailedPrecondition, "layer");
  // The march's fields on a profile request.
  v1::GenerateGridRequest profile;
  profile.set_grid_id("bad");
  profile.set_airfoil_file(ReadFileToString(SharedDataPath("airfoils/naca0012.dat")).value());
  profile.set_normal_smoothing(40);
  ExpectGenerateRefused(profile, absl::StatusCode::kInvalidArgument,
                        "normal_smoothing is set: it applies to a stored_surface");
  // The name is taken.
  r = M6Request("m6");
  ExpectGenerateRefused(r, absl::StatusCode::kAlreadyExists, "grids/m6 already exists");
}

TEST_F(GenerateVolumeTest, SizeOverTheServersCapIsOutOfRange) {
  options_.max_output_points = 100000;
  StartServer();
  ImportShared("surfaces/m6_small.fmt", "m6");
  ASSERT_TRUE(client_->Fit("m6", v1::FitSpec()).ok());
  ExpectGenerateRefused(M6Request("big"), absl::StatusCode::kOutOfRange,
                        "surface points * (layers + 1) = 528033 points");
}

}  // namespace
}  // namespace splinegrid::testing
