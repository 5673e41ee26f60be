// The CGNS reader and writer (io/cgns) on files written by Debian's plot3d_to_cgns, by the
// CGNS mid-level library directly, and by the writer itself.
#include "io/cgns/cgns_io.h"

#include <cgnslib.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "absl/strings/match.h"
#include "absl/strings/str_join.h"
#include "core/io/file_util.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/cgns/cgns_test_util.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::splinegrid::testing::TempDir;
using ::testing::AllOf;
using ::testing::Contains;
using ::testing::HasSubstr;
using ::testing::Not;

// Single precision keeps about 7 significant digits; the grids are O(1)..O(500) in size.
constexpr double kSingleRelative = 1e-6;

TEST(CgnsBcKindsTest, MapsTheSidsTypes) {
  EXPECT_EQ(KindOfBcType("BCWall"), BoundaryKind::kWall);
  EXPECT_EQ(KindOfBcType("BCWallViscousHeatFlux"), BoundaryKind::kWall);
  EXPECT_EQ(KindOfBcType("BCWallInviscid"), BoundaryKind::kWall);
  EXPECT_EQ(KindOfBcType("BCFarfield"), BoundaryKind::kOuter);
  EXPECT_EQ(KindOfBcType("BCInflowSubsonic"), BoundaryKind::kOuter);
  EXPECT_EQ(KindOfBcType("BCOutflowSupersonic"), BoundaryKind::kOuter);
  EXPECT_EQ(KindOfBcType("BCTunnelInflow"), BoundaryKind::kOuter);
  EXPECT_EQ(KindOfBcType("BCExtrapolate"), BoundaryKind::kOuter);
  EXPECT_EQ(KindOfBcType("BCDegeneratePoint"), BoundaryKind::kOuter);
  EXPECT_EQ(KindOfBcType("BCSymmetryPlane"), BoundaryKind::kInterface);
  EXPECT_EQ(KindOfBcType("BCTypeUserDefined"), std::nullopt);
  EXPECT_EQ(KindOfBcType("FamilySpecified"), std::nullopt);
  EXPECT_EQ(KindOfBcType("Wall"), std::nullopt);
}

TEST(CgnsReaderTest, Plot3dToCgnsMultiBlockMatchesThePlot3dFile) {
  TempDir dir("cgns-io");
  const std::string plot3d = SharedDataPath("surfaces/m6_small.fmt");
  testing::Plot3dToCgns(plot3d, dir.File("m6.cgns"), "-d");
  absl::StatusOr<ImportedGrid> cgns = ReadCgnsFile(dir.File("m6.cgns"));
  ASSERT_TRUE(cgns.ok()) << cgns.status();
  absl::StatusOr<MultiBlockGrid> reference = ReadPlot3dFile(plot3d);
  ASSERT_TRUE(reference.ok()) << reference.status();
  ASSERT_EQ(cgns->grid.blocks.size(), 9u);
  EXPECT_EQ(testing::MaxDifference(cgns->grid, *reference), 0.0);  // doubles, bitwise
  EXPECT_THAT(cgns->format, HasSubstr("9 zones, double"));
  EXPECT_THAT(cgns->format, HasSubstr("hdf5"));
  EXPECT_TRUE(cgns->boundaries.conditions.empty());
  EXPECT_EQ(cgns->boundaries.block_names.size(), 9u);
}

