// VTK XML output: structure of .vts/.vtm files, appended raw data, ASCII values, errors.
#include "core/io/vtk.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/io/file_util.h"
#include "core/io/vtk_compress.h"
#include "core/io/vtk_pvd.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/io_test_util.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

// The value of attribute `name` in the first element of `xml` whose opening tag starts with
// `tag` at or after `from` (e.g. tag "<Piece"); empty when absent.
std::string Attribute(const std::string& xml, const std::string& tag, const std::string& name,
                      size_t from = 0) {
  const size_t start = xml.find(tag, from);
  if (start == std::string::npos) return "";
  const size_t end = xml.find('>', start);
  const std::string element = xml.substr(start, end - start);
  const size_t at = element.find(" " + name + "=\"");
  if (at == std::string::npos) return "";
  const size_t value = at + name.size() + 3;
  return element.substr(value, element.find('"', value) - value);
}

// Offsets of every `<DataArray` tag in `xml`, in order.
std::vector<size_t> DataArrayTags(const std::string& xml) {
  std::vector<size_t> tags;
  for (size_t at = xml.find("<DataArray"); at != std::string::npos;
       at = xml.find("<DataArray", at + 1)) {
    tags.push_back(at);
  }
  return tags;
}

// The raw appended bytes of the array at `offset` (after its UInt64 size header, or decoded
// from zlib blocks when the file says compressor="vtkZLibDataCompressor").
std::string AppendedArray(const std::string& vts, uint64_t offset) {
  const size_t data = vts.find("<AppendedData encoding=\"raw\">");
  const size_t underscore = vts.find('_', data);
  if (vts.find("compressor=\"vtkZLibDataCompressor\"") != std::string::npos) {
    int64_t consumed = 0;
    absl::StatusOr<std::string> raw =
        DecodeVtkZlibBlocks(std::string_view(vts).substr(underscore + 1 + offset), &consumed);
    EXPECT_TRUE(raw.ok()) << raw.status();
    return raw.ok() ? *raw : std::string();
  }
  uint64_t size = 0;
  std::memcpy(&size, vts.data() + underscore + 1 + offset, sizeof(size));
  return vts.substr(underscore + 1 + offset + sizeof(size), size);
}

// The doubles of `raw`.
std::vector<double> AsDoubles(const std::string& raw) {
  std::vector<double> values(raw.size() / 8);
  std::memcpy(values.data(), raw.data(), values.size() * 8);
  return values;
}

// A 4 x 3 x 1 2D block with a scalar and a 2-component vector field.
class VtkTest : public testing::Test {
 protected:
  void SetUp() override {
    block_ = MakeSimpleGrid(2, {{4, 3, 1}}, /*with_iblank=*/true).blocks[0];
    for (int64_t p = 0; p < 12; ++p) {
      pressure_.push_back(0.1 * p + 1.0 / 3);
      velocity_.push_back(p);
      velocity_.push_back(-0.5 * p);
    }
    arrays_ = {VtkPointArray{"pressure", 1, pressure_}, VtkPointArray{"velocity", 2, velocity_}};
  }

  StructuredBlock block_;
  std::vector<double> pressure_, velocity_;
  std::vector<VtkPointArray> arrays_;
};

