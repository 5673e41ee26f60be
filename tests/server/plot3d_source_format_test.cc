// The layout of an imported Plot3D file (SourceGrid.plot3d): set at import (layout choice,
// planar view), kept by an archive round trip and by the directory store across a restart,
// and validated when read back.
#include <filesystem>
#include <string>

#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "proto/convert/plot3d_format_convert.h"
#include "tests/core/io_test_util.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::testing {
namespace {

class Plot3dSourceFormatTest : public ServiceTest {};

// The planes of rae2822_257x97.fmt: i-direction planes, y = 0 and y = -1.
void ExpectRaePlanes(const v1::Plot3dFileFormat& format) {
  EXPECT_EQ(format.encoding(), v1::PLOT3D_ENCODING_ASCII);
  EXPECT_EQ(format.spatial_dim(), 3);
  EXPECT_TRUE(format.has_block_count());
  ASSERT_EQ(format.two_planes_size(), 1);
  EXPECT_EQ(format.two_planes(0).plane_direction(), 0);
  EXPECT_EQ(format.two_planes(0).normal_coordinate(), 1);
  EXPECT_EQ(format.two_planes(0).plane_value_0(), 0.0);
  EXPECT_EQ(format.two_planes(0).plane_value_1(), -1.0);
}

TEST_F(Plot3dSourceFormatTest, PlanarImportKeepsThePlanesThroughArchives) {
  const v1::Grid grid = ImportShared("grids/rae2822_257x97.fmt", "rae", /*planar=*/true);
  ASSERT_TRUE(grid.source().has_plot3d());
  ExpectRaePlanes(grid.source().plot3d());
  EXPECT_EQ(grid.source().spatial_dim(), 2);  // the stored view
  const std::string path = (std::filesystem::path(::testing::TempDir()) / "rae.sgrid").string();
  FitCounts("rae", 20, 10);
  ASSERT_TRUE(client_->ExportGrid("rae", path).ok());
  absl::StatusOr<v1::Grid> imported = client_->ImportArchive(path, "rae-copy");
  ASSERT_TRUE(imported.ok()) << imported.status();
  EXPECT_EQ(imported->source().plot3d().SerializeAsString(),
            grid.source().plot3d().SerializeAsString());
  // Points imports have none.
  absl::StatusOr<v1::Grid> points =
      client_->ImportPoints(MakeSimpleGrid(2, {{4, 3, 1}}), "points", "points");
  ASSERT_TRUE(points.ok()) << points.status();
  EXPECT_FALSE(points->source().has_plot3d());
}

TEST_F(Plot3dSourceFormatTest, DirectoryStoreKeepsTheLayoutAcrossARestart) {
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / "plot3d_source_format_store";
  std::filesystem::remove_all(dir);
  options_.store = "dir:" + dir.string();
  StartServer();
  // A big-endian single-precision C stream in the planes layout, imported with that choice.
  Plot3dFormat format{Plot3dEncoding::kBinaryBigEndian, 3, true, false, 4};
  format.framing = Plot3dFraming::kCStream;
  format.layout = Plot3dLayout::kPlanes;
  const std::string bytes = EncodePlot3d(MakeSimpleGrid(3, {{5, 4, 3}}), format).value();
  v1::Plot3dSource options;
  options.set_layout(v1::PLOT3D_LAYOUT_PLANES);
  absl::StatusOr<v1::Grid> grid = client_->ImportPlot3d(bytes, "stream", "stream.x", options);
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_THAT(grid->source().format(), ::testing::HasSubstr("C-stream single precision"));
  FitCounts("stream", 4, 4, 3);
  StartServer();  // a new server on the same directory
  v1::GetGridRequest get;
  get.set_name("stream");
  absl::StatusOr<v1::Grid> again = client_->Get(get);
  ASSERT_TRUE(again.ok()) << again.status();
  const v1::Plot3dFileFormat& kept = again->source().plot3d();
  EXPECT_EQ(kept.encoding(), v1::PLOT3D_ENCODING_BINARY_BIG_ENDIAN);
  EXPECT_TRUE(kept.c_stream());
  EXPECT_EQ(kept.bytes_per_real(), 4);
  EXPECT_EQ(kept.layout(), v1::PLOT3D_LAYOUT_PLANES);
  std::filesystem::remove_all(dir);
}

TEST_F(Plot3dSourceFormatTest, ARequestedLayoutThatContradictsTheRecordsIsRefused) {
  Plot3dFormat format{Plot3dEncoding::kBinaryLittleEndian, 3, true, false, 8};
  format.layout = Plot3dLayout::kPlanes;
  const std::string bytes = EncodePlot3d(MakeSimpleGrid(3, {{5, 4, 3}}), format).value();
  v1::Plot3dSource options;
  options.set_layout(v1::PLOT3D_LAYOUT_WHOLE);
  EXPECT_THAT(client_->ImportPlot3d(bytes, "records", "records.x", options).status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "the records hold the planes layout"));
}

TEST(Plot3dFormatConvertTest, DamagedFormatsAreRefusedNamingTheField) {
  v1::Plot3dFileFormat format;
  format.set_encoding(v1::PLOT3D_ENCODING_ASCII);
  format.set_spatial_dim(3);
  format.set_bytes_per_real(8);
  ASSERT_TRUE(ParsePlot3dSourceFormat(format, 1, "source.plot3d").ok());
  v1::Plot3dFileFormat bad = format;
  bad.set_encoding(v1::PLOT3D_ENCODING_UNSPECIFIED);
  EXPECT_THAT(ParsePlot3dSourceFormat(bad, 1, "source.plot3d").status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "source.plot3d.encoding = 0"));
  bad = format;
  bad.set_bytes_per_real(2);
  EXPECT_THAT(ParsePlot3dSourceFormat(bad, 1, "f").status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "f.bytes_per_real = 2"));
  bad = format;
  bad.add_two_planes()->set_plane_value_1(1.0);
  EXPECT_THAT(ParsePlot3dSourceFormat(bad, 2, "f").status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "two_planes has 1 entries"));
  bad.mutable_two_planes(0)->set_plane_value_1(0.0);
  EXPECT_THAT(ParsePlot3dSourceFormat(bad, 1, "f").status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "must be finite and differ"));
  bad.mutable_two_planes(0)->set_plane_value_1(1.0);
  bad.mutable_two_planes(0)->set_normal_coordinate(5);
  EXPECT_THAT(ParsePlot3dSourceFormat(bad, 1, "f").status(),
              StatusIs(absl::StatusCode::kInvalidArgument, "must be from 0 to 2"));
}

}  // namespace
}  // namespace splinegrid::testing