// (plot3d_to_cgns misreads the Fortran repeat counts "2*20." of the CFL3D files, so the
// single-precision file is made from the M6 surfaces.)
TEST(CgnsReaderTest, SinglePrecisionFileMatchesThePlot3dFileToFloatRounding) {
  TempDir dir("cgns-io");
  const std::string plot3d = SharedDataPath("surfaces/m6_small.fmt");
  testing::Plot3dToCgns(plot3d, dir.File("m6s.cgns"), "");  // no -d: RealSingle
  absl::StatusOr<ImportedGrid> cgns = ReadCgnsFile(dir.File("m6s.cgns"));
  ASSERT_TRUE(cgns.ok()) << cgns.status();
  absl::StatusOr<MultiBlockGrid> reference = ReadPlot3dFile(plot3d);
  ASSERT_TRUE(reference.ok()) << reference.status();
  EXPECT_THAT(cgns->format, HasSubstr("9 zones, single"));
  ASSERT_EQ(cgns->grid.blocks.size(), reference->blocks.size());
  double extent = 0.0;
  for (const StructuredBlock& b : reference->blocks) {
    for (double v : b.coords()) extent = std::max(extent, std::abs(v));
  }
  const double difference = testing::MaxDifference(cgns->grid, *reference);
  EXPECT_GT(difference, 0.0);  // it was rounded to float
  EXPECT_LE(difference, kSingleRelative * extent);
}

TEST(CgnsWriterTest, CGridRoundTripKeepsPointsConditionsFamiliesAndTheWakeCut) {
  TempDir dir("cgns-io");
  absl::StatusOr<MultiBlockGrid> grid = ReadPlot3dFile(SharedDataPath("grids/n0012_113-33.p2dfmt"));
  ASSERT_TRUE(grid.ok()) << grid.status();
  absl::StatusOr<Connectivity> connectivity = FindConnectivity(*grid);
  ASSERT_TRUE(connectivity.ok());
  ASSERT_EQ(connectivity->matches.size(), 1u);  // the wake cut
  CgnsWriteOptions options;
  options.source_extents = {grid->blocks[0].extents()};
  options.block_names = {"naca"};
  options.conditions = testing::CGridConditions(*grid, *connectivity);
  options.matches = connectivity->matches;
  std::vector<std::string> notes;
  ASSERT_TRUE(WriteCgnsFile(dir.File("c.cgns"), *grid, options, &notes).ok());
  EXPECT_TRUE(notes.empty());

  absl::StatusOr<ImportedGrid> back = ReadCgnsFile(dir.File("c.cgns"));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(testing::MaxDifference(back->grid, *grid), 0.0);
  EXPECT_EQ(back->grid.blocks[0].spatial_dim(), 2);
  EXPECT_THAT(back->format, HasSubstr("2d, 1 zone, double"));
  EXPECT_EQ(back->boundaries.block_names, std::vector<std::string>{"naca"});
  ASSERT_EQ(back->boundaries.conditions.size(), options.conditions.size());
  for (size_t q = 0; q < options.conditions.size(); ++q) {
    const SourceBoundary& want = options.conditions[q];
    const SourceBoundary& got = back->boundaries.conditions[q];
    EXPECT_EQ(got.name, want.name);
    EXPECT_EQ(got.bc_type, want.bc_type);
    EXPECT_EQ(got.family, want.family);
    EXPECT_EQ(got.kind, want.kind);
    EXPECT_EQ(got.range.face, want.range.face) << want.name;
    EXPECT_EQ(got.range.begin, want.range.begin) << want.name;
    EXPECT_EQ(got.range.end, want.range.end) << want.name;
  }
  // The face kinds: the wall face j=0, outer elsewhere; no mixed face, no note.
  EXPECT_TRUE(back->boundaries.notes.empty()) << back->boundaries.notes.front();
  ASSERT_EQ(back->boundaries.face_kinds.size(), 4u);
  for (const FaceKindOverride& k : back->boundaries.face_kinds) {
    const bool wall = k.face.normal == 1 && !k.face.upper;
    EXPECT_EQ(k.kind, wall ? BoundaryKind::kWall : BoundaryKind::kOuter) << FaceName(k.face);
  }
  // Both sides of the wake cut, agreeing with the connectivity found in the points.
  ASSERT_EQ(back->connections.size(), 2u);
  absl::StatusOr<Connectivity> found = FindConnectivity(back->grid);
  ASSERT_TRUE(found.ok());
  EXPECT_TRUE(CompareConnections(back->connections, *found, {}).empty());
  // The transform maps the range's first point onto the donor's: a reversed i (-1), j mirrored
  // across the cut (-2).
  EXPECT_EQ(back->connections[0].transform[0], -1);
  EXPECT_EQ(back->connections[0].transform[1], -2);
}