TEST_F(VtkTest, AppendedRawVtsHasExtentsOffsetsAndData) {
  VtkWriteOptions raw;
  raw.compress = false;
  absl::StatusOr<std::string> vts = EncodeVts(block_, arrays_, raw);
  ASSERT_TRUE(vts.ok()) << vts.status();
  EXPECT_EQ(Attribute(*vts, "<VTKFile", "type"), "StructuredGrid");
  EXPECT_EQ(Attribute(*vts, "<VTKFile", "header_type"), "UInt64");
  EXPECT_EQ(Attribute(*vts, "<VTKFile", "byte_order"),
            std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian");
  EXPECT_EQ(Attribute(*vts, "<StructuredGrid", "WholeExtent"), "0 3 0 2 0 0");
  EXPECT_EQ(Attribute(*vts, "<Piece", "Extent"), "0 3 0 2 0 0");
  EXPECT_EQ(Attribute(*vts, "<PointData", "Scalars"), "pressure");

  const std::vector<size_t> tags = DataArrayTags(*vts);
  ASSERT_EQ(tags.size(), 4);  // pressure, velocity, iblank, Points
  const char* names[] = {"pressure", "velocity", "iblank", "Points"};
  const char* types[] = {"Float64", "Float64", "Int32", "Float64"};
  const int components[] = {1, 2, 1, 3};
  const uint64_t bytes[] = {12 * 8, 12 * 2 * 8, 12 * 4, 12 * 3 * 8};
  uint64_t offset = 0;
  for (int a = 0; a < 4; ++a) {
    SCOPED_TRACE(names[a]);
    EXPECT_EQ(Attribute(*vts, "<DataArray", "Name", tags[a]), names[a]);
    EXPECT_EQ(Attribute(*vts, "<DataArray", "type", tags[a]), types[a]);
    EXPECT_EQ(Attribute(*vts, "<DataArray", "NumberOfComponents", tags[a]),
              std::to_string(components[a]));
    EXPECT_EQ(Attribute(*vts, "<DataArray", "format", tags[a]), "appended");
    EXPECT_EQ(Attribute(*vts, "<DataArray", "offset", tags[a]), std::to_string(offset));
    EXPECT_EQ(AppendedArray(*vts, offset).size(), bytes[a]);
    offset += 8 + bytes[a];
  }
  EXPECT_EQ(AsDoubles(AppendedArray(*vts, 0)), pressure_);
  const std::vector<double> points = AsDoubles(AppendedArray(*vts, offset - 8 - bytes[3]));
  ASSERT_EQ(points.size(), 36);
  for (int64_t p = 0; p < 12; ++p) {
    EXPECT_EQ(points[3 * p], block_.coords()[2 * p]);
    EXPECT_EQ(points[3 * p + 1], block_.coords()[2 * p + 1]);
    EXPECT_EQ(points[3 * p + 2], 0.0);  // z = 0 for 2D blocks
  }
  // The appended section ends right after the last array.
  const size_t underscore = vts->find('_', vts->find("<AppendedData"));
  EXPECT_EQ(vts->substr(underscore + 1 + offset), "\n  </AppendedData>\n</VTKFile>\n");
}

TEST_F(VtkTest, AsciiVtsHoldsExactValues) {
  VtkWriteOptions options;
  options.data_format = VtkDataFormat::kAscii;
  options.write_iblank = false;
  absl::StatusOr<std::string> vts = EncodeVts(block_, arrays_, options);
  ASSERT_TRUE(vts.ok()) << vts.status();
  EXPECT_EQ(vts->find("AppendedData"), std::string::npos);
  const std::vector<size_t> tags = DataArrayTags(*vts);
  ASSERT_EQ(tags.size(), 3);  // no iblank
  auto values_of = [&](size_t tag) {
    std::istringstream in(vts->substr(vts->find('>', tag) + 1));
    std::vector<double> values;
    std::string token;
    while (in >> token && token[0] != '<') values.push_back(std::stod(token));
    return values;
  };
  EXPECT_EQ(Attribute(*vts, "<DataArray", "format", tags[0]), "ascii");
  EXPECT_EQ(values_of(tags[0]), pressure_);
  EXPECT_EQ(values_of(tags[1]), velocity_);
  const std::vector<double> points = values_of(tags[2]);
  ASSERT_EQ(points.size(), 36);
  EXPECT_EQ(points[3 * 7], block_.coords()[2 * 7]);
  EXPECT_EQ(points[3 * 7 + 1], block_.coords()[2 * 7 + 1]);
  EXPECT_EQ(points[3 * 7 + 2], 0.0);
}

TEST_F(VtkTest, ThreeDimensionalBlockKeepsZ) {
  const StructuredBlock block = MakeSimpleGrid(3, {{2, 3, 4}}).blocks[0];
  VtkWriteOptions options;
  options.data_format = VtkDataFormat::kAscii;
  absl::StatusOr<std::string> vts = EncodeVts(block, {}, options);
  ASSERT_TRUE(vts.ok()) << vts.status();
  EXPECT_EQ(Attribute(*vts, "<Piece", "Extent"), "0 1 0 2 0 3");
  absl::StatusOr<std::string> raw = EncodeVts(block);
  ASSERT_TRUE(raw.ok()) << raw.status();
  const std::vector<double> points = AsDoubles(AppendedArray(*raw, 0));
  ASSERT_EQ(points.size(), block.coords().size());
  for (size_t c = 0; c < points.size(); ++c) EXPECT_EQ(points[c], block.coords()[c]);
}

TEST_F(VtkTest, RejectsBadPointArrays) {
  auto error = [&](std::vector<VtkPointArray> arrays) {
    absl::StatusOr<std::string> vts = EncodeVts(block_, arrays);
    EXPECT_EQ(vts.status().code(), absl::StatusCode::kInvalidArgument);
    return MessageOf(vts.status());
  };
  EXPECT_THAT(error({VtkPointArray{"short", 1, std::span(pressure_).first(11)}}),
              HasSubstr("'short' has 11 values; 12 points x 1 components need 12"));
  EXPECT_THAT(error({VtkPointArray{"v", 3, velocity_}}),
              HasSubstr("'v' has 24 values; 12 points x 3 components need 36"));
  EXPECT_THAT(error({VtkPointArray{"", 1, pressure_}}), HasSubstr("empty name"));
  EXPECT_THAT(error({VtkPointArray{"p", 1, pressure_}, VtkPointArray{"p", 1, pressure_}}),
              HasSubstr("'p' is used twice"));
  EXPECT_THAT(error({VtkPointArray{"iblank", 1, pressure_}}), HasSubstr("is used twice"));
  EXPECT_THAT(error({VtkPointArray{"p", 0, {}}}), HasSubstr("0 components"));
}

TEST_F(VtkTest, EscapesArrayNames) {
  const std::vector<VtkPointArray> arrays = {VtkPointArray{"a<b & \"c\"", 1, pressure_}};
  absl::StatusOr<std::string> vts = EncodeVts(block_, arrays);
  ASSERT_TRUE(vts.ok()) << vts.status();
  EXPECT_THAT(*vts, HasSubstr("Name=\"a&lt;b &amp; &quot;c&quot;\""));
}

TEST_F(VtkTest, WritesMultiBlockFileAndDirectory) {
  const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "vtk_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const MultiBlockGrid grid = MakeSimpleGrid(3, {{2, 2, 2}, {3, 2, 1}, {2, 4, 1}});
  std::vector<std::vector<double>> fields(3);
  std::vector<std::vector<VtkPointArray>> arrays(3);
  for (int b = 0; b < 3; ++b) {
    fields[b].assign(static_cast<size_t>(grid.blocks[b].num_points()), b + 0.5);
    arrays[b].push_back(VtkPointArray{"block_value", 1, fields[b]});
  }
  const std::string path = (dir / "flow.vtm").string();
  ASSERT_TRUE(WriteVtm(path, grid, arrays).ok());
  absl::StatusOr<std::string> vtm = ReadFileToString(path);
  ASSERT_TRUE(vtm.ok()) << vtm.status();
  EXPECT_EQ(Attribute(*vtm, "<VTKFile", "type"), "vtkMultiBlockDataSet");
  for (int b = 0; b < 3; ++b) {
    const size_t tag = vtm->find("<DataSet index=\"" + std::to_string(b) + "\"");
    ASSERT_NE(tag, std::string::npos);
    const std::string file = Attribute(*vtm, "<DataSet", "file", tag);
    EXPECT_EQ(file, "flow/flow_" + std::to_string(b) + ".vts");
    absl::StatusOr<std::string> vts = ReadFileToString((dir / file).string());
    ASSERT_TRUE(vts.ok()) << vts.status();
    const Extents& e = grid.blocks[b].extents();
    EXPECT_EQ(Attribute(*vts, "<Piece", "Extent"),
              absl::StrCat("0 ", e[0] - 1, " 0 ", e[1] - 1, " 0 ", e[2] - 1));
    EXPECT_EQ(AsDoubles(AppendedArray(*vts, 0)), fields[b]);
  }
  // Only flow.vtm and flow/ with its 3 files: no temporary files are left behind.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir),
                          std::filesystem::directory_iterator()),
            2);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir / "flow"),
                          std::filesystem::directory_iterator()),
            3);
}

