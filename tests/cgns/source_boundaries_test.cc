// Source boundary conditions (core/grid/source_boundaries.h) and the validation of the CGNS
// decoder's output (proto/convert/source_boundaries_convert.h), which the server treats as
// untrusted input.
#include "core/grid/source_boundaries.h"

#include <cmath>
#include <limits>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "proto/convert/source_boundaries_convert.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

TEST(SourceBoundariesTest, ExplicitFaceKindsWinOverTheFilesDefaults) {
  const std::vector<FaceKindOverride> defaults = {{Face{0, 1, false}, BoundaryKind::kWall},
                                                  {Face{0, 1, true}, BoundaryKind::kOuter}};
  const std::vector<FaceKindOverride> merged =
      WithDefaultFaceKinds({{Face{0, 1, false}, BoundaryKind::kOuter}}, defaults);
  ASSERT_EQ(merged.size(), 2u);
  EXPECT_EQ(merged[0].face, (Face{0, 1, false}));
  EXPECT_EQ(merged[0].kind, BoundaryKind::kOuter);  // given, not the file's wall
  EXPECT_EQ(merged[1].face, (Face{0, 1, true}));
  EXPECT_EQ(merged[1].kind, BoundaryKind::kOuter);
  EXPECT_EQ(WithDefaultFaceKinds({}, defaults).size(), 2u);
}

TEST(SourceBoundariesTest, TightestKindPerFaceAndANoteOnlyForMixedFaces) {
  std::vector<SourceBoundary> conditions = {
      {FaceRange{Face{0, 0, false}, {0, 0, 0}, {0, 4, 0}}, BoundaryKind::kOuter, "in", "BCInflow",
       ""},
      {FaceRange{Face{0, 0, false}, {0, 4, 0}, {0, 8, 0}}, BoundaryKind::kInterface, "sym",
       "BCSymmetryPlane", ""},
      {FaceRange{Face{0, 1, false}, {0, 0, 0}, {8, 0, 0}}, BoundaryKind::kWall, "w", "BCWall", ""}};
  std::vector<std::string> notes;
  const std::vector<FaceKindOverride> kinds = FaceKindsOf(conditions, {"main"}, &notes);
  ASSERT_EQ(kinds.size(), 2u);
  EXPECT_EQ(kinds[0].kind, BoundaryKind::kInterface);  // i=0: interface is tighter than outer
  EXPECT_EQ(kinds[1].kind, BoundaryKind::kWall);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_THAT(notes[0], HasSubstr("block 0 ('main') i=0"));
  EXPECT_THAT(notes[0], HasSubstr("fitted as interface"));
}

TEST(SourceBoundariesTest, RangesOffTheirFaceAreRefusedNamingTheField) {
  SourceBoundaries b;
  b.conditions = {
      {FaceRange{Face{0, 0, true}, {3, 0, 0}, {3, 9, 0}}, BoundaryKind::kWall, "w", "BCWall", ""}};
  const std::vector<Extents> blocks = {{5, 9, 1}};
  absl::Status status = ValidateSourceBoundaries(b, blocks, "boundaries");
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("boundaries.conditions[0].range"));
  b.conditions[0].range = FaceRange{Face{0, 0, true}, {4, 0, 0}, {4, 8, 0}};
  EXPECT_TRUE(ValidateSourceBoundaries(b, blocks, "boundaries").ok());
  b.conditions[0].range.face.block = 1;
  EXPECT_THAT(ValidateSourceBoundaries(b, blocks, "boundaries").message(),
              HasSubstr("block = 1 is outside [0, 0]"));
  b.conditions[0].range = FaceRange{Face{0, 2, false}, {0, 0, 0}, {4, 8, 0}};
  EXPECT_THAT(ValidateSourceBoundaries(b, blocks, "boundaries").message(),
              HasSubstr("is not a face of block 0"));
  b.conditions.clear();
  b.block_names = {"a", "b"};
  EXPECT_THAT(ValidateSourceBoundaries(b, blocks, "boundaries").message(),
              HasSubstr("2 names for 1 blocks"));
}