TEST(CgnsWriterTest, VolumeRoundTripIsCheckedCleanByCgnscheck) {
  TempDir dir("cgns-io");
  const MultiBlockGrid grid = testing::TwoBoxes();
  absl::StatusOr<Connectivity> connectivity = FindConnectivity(grid);
  ASSERT_TRUE(connectivity.ok());
  ASSERT_EQ(connectivity->matches.size(), 1u);
  CgnsWriteOptions options;
  options.source_extents = {grid.blocks[0].extents(), grid.blocks[1].extents()};
  options.conditions = {{FaceRange{Face{0, 0, false}, {0, 0, 0}, {0, 6, 4}}, BoundaryKind::kWall,
                         "wall", "BCWall", ""},
                        {FaceRange{Face{1, 0, true}, {8, 0, 0}, {8, 4, 6}}, BoundaryKind::kOuter,
                         "out", "BCOutflow", ""},
                        {FaceRange{Face{0, 2, false}, {0, 0, 0}, {8, 6, 0}},
                         BoundaryKind::kInterface, "sym", "BCSymmetryPlane", "mirror"}};
  options.matches = connectivity->matches;
  ASSERT_TRUE(WriteCgnsFile(dir.File("v.cgns"), grid, options, nullptr).ok());
  // Debian's checker of the standard (cgns-convert's cgnscheck) finds no error.
  const std::string report = testing::CgnsCheckReport(dir.File("v.cgns"));
  EXPECT_THAT(report, HasSubstr("checking complete")) << report;
  EXPECT_THAT(report, ::testing::Not(HasSubstr("ERROR"))) << report;
  EXPECT_THAT(report, ::testing::Not(HasSubstr(" errors"))) << report;

  absl::StatusOr<ImportedGrid> back = ReadCgnsFile(dir.File("v.cgns"));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(testing::MaxDifference(back->grid, grid), 0.0);
  EXPECT_THAT(back->format, HasSubstr("3d, 2 zones, double"));
  ASSERT_EQ(back->boundaries.conditions.size(), 3u);  // zone by zone: wall, sym, out
  EXPECT_EQ(back->boundaries.conditions[1].name, "sym");
  EXPECT_EQ(back->boundaries.conditions[1].family, "mirror");
  EXPECT_EQ(back->boundaries.conditions[1].bc_type, "BCSymmetryPlane");
  EXPECT_EQ(back->boundaries.conditions[1].kind, BoundaryKind::kInterface);
  ASSERT_EQ(back->boundaries.notes.size(), 1u);  // the symmetry choice, stated
  EXPECT_THAT(back->boundaries.notes[0], HasSubstr("BCSymmetryPlane"));
  ASSERT_EQ(back->connections.size(), 2u);
  absl::StatusOr<Connectivity> found = FindConnectivity(back->grid);
  ASSERT_TRUE(found.ok());
  EXPECT_TRUE(CompareConnections(back->connections, *found, {}).empty());
  // Block 0's i=max joins block 1's i=0; block 0's j runs along block 1's k and k along j.
  const StatedConnection& c = back->connections[0];
  EXPECT_EQ(c.range.face, (Face{0, 0, true}));
  EXPECT_EQ(c.donor.face, (Face{1, 0, false}));
  EXPECT_EQ(c.transform, (std::array<int, 3>{1, 3, 2}));
}

