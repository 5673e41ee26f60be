#include "core/io/vtk.h"

#include <bit>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <set>

#include "absl/strings/str_cat.h"
#include "core/io/file_util.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

// Most components a point array may have (a 3 x 3 tensor).
constexpr int kMaxComponents = 9;

// "LittleEndian" or "BigEndian": the byte order of this machine, used for raw data.
const char* MachineByteOrder() {
  return std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
}

// `text` with the five XML special characters escaped, for an attribute value.
std::string XmlEscape(const std::string& text) {
  std::string escaped;
  escaped.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      case '\'':
        escaped += "&apos;";
        break;
      default:
        escaped.push_back(c);
    }
  }
  return escaped;
}

// One DataArray to write: its XML attributes and where its numbers come from.
struct ArrayToWrite {
  std::string type;                 // "Float64" or "Int32"
  std::string name;                 // Name attribute (unescaped)
  int num_components = 1;           // NumberOfComponents
  std::span<const double> doubles;  // Float64 data (points are produced separately)
  std::span<const int> ints;        // Int32 data
  bool is_points = false;           // the Points array: 3 components from the block
  // Bytes of the raw data (without the UInt64 size header).
  uint64_t bytes(int64_t num_points) const {
    return static_cast<uint64_t>(num_points) * num_components * (type == "Int32" ? 4 : 8);
  }
};

// Calls `emit(double)` for each of the 3 * num_points point coordinates of `block`, z = 0 in 2D.
template <typename Emit>
void ForEachPointCoordinate(const StructuredBlock& block, Emit emit) {
  const std::span<const double> coords = block.coords();
  const int dim = block.spatial_dim();
  for (int64_t p = 0; p < block.num_points(); ++p) {
    emit(coords[p * dim]);
    emit(coords[p * dim + 1]);
    emit(dim == 3 ? coords[p * dim + 2] : 0.0);
  }
}

// Appends the values of `array` as ASCII, 6 per line.
void AppendAscii(const StructuredBlock& block, const ArrayToWrite& array, std::string* out) {
  int64_t count = 0;
  auto emit_text = [&](const char* begin, const char* end) {
    out->append(begin, end);
    out->push_back(++count % 6 == 0 ? '\n' : ' ');
  };
  char buffer[40];
  auto emit_double = [&](double value) {
    emit_text(buffer, std::to_chars(buffer, buffer + sizeof(buffer), value).ptr);
  };
  if (array.is_points) {
    ForEachPointCoordinate(block, emit_double);
  } else if (array.type == "Int32") {
    for (int value : array.ints) {
      emit_text(buffer, std::to_chars(buffer, buffer + sizeof(buffer), value).ptr);
    }
  } else {
    for (double value : array.doubles) emit_double(value);
  }
  out->push_back('\n');
}

// Appends the UInt64 byte count and the raw bytes of `array` in machine byte order.
void AppendRaw(const StructuredBlock& block, const ArrayToWrite& array, std::string* out) {
  const uint64_t size = array.bytes(block.num_points());
  out->append(reinterpret_cast<const char*>(&size), sizeof(size));
  if (array.is_points) {
    const size_t start = out->size();
    out->resize(start + size);
    char* p = out->data() + start;
    ForEachPointCoordinate(block, [&p](double value) {
      std::memcpy(p, &value, sizeof(value));
      p += sizeof(value);
    });
  } else if (array.type == "Int32") {
    out->append(reinterpret_cast<const char*>(array.ints.data()), size);
  } else {
    out->append(reinterpret_cast<const char*>(array.doubles.data()), size);
  }
}

// OK when `arrays` are valid point data for a block of `num_points` points.
absl::Status ValidateArrays(std::span<const VtkPointArray> arrays, int64_t num_points,
                            bool iblank_added) {
  std::set<std::string> names;
  if (iblank_added) names.insert("iblank");
  for (const VtkPointArray& array : arrays) {
    if (array.name.empty()) {
      return absl::InvalidArgumentError("VTK point array with an empty name");
    }
    if (!names.insert(array.name).second) {
      return absl::InvalidArgumentError(
          absl::StrCat("VTK point array name '", array.name, "' is used twice",
                       array.name == "iblank" ? " (the block's iblank is written too)" : ""));
    }
    if (array.num_components < 1 || array.num_components > kMaxComponents) {
      return absl::InvalidArgumentError(
          absl::StrCat("VTK point array '", array.name, "': ", array.num_components,
                       " components; must be from 1 to ", kMaxComponents));
    }
    const int64_t expected = num_points * array.num_components;
    if (static_cast<int64_t>(array.values.size()) != expected) {
      return absl::InvalidArgumentError(absl::StrCat(
          "VTK point array '", array.name, "' has ", array.values.size(), " values; ", num_points,
          " points x ", array.num_components, " components need ", expected));
    }
  }
  return absl::OkStatus();
}

// The opening tag of a DataArray, without the closing '>' or '/>'.
std::string DataArrayTag(const ArrayToWrite& array, const VtkWriteOptions& options,
                         uint64_t offset) {
  std::string tag =
      absl::StrCat("<DataArray type=\"", array.type, "\" Name=\"", XmlEscape(array.name),
                   "\" NumberOfComponents=\"", array.num_components, "\"");
  if (options.data_format == VtkDataFormat::kAppendedRaw) {
    absl::StrAppend(&tag, " format=\"appended\" offset=\"", offset, "\"");
  } else {
    absl::StrAppend(&tag, " format=\"ascii\"");
  }
  return tag;
}

}  // namespace