// A valid decoder output: one 3 x 2 planar zone with a wall on j=0.
v1::CgnsDecoded ValidDecoded() {
  v1::CgnsDecoded d;
  d.set_spatial_dim(2);
  d.set_format("cgns hdf5, 2d, 1 zone, double");
  v1::CgnsZone* zone = d.add_zones();
  zone->mutable_extents()->set_i(3);
  zone->mutable_extents()->set_j(2);
  zone->mutable_extents()->set_k(1);
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 3; ++i) {
      zone->add_coords(i);
      zone->add_coords(j);
    }
  }
  d.mutable_boundaries()->add_block_names("z");
  v1::SourceBoundary* c = d.mutable_boundaries()->add_conditions();
  c->mutable_range()->set_block(0);
  c->mutable_range()->set_face(v1::BLOCK_FACE_J_MIN);
  c->mutable_range()->mutable_begin();  // (0, 0, 0), present as the encoder writes it
  c->mutable_range()->mutable_end()->set_i(2);
  c->set_kind(v1::BOUNDARY_KIND_WALL);
  c->set_name("wall");
  c->set_bc_type("BCWall");
  d.mutable_boundaries()->set_base_name("Airfoil");
  d.mutable_boundaries()->set_data_class("Dimensional");
  for (const char* unit : {"Kilogram", "Meter", "Second", "Kelvin", "Radian"}) {
    d.mutable_boundaries()->add_dimensional_units(unit);
  }
  return d;
}

TEST(CgnsDecodedTest, ValidOutputParsesAndEncodesBack) {
  absl::StatusOr<ImportedGrid> grid = ParseCgnsDecoded(ValidDecoded());
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_EQ(grid->grid.blocks[0].Point(2, 1, 0)[0], 2.0);
  ASSERT_EQ(grid->boundaries.conditions.size(), 1u);
  EXPECT_EQ(grid->boundaries.base_name, "Airfoil");
  EXPECT_EQ(grid->boundaries.units[1], "Meter");
  v1::CgnsDecoded again;
  EncodeCgnsDecoded(*grid, &again);
  EXPECT_EQ(again.SerializeAsString(), ValidDecoded().SerializeAsString());
}

TEST(CgnsDecodedTest, HostileOutputIsInvalidArgumentNamingTheField) {
  auto expect_refused = [](v1::CgnsDecoded d, const std::string& what) {
    absl::StatusOr<ImportedGrid> grid = ParseCgnsDecoded(d);
    EXPECT_EQ(grid.status().code(), absl::StatusCode::kInvalidArgument) << what;
    EXPECT_THAT(grid.status().message(), HasSubstr(what));
  };
  v1::CgnsDecoded d = ValidDecoded();
  d.set_spatial_dim(4);
  expect_refused(d, "spatial_dim = 4");
  d = ValidDecoded();
  d.mutable_zones(0)->mutable_coords()->RemoveLast();
  expect_refused(d, "zone 0: 11 coordinates for 6 points");
  d = ValidDecoded();
  d.mutable_zones(0)->set_coords(3, std::numeric_limits<double>::quiet_NaN());
  expect_refused(d, "zone 0");
  d = ValidDecoded();
  d.mutable_zones(0)->mutable_extents()->set_i(-3);
  expect_refused(d, "zone 0");
  d = ValidDecoded();
  d.mutable_boundaries()->mutable_conditions(0)->mutable_range()->mutable_end()->set_i(7);
  expect_refused(d, "boundaries.conditions[0].range");
  d = ValidDecoded();
  d.mutable_boundaries()->mutable_conditions(0)->set_kind(static_cast<v1::BoundaryKind>(9));
  expect_refused(d, "boundaries.conditions[0].kind = 9");
  d = ValidDecoded();
  d.mutable_boundaries()->mutable_conditions(0)->set_name(std::string(300, 'x'));
  expect_refused(d, "boundaries.conditions[0].name is longer than 256 bytes");
  d = ValidDecoded();
  d.mutable_boundaries()->mutable_dimensional_units()->RemoveLast();
  expect_refused(d, "boundaries.dimensional_units has 4 entries; give none or five");
  d = ValidDecoded();
  d.mutable_boundaries()->set_base_name(std::string(33, 'b'));
  expect_refused(d, "boundaries.base_name is 33 bytes; a CGNS name has at most 32");
  d = ValidDecoded();
  v1::CgnsConnection* c = d.add_connections();
  c->mutable_range()->set_face(v1::BLOCK_FACE_I_MIN);
  c->mutable_range()->mutable_end()->set_j(1);
  c->mutable_donor()->set_face(v1::BLOCK_FACE_I_MAX);
  c->mutable_donor()->mutable_begin()->set_i(2);
  c->mutable_donor()->mutable_end()->set_i(2);
  c->mutable_donor()->mutable_end()->set_j(1);
  c->add_transform(1);
  c->add_transform(7);
  c->add_transform(3);
  expect_refused(d, "connections[0].transform[1] = 7");
  d.clear_zones();
  expect_refused(d, "no zone");
}

}  // namespace
}  // namespace splinegrid