TEST(CgnsReaderTest, FaceWithWallAndOuterConditionsIsAWallWithANote) {
  TempDir dir("cgns-io");
  const MultiBlockGrid grid = testing::TwoBoxes();
  CgnsWriteOptions options;
  options.source_extents = {grid.blocks[0].extents(), grid.blocks[1].extents()};
  options.conditions = {{FaceRange{Face{0, 1, false}, {0, 0, 0}, {4, 0, 4}}, BoundaryKind::kWall,
                         "plate", "BCWallViscous", ""},
                        {FaceRange{Face{0, 1, false}, {4, 0, 0}, {8, 0, 4}}, BoundaryKind::kOuter,
                         "free", "BCFarfield", ""}};
  ASSERT_TRUE(WriteCgnsFile(dir.File("m.cgns"), grid, options, nullptr).ok());
  absl::StatusOr<ImportedGrid> back = ReadCgnsFile(dir.File("m.cgns"));
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->boundaries.face_kinds.size(), 1u);
  EXPECT_EQ(back->boundaries.face_kinds[0].kind, BoundaryKind::kWall);
  ASSERT_EQ(back->boundaries.notes.size(), 1u);
  EXPECT_THAT(back->boundaries.notes[0], HasSubstr("j=0"));
  EXPECT_THAT(back->boundaries.notes[0], HasSubstr("'plate' BCWallViscous (wall)"));
  EXPECT_THAT(back->boundaries.notes[0], HasSubstr("'free' BCFarfield (outer)"));
  EXPECT_THAT(back->boundaries.notes[0], HasSubstr("fitted as wall"));
}

// A 2D case stored as two planes (the shared CFL3D RAE 2822 grid, 2 x 257 x 97, y = 0 and -1)
// in a CGNS file is read as the volume it is, with a note saying so and how to get its 2D view;
// a genuine volume gets no such note.
TEST(CgnsReaderTest, ATwoPlaneZoneIsReadAsAVolumeWithANote) {
  TempDir dir("cgns-io");
  const MultiBlockGrid grid = ReadPlot3dFile(SharedDataPath("grids/rae2822_257x97.fmt")).value();
  CgnsWriteOptions options;
  options.source_extents = {grid.blocks[0].extents()};
  ASSERT_TRUE(WriteCgnsFile(dir.File("planes.cgns"), grid, options, nullptr).ok());
  absl::StatusOr<ImportedGrid> read = ReadCgnsFile(dir.File("planes.cgns"));
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(testing::MaxDifference(read->grid, grid), 0.0);
  EXPECT_THAT(read->boundaries.notes,
              Contains(AllOf(HasSubstr("zone 'block_0' is two planes (i = 1, 2) at y = 0 and -1"),
                             HasSubstr("cgns_to_plot3d"))));

  const MultiBlockGrid boxes = testing::TwoBoxes();
  options.source_extents = {boxes.blocks[0].extents(), boxes.blocks[1].extents()};
  ASSERT_TRUE(WriteCgnsFile(dir.File("boxes.cgns"), boxes, options, nullptr).ok());
  read = ReadCgnsFile(dir.File("boxes.cgns"));
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_THAT(read->boundaries.notes, Not(Contains(HasSubstr("two planes"))));
}

// The base's name, DataClass and DimensionalUnits come back as the source stated them; a source
// that stated none (Plot3D) is written as NormalizedByUnknownDimensional, and every coordinate
// with its DimensionalExponents (a length), so that cgnscheck warns of nothing (it warned
// "dataclass not given" for every coordinate array, 27 times for the M6 surfaces).
TEST(CgnsWriterTest, TheBasesNameDataClassAndUnitsComeBack) {
  TempDir dir("cgns-io");
  const MultiBlockGrid grid = testing::TwoBoxes();
  CgnsWriteOptions options;
  options.source_extents = {grid.blocks[0].extents(), grid.blocks[1].extents()};
  ASSERT_TRUE(WriteCgnsFile(dir.File("plain.cgns"), grid, options, nullptr).ok());
  absl::StatusOr<ImportedGrid> back = ReadCgnsFile(dir.File("plain.cgns"));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->boundaries.base_name, "Base");
  EXPECT_EQ(back->boundaries.data_class, "NormalizedByUnknownDimensional");
  EXPECT_TRUE(back->boundaries.units.empty());
  const std::string report = testing::CgnsCheckReport(dir.File("plain.cgns"));
  EXPECT_THAT(report, HasSubstr("checking complete")) << report;
  EXPECT_THAT(report, Not(HasSubstr("WARNING"))) << report;

  options.base_name = "Wing";
  options.data_class = "Dimensional";
  options.units = {"Kilogram", "Millimeter", "Second", "Kelvin", "Degree"};
  ASSERT_TRUE(WriteCgnsFile(dir.File("units.cgns"), grid, options, nullptr).ok());
  back = ReadCgnsFile(dir.File("units.cgns"));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->boundaries.base_name, "Wing");
  EXPECT_EQ(back->boundaries.data_class, "Dimensional");
  EXPECT_EQ(back->boundaries.units, options.units);
  const std::string units_report = testing::CgnsCheckReport(dir.File("units.cgns"));
  EXPECT_THAT(units_report, HasSubstr("checking complete")) << units_report;
  EXPECT_THAT(units_report, Not(HasSubstr("WARNING"))) << units_report;

  options.units[1] = "Furlong";
  const absl::Status bad = WriteCgnsFile(dir.File("bad.cgns"), grid, options, nullptr);
  EXPECT_EQ(bad.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.message(), HasSubstr("length unit 'Furlong' is not a CGNS name"));
}