absl::StatusOr<std::string> EncodeVts(const StructuredBlock& block,
                                      std::span<const VtkPointArray> arrays,
                                      const VtkWriteOptions& options) {
  const int64_t num_points = block.num_points();
  const bool write_iblank =
      options.write_iblank && block.iblank().size() == static_cast<size_t>(num_points);
  SG_RETURN_IF_ERROR(ValidateArrays(arrays, num_points, write_iblank));
  std::vector<ArrayToWrite> point_data;
  std::string active;  // Scalars="..." / Vectors="..." of PointData
  for (const VtkPointArray& array : arrays) {
    ArrayToWrite data;
    data.type = "Float64";
    data.name = array.name;
    data.num_components = array.num_components;
    data.doubles = array.values;
    point_data.push_back(std::move(data));
    const char* role = array.num_components == 1   ? "Scalars"
                       : array.num_components == 3 ? "Vectors"
                                                   : nullptr;
    if (role != nullptr && active.find(role) == std::string::npos) {
      absl::StrAppend(&active, " ", role, "=\"", XmlEscape(array.name), "\"");
    }
  }
  if (write_iblank) {
    ArrayToWrite iblank;
    iblank.type = "Int32";
    iblank.name = "iblank";
    iblank.ints = block.iblank();
    point_data.push_back(iblank);
  }
  ArrayToWrite points;
  points.type = "Float64";
  points.name = "Points";
  points.num_components = 3;
  points.is_points = true;

  const std::string extent = absl::StrCat("0 ", block.extent(0) - 1, " 0 ", block.extent(1) - 1,
                                          " 0 ", block.extent(2) - 1);
  const bool ascii = options.data_format == VtkDataFormat::kAscii;
  std::string out = absl::StrCat(
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"StructuredGrid\" version=\"1.0\" byte_order=\"",
      MachineByteOrder(), "\" header_type=\"UInt64\">\n  <StructuredGrid WholeExtent=\"", extent,
      "\">\n    <Piece Extent=\"", extent, "\">\n      <PointData", active, ">\n");
  uint64_t offset = 0;
  auto add_array = [&](const ArrayToWrite& array, const char* indent) {
    absl::StrAppend(&out, indent, DataArrayTag(array, options, offset));
    if (ascii) {
      out += ">\n";
      AppendAscii(block, array, &out);
      absl::StrAppend(&out, indent, "</DataArray>\n");
    } else {
      out += "/>\n";
      offset += sizeof(uint64_t) + array.bytes(num_points);
    }
  };
  for (const ArrayToWrite& array : point_data) add_array(array, "        ");
  out += "      </PointData>\n      <Points>\n";
  add_array(points, "        ");
  out += "      </Points>\n    </Piece>\n  </StructuredGrid>\n";
  if (!ascii) {
    out.reserve(out.size() + offset + 64);
    out += "  <AppendedData encoding=\"raw\">\n   _";
    for (const ArrayToWrite& array : point_data) AppendRaw(block, array, &out);
    AppendRaw(block, points, &out);
    out += "\n  </AppendedData>\n";
  }
  out += "</VTKFile>\n";
  return out;
}

absl::Status WriteVts(const std::string& path, const StructuredBlock& block,
                      std::span<const VtkPointArray> arrays, const VtkWriteOptions& options) {
  absl::StatusOr<std::string> contents = EncodeVts(block, arrays, options);
  if (!contents.ok()) {
    return absl::Status(contents.status().code(),
                        absl::StrCat("writing '", path, "': ", contents.status().message()));
  }
  return WriteFileAtomically(path, *contents);
}

absl::Status WriteVtm(const std::string& path, const MultiBlockGrid& grid,
                      std::span<const std::vector<VtkPointArray>> block_arrays,
                      const VtkWriteOptions& options) {
  const std::filesystem::path vtm(path);
  if (vtm.extension() != ".vtm" || vtm.stem().empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("VTK multiblock path '", path, "' must end in <name>.vtm"));
  }
  if (!block_arrays.empty() && block_arrays.size() != grid.blocks.size()) {
    return absl::InvalidArgumentError(absl::StrCat("writing '", path, "': point arrays given for ",
                                                   block_arrays.size(), " blocks, the grid has ",
                                                   grid.blocks.size()));
  }
  const std::string name = vtm.stem().string();
  const std::filesystem::path directory = vtm.parent_path() / name;
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) {
    return ErrnoToStatusWithMessage(
        error.value(),
        absl::StrCat("cannot create the directory '", directory.string(), "' for '", path, "'"));
  }
  std::string xml = absl::StrCat(
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"vtkMultiBlockDataSet\" version=\"1.0\" "
      "byte_order=\"",
      MachineByteOrder(), "\" header_type=\"UInt64\">\n  <vtkMultiBlockDataSet>\n");
  for (size_t b = 0; b < grid.blocks.size(); ++b) {
    const std::string file = absl::StrCat(name, "_", b, ".vts");
    const std::span<const VtkPointArray> arrays =
        block_arrays.empty() ? std::span<const VtkPointArray>() : block_arrays[b];
    absl::Status status = WriteVts((directory / file).string(), grid.blocks[b], arrays, options);
    if (!status.ok()) {
      return absl::Status(status.code(),
                          absl::StrCat("block ", b, " of '", path, "': ", status.message()));
    }
    absl::StrAppend(&xml, "    <DataSet index=\"", b, "\" name=\"block_", b, "\" file=\"",
                    XmlEscape(absl::StrCat(name, "/", file)), "\"/>\n");
  }
  xml += "  </vtkMultiBlockDataSet>\n</VTKFile>\n";
  return WriteFileAtomically(path, xml);
}

}  // namespace splinegrid