TEST_F(VtkTest, ReportsUnwritablePathsAndBadArguments) {
  const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "vtk_errors";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string file = (dir / "plain_file").string();
  ASSERT_TRUE(WriteFileAtomically(file, "x").ok());

  const std::string vts_path = file + "/block.vts";  // a path "inside" a regular file
  absl::Status status = WriteVts(vts_path, block_);
  EXPECT_FALSE(status.ok());
  EXPECT_THAT(MessageOf(status), HasSubstr(vts_path));

  MultiBlockGrid grid;
  grid.blocks.push_back(block_);
  status = WriteVtm(file + "/flow.vtm", grid);
  EXPECT_FALSE(status.ok());
  EXPECT_THAT(MessageOf(status), HasSubstr("flow.vtm"));

  status = WriteVtm((dir / "flow.vts").string(), grid);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(MessageOf(status), HasSubstr("must end in <name>.vtm"));

  std::vector<std::vector<VtkPointArray>> too_few(2);
  status = WriteVtm((dir / "flow.vtm").string(), grid, too_few);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
}

TEST_F(VtkTest, CompressedArraysDecodeToTheRawBytesAndAreSmaller) {
  // A smooth 60 x 50 block: several 32 KiB blocks per array, the last one partial.
  const StructuredBlock block = MakeSimpleGrid(3, {{60, 50, 3}}).blocks[0];
  std::vector<double> field(static_cast<size_t>(block.num_points()));
  for (size_t p = 0; p < field.size(); ++p) field[p] = std::sin(0.01 * static_cast<double>(p));
  const std::vector<VtkPointArray> arrays = {VtkPointArray{"f", 1, field}};
  VtkWriteOptions raw_options;
  raw_options.compress = false;
  absl::StatusOr<std::string> raw = EncodeVts(block, arrays, raw_options);
  absl::StatusOr<std::string> compressed = EncodeVts(block, arrays);
  ASSERT_TRUE(raw.ok() && compressed.ok());
  EXPECT_EQ(Attribute(*compressed, "<VTKFile", "compressor"), "vtkZLibDataCompressor");
  EXPECT_EQ(Attribute(*raw, "<VTKFile", "compressor"), "");
  EXPECT_LT(compressed->size(), raw->size() * 3 / 4);
  const std::vector<size_t> raw_tags = DataArrayTags(*raw);
  const std::vector<size_t> tags = DataArrayTags(*compressed);
  ASSERT_EQ(tags.size(), 2u);  // f, Points
  for (size_t a = 0; a < tags.size(); ++a) {
    const uint64_t offset = std::stoull(Attribute(*compressed, "<DataArray", "offset", tags[a]));
    const uint64_t raw_offset = std::stoull(Attribute(*raw, "<DataArray", "offset", raw_tags[a]));
    EXPECT_EQ(AppendedArray(*compressed, offset), AppendedArray(*raw, raw_offset));
  }
  // The header of the points array: 9000 x 24 bytes = 6 full blocks and one of 19392 bytes.
  const size_t underscore = compressed->find('_', compressed->find("<AppendedData"));
  const uint64_t points_offset =
      std::stoull(Attribute(*compressed, "<DataArray", "offset", tags[1]));
  uint64_t header[3];
  std::memcpy(header, compressed->data() + underscore + 1 + points_offset, sizeof(header));
  EXPECT_EQ(header[0], 7u);
  EXPECT_EQ(header[1], 32768u);
  EXPECT_EQ(header[2], 9000u * 24 - 6 * 32768);
}