TEST(CgnsWriterTest, RefusesBlocksThatAreNotALevelOfTheSource) {
  TempDir dir("cgns-io");
  const MultiBlockGrid grid = testing::TwoBoxes();
  CgnsWriteOptions options;
  options.index_scale = 2;  // the blocks would need 17 x 13 x 9 points
  options.source_extents = {grid.blocks[0].extents(), grid.blocks[1].extents()};
  const absl::Status status = WriteCgnsFile(dir.File("x.cgns"), grid, options, nullptr);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("refinement level"));
  EXPECT_FALSE(std::filesystem::exists(dir.File("x.cgns")));  // no partial file
}

TEST(CgnsWriterTest, AFailedWriteLeavesAnExistingFileAsItWasAndNoTemporaryFile) {
  TempDir dir("cgns-io");
  const MultiBlockGrid grid = testing::TwoBoxes();
  CgnsWriteOptions options;
  options.source_extents = {grid.blocks[0].extents(), grid.blocks[1].extents()};
  const std::string path = dir.File("keep.cgns");
  ASSERT_TRUE(WriteCgnsFile(path, grid, options, nullptr).ok());
  const std::string before = *ReadFileToString(path);
  // A write that fails after the file was opened (the blocks are not level 1 of the source).
  options.index_scale = 2;
  const absl::Status status = WriteCgnsFile(path, grid, options, nullptr);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(*ReadFileToString(path), before);
  absl::StatusOr<ImportedGrid> back = ReadCgnsFile(path);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(testing::MaxDifference(back->grid, grid), 0.0);
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.File(""))) {
    EXPECT_EQ(entry.path().filename(), "keep.cgns");  // no PATH.tmp-* left behind
    ++files;
  }
  EXPECT_EQ(files, 1);
  // A successful write replaces the file (through the rename).
  options.index_scale = 1;
  MultiBlockGrid one;
  one.blocks.push_back(grid.blocks[0]);
  options.source_extents = {grid.blocks[0].extents()};
  ASSERT_TRUE(WriteCgnsFile(path, one, options, nullptr).ok());
  back = ReadCgnsFile(path);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->grid.blocks.size(), 1u);
}

// Writing through a symbolic link replaces the file it names (the link stays) and an existing
// file keeps its permission bits.
TEST(CgnsWriterTest, AWriteThroughALinkReplacesItsTargetAndKeepsTheMode) {
  TempDir dir("cgns-io");
  const MultiBlockGrid grid = testing::TwoBoxes();
  CgnsWriteOptions options;
  options.source_extents = {grid.blocks[0].extents(), grid.blocks[1].extents()};
  std::filesystem::create_directories(dir.File("real"));
  const std::string target = dir.File("real/grid.cgns");
  ASSERT_TRUE(WriteCgnsFile(target, grid, options, nullptr).ok());
  std::filesystem::permissions(
      target, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  const std::string link = dir.File("link.cgns");
  std::filesystem::create_symlink(target, link);
  MultiBlockGrid one;
  one.blocks.push_back(grid.blocks[0]);
  options.source_extents = {grid.blocks[0].extents()};
  ASSERT_TRUE(WriteCgnsFile(link, one, options, nullptr).ok());
  EXPECT_TRUE(std::filesystem::is_symlink(link));
  absl::StatusOr<ImportedGrid> back = ReadCgnsFile(target);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->grid.blocks.size(), 1u);
  EXPECT_EQ(std::filesystem::status(target).permissions() & std::filesystem::perms::all,
            std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
}

// A base with one zone written by the mid-level library itself, for what the reader refuses.
void WriteOneZone(const std::string& path, bool unstructured, bool rind) {
  int fn = 0, base = 0, zone = 0, coord = 0;
  ASSERT_EQ(cg_open(path.c_str(), CG_MODE_WRITE, &fn), CG_OK) << cg_get_error();
  ASSERT_EQ(cg_base_write(fn, "Base", unstructured ? 3 : 2, unstructured ? 3 : 2, &base), CG_OK);
  std::vector<double> x(16, 0.0), y(16, 0.0), z(16, 0.0);
  for (int p = 0; p < 16; ++p) {
    x[p] = p % 4;
    y[p] = p / 4;
  }
  if (unstructured) {
    cgsize_t size[3] = {16, 3, 0};
    ASSERT_EQ(cg_zone_write(fn, base, "tets", size, CGNS_ENUMV(Unstructured), &zone), CG_OK);
    ASSERT_EQ(
        cg_coord_write(fn, base, zone, CGNS_ENUMV(RealDouble), "CoordinateZ", z.data(), &coord),
        CG_OK);
  } else {
    cgsize_t size[6] = {4, 4, 3, 3, 0, 0};
    ASSERT_EQ(cg_zone_write(fn, base, "square", size, CGNS_ENUMV(Structured), &zone), CG_OK);
  }
  if (rind) {  // the rind node first: coordinates written after it include the rind planes
    int grid = 0;
    ASSERT_EQ(cg_grid_write(fn, base, zone, "GridCoordinates", &grid), CG_OK) << cg_get_error();
    ASSERT_EQ(cg_goto(fn, base, "Zone_t", zone, "GridCoordinates_t", grid, "end"), CG_OK);
    const int planes[4] = {1, 1, 0, 0};
    ASSERT_EQ(cg_rind_write(planes), CG_OK) << cg_get_error();
  } else {
    ASSERT_EQ(
        cg_coord_write(fn, base, zone, CGNS_ENUMV(RealDouble), "CoordinateX", x.data(), &coord),
        CG_OK);
    ASSERT_EQ(
        cg_coord_write(fn, base, zone, CGNS_ENUMV(RealDouble), "CoordinateY", y.data(), &coord),
        CG_OK);
  }
  ASSERT_EQ(cg_close(fn), CG_OK);
}

TEST(CgnsReaderTest, UnstructuredZoneIsInvalidArgumentNamingIt) {
  TempDir dir("cgns-io");
  WriteOneZone(dir.File("u.cgns"), /*unstructured=*/true, /*rind=*/false);
  absl::StatusOr<ImportedGrid> read = ReadCgnsFile(dir.File("u.cgns"));
  EXPECT_EQ(read.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(read.status().message(), HasSubstr("zone 1 ('tets') is Unstructured"));
}

TEST(CgnsReaderTest, RindPlanesAreInvalidArgument) {
  TempDir dir("cgns-io");
  WriteOneZone(dir.File("r.cgns"), /*unstructured=*/false, /*rind=*/true);
  absl::StatusOr<ImportedGrid> read = ReadCgnsFile(dir.File("r.cgns"));
  EXPECT_EQ(read.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(read.status().message(), HasSubstr("rind"));
}

TEST(CgnsReaderTest, PlainStructuredZoneReadsAsPlanarBlock) {
  TempDir dir("cgns-io");
  WriteOneZone(dir.File("s.cgns"), /*unstructured=*/false, /*rind=*/false);
  absl::StatusOr<ImportedGrid> read = ReadCgnsFile(dir.File("s.cgns"));
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->grid.blocks.size(), 1u);
  EXPECT_EQ(read->grid.blocks[0].extents(), (Extents{4, 4, 1}));
  EXPECT_EQ(read->grid.blocks[0].Point(3, 2, 0)[0], 3.0);
  EXPECT_EQ(read->grid.blocks[0].Point(3, 2, 0)[1], 2.0);
}

TEST(CgnsReaderTest, NotACgnsFileIsInvalidArgument) {
  absl::StatusOr<ImportedGrid> read = ReadCgnsFile(SharedDataPath("grids/n0012_113-33.p2dfmt"));
  EXPECT_EQ(read.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(read.status().message(),
              HasSubstr("not a CGNS file: it starts with neither the HDF5 signature nor an ADF "
                        "header"));
}

TEST(CgnsSignatureTest, RecognisesHdf5AndAdfButNotPlot3d) {
  EXPECT_TRUE(LooksLikeCgns(std::string_view("\x89HDF\r\n\x1a\n\x02\x08", 10)));
  EXPECT_TRUE(LooksLikeCgns("@(#)ADF Database Version A02011>"));
  EXPECT_FALSE(LooksLikeCgns("           1\n         113          33\n"));
  EXPECT_FALSE(LooksLikeCgns(""));
}

}  // namespace
}  // namespace splinegrid

namespace splinegrid {
namespace {

TEST(CgnsWriterTest, SurfacePatchesAsCellDimensionTwoInSingleOrDoublePrecision) {
  TempDir dir("cgns-io");
  absl::StatusOr<MultiBlockGrid> m6 = ReadPlot3dFile(SharedDataPath("surfaces/m6_small.fmt"));
  ASSERT_TRUE(m6.ok()) << m6.status();
  for (const bool single : {false, true}) {
    CgnsWriteOptions options;
    options.single_precision = single;
    const std::string path = dir.File(single ? "s.cgns" : "d.cgns");
    ASSERT_TRUE(WriteCgnsFile(path, *m6, options, nullptr).ok());
    absl::StatusOr<ImportedGrid> back = ReadCgnsFile(path);
    ASSERT_TRUE(back.ok()) << back.status();
    // 3 coordinates on patches of 2 index directions: CellDimension 2, PhysicalDimension 3.
    EXPECT_THAT(back->format,
                HasSubstr(single ? "surface, 9 zones, single" : "surface, 9 zones, double"));
    const double difference = testing::MaxDifference(back->grid, *m6);
    if (single) {
      EXPECT_GT(difference, 0.0);
      EXPECT_LE(difference, kSingleRelative * 2.0);  // coordinates within +-2
    } else {
      EXPECT_EQ(difference, 0.0);
    }
  }
}

// libcgns lists a file's zones by name: unnamed blocks are written as block_00 .. block_11, so a
// grid of 12 blocks comes back in its order (block_10 used to come back third).
TEST(CgnsWriterTest, TwelveUnnamedBlocksComeBackInTheirOrder) {
  TempDir dir("cgns-io");
  MultiBlockGrid grid;
  for (int b = 0; b < 12; ++b) {
    StructuredBlock block({5 + b, 4, 1}, 2);
    for (int j = 0; j < 4; ++j) {
      for (int i = 0; i < 5 + b; ++i) {
        block.Point(i, j, 0)[0] = 10.0 * b + i;
        block.Point(i, j, 0)[1] = j;
      }
    }
    grid.blocks.push_back(std::move(block));
  }
  const std::string path = dir.File("twelve.cgns");
  ASSERT_TRUE(WriteCgnsFile(path, grid, CgnsWriteOptions(), nullptr).ok());
  absl::StatusOr<ImportedGrid> back = ReadCgnsFile(path);
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->grid.blocks.size(), 12u);
  EXPECT_EQ(testing::MaxDifference(back->grid, grid), 0.0);
  ASSERT_EQ(back->boundaries.block_names.size(), 12u);
  EXPECT_EQ(back->boundaries.block_names[2], "block_02");
  EXPECT_EQ(back->boundaries.block_names[11], "block_11");
}

// A condition whose type says nothing about the kind (BCTypeUserDefined: solver-specific BCs on
// proper face ranges) is kept and written back, setting no kind; one whose range lies outside
// its zone is named as such, in the file's 1-based indices over the zone's dimensions.
TEST(CgnsReaderTest, AUserDefinedConditionIsKeptAndAnOutOfRangeOneNamed) {
  TempDir dir("cgns-io");
  MultiBlockGrid grid;
  StructuredBlock block({5, 4, 1}, 2);
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 5; ++i) {
      block.Point(i, j, 0)[0] = i;
      block.Point(i, j, 0)[1] = j * (1.0 + 0.1 * i);
    }
  }
  grid.blocks.push_back(block);
  CgnsWriteOptions options;
  options.source_extents = {block.extents()};
  SourceBoundary wall;
  wall.range = {{0, 1, false}, {0, 0, 0}, {4, 0, 0}};
  wall.kind = BoundaryKind::kWall;
  wall.name = "wall";
  wall.bc_type = "BCWall";
  SourceBoundary porous = wall;
  porous.range = {{0, 1, true}, {0, 3, 0}, {4, 3, 0}};
  porous.kind = std::nullopt;
  porous.name = "porous";
  porous.bc_type = "UserDefined";  // CGNS names BCTypeUserDefined so
  options.conditions = {wall, porous};
  const std::string path = dir.File("ud.cgns");
  ASSERT_TRUE(WriteCgnsFile(path, grid, options, nullptr).ok());
  {  // and a far field beyond the zone's 5 points in i
    int fn = 0, bc = 0;
    ASSERT_EQ(cg_open(path.c_str(), CG_MODE_MODIFY, &fn), CG_OK);
    const cgsize_t range[4] = {1, 1, 300, 1};
    ASSERT_EQ(cg_boco_write(fn, 1, 1, "far", CGNS_ENUMV(BCFarfield), CGNS_ENUMV(PointRange), 2,
                            range, &bc),
              CG_OK);
    ASSERT_EQ(cg_close(fn), CG_OK);
  }
  absl::StatusOr<ImportedGrid> back = ReadCgnsFile(path);
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->boundaries.conditions.size(), 2u);
  EXPECT_EQ(back->boundaries.conditions[1].name, "porous");
  EXPECT_EQ(back->boundaries.conditions[1].kind, std::nullopt);
  ASSERT_EQ(back->boundaries.face_kinds.size(), 1u);  // the wall's face only
  EXPECT_EQ(back->boundaries.face_kinds[0].kind, BoundaryKind::kWall);
  const std::string notes = absl::StrJoin(back->boundaries.notes, "\n");
  EXPECT_THAT(notes, HasSubstr("BC 'porous' of zone 'block_0' has type UserDefined, which "
                               "says nothing about the kind; it is kept"));
  EXPECT_THAT(notes, HasSubstr("BC 'far' of zone 'block_0' (1:300, 1:1, 1-based) lies outside "
                               "the zone's 5 x 4 points; it is not kept"));
  // Written again, it is still there.
  options.conditions = back->boundaries.conditions;
  ASSERT_TRUE(WriteCgnsFile(dir.File("again.cgns"), back->grid, options, nullptr).ok());
  absl::StatusOr<ImportedGrid> again = ReadCgnsFile(dir.File("again.cgns"));
  ASSERT_TRUE(again.ok()) << again.status();
  ASSERT_EQ(again->boundaries.conditions.size(), 2u);
  EXPECT_EQ(again->boundaries.conditions[1].bc_type, "UserDefined");
}

}  // namespace
}  // namespace splinegrid