TEST_F(VtkTest, CellArraysGoToCellData) {
  const std::vector<double> quality = {0.5, 0.25, 1.0, -0.5, 0.75, 0.125};  // 3 x 2 cells
  const std::vector<VtkPointArray> arrays = {
      VtkPointArray{"pressure", 1, pressure_},
      VtkPointArray{"quality", 1, quality, VtkArrayLocation::kCell}};
  EXPECT_EQ(VtkNumCells(block_), 6);
  VtkWriteOptions options;
  options.data_format = VtkDataFormat::kAscii;
  absl::StatusOr<std::string> vts = EncodeVts(block_, arrays, options);
  ASSERT_TRUE(vts.ok()) << vts.status();
  const size_t cell_data = vts->find("<CellData");
  ASSERT_NE(cell_data, std::string::npos);
  EXPECT_EQ(Attribute(*vts, "<CellData", "Scalars"), "quality");
  EXPECT_EQ(Attribute(*vts, "<DataArray", "Name", cell_data), "quality");
  EXPECT_LT(vts->find("Name=\"pressure\""), cell_data);
  const std::vector<VtkPointArray> wrong = {
      VtkPointArray{"quality", 1, pressure_, VtkArrayLocation::kCell}};
  absl::StatusOr<std::string> refused = EncodeVts(block_, wrong);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(MessageOf(refused.status()),
              HasSubstr("cell array 'quality' has 12 values; 6 cells x 1 components need 6"));
}

TEST_F(VtkTest, MultiBlockFilesCarryTheGivenBlockNumbers) {
  const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "vtk_numbers";
  std::filesystem::remove_all(dir);
  const MultiBlockGrid grid = MakeSimpleGrid(3, {{2, 2, 2}, {3, 2, 1}});
  const std::vector<int> numbers = {0, 3};
  const std::string path = (dir / "wing.vtm").string();
  std::filesystem::create_directories(dir);
  ASSERT_TRUE(WriteVtm(path, grid, {}, {}, numbers).ok());
  absl::StatusOr<std::string> vtm = ReadFileToString(path);
  ASSERT_TRUE(vtm.ok());
  EXPECT_THAT(*vtm, HasSubstr("<DataSet index=\"1\" name=\"block_3\" file=\"wing/wing_3.vts\"/>"));
  EXPECT_TRUE(std::filesystem::exists(dir / "wing" / "wing_3.vts"));
  EXPECT_FALSE(std::filesystem::exists(dir / "wing" / "wing_1.vts"));
  const std::vector<int> repeated = {2, 2};
  EXPECT_EQ(WriteVtm(path, grid, {}, {}, repeated).code(), absl::StatusCode::kInvalidArgument);
  const std::vector<int> one = {2};
  EXPECT_EQ(WriteVtm(path, grid, {}, {}, one).code(), absl::StatusCode::kInvalidArgument);
}

TEST(VtkPvdTest, ListsTimeStepsAndRefusesBadOnes) {
  const std::vector<PvdEntry> entries = {{0.01, "run/run_1.vts"}, {0.025, "run/run_2.vts"}};
  absl::StatusOr<std::string> pvd = EncodePvd(entries);
  ASSERT_TRUE(pvd.ok()) << pvd.status();
  EXPECT_THAT(*pvd, HasSubstr("<VTKFile type=\"Collection\" version=\"0.1\">"));
  EXPECT_THAT(*pvd, HasSubstr("<DataSet timestep=\"0.025\" group=\"\" part=\"0\" "
                              "file=\"run/run_2.vts\"/>"));
  EXPECT_EQ(EncodePvd({}).status().code(), absl::StatusCode::kInvalidArgument);
  const std::vector<PvdEntry> repeated = {{1.0, "a.vts"}, {1.0, "b.vts"}};
  EXPECT_THAT(MessageOf(EncodePvd(repeated).status()), HasSubstr("not finite or repeats"));
  const std::vector<PvdEntry> nan = {{std::nan(""), "a.vts"}};
  EXPECT_EQ(EncodePvd(nan).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(VtkCompressTest, CorruptDataIsRefused) {
  std::string out;
  AppendVtkZlibBlocks(std::string(100000, 'a'), 6, &out);
  int64_t consumed = 0;
  absl::StatusOr<std::string> raw = DecodeVtkZlibBlocks(out, &consumed);
  ASSERT_TRUE(raw.ok());
  EXPECT_EQ(*raw, std::string(100000, 'a'));
  EXPECT_EQ(consumed, static_cast<int64_t>(out.size()));
  EXPECT_FALSE(
      DecodeVtkZlibBlocks(std::string_view(out).substr(0, out.size() - 3), &consumed).ok());
  std::string damaged = out;
  damaged[damaged.size() - 5] ^= 0x55;
  EXPECT_FALSE(DecodeVtkZlibBlocks(damaged, &consumed).ok());
  EXPECT_FALSE(DecodeVtkZlibBlocks("short", &consumed).ok());
}

}  // namespace
}  // namespace splinegrid
