#include "core/io/vtk.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <set>

#include "absl/strings/str_cat.h"
#include "core/io/file_util.h"
#include "core/io/vtk_compress.h"
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

// Appends the raw bytes of `array` (`tuples` of it) in machine byte order.
void AppendRawBytes(const StructuredBlock& block, const ArrayToWrite& array, int64_t tuples,
                    std::string* out) {
  const uint64_t size = array.bytes(tuples);
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

// Appends `array` as appended data: the UInt64 byte count and the raw bytes, or with
// options.compress the zlib blocks (vtk_compress.h). Returns the bytes appended.
uint64_t AppendData(const StructuredBlock& block, const ArrayToWrite& array, int64_t tuples,
                    const VtkWriteOptions& options, std::string* out) {
  const size_t start = out->size();
  if (options.compress) {
    std::string raw;
    raw.reserve(array.bytes(tuples));
    AppendRawBytes(block, array, tuples, &raw);
    AppendVtkZlibBlocks(raw, options.compression_level, out);
  } else {
    const uint64_t size = array.bytes(tuples);
    out->append(reinterpret_cast<const char*>(&size), sizeof(size));
    AppendRawBytes(block, array, tuples, out);
  }
  return out->size() - start;
}

// OK when `arrays` are valid point data for a block of `num_points` points.
absl::Status ValidateArrays(std::span<const VtkPointArray> arrays, int64_t num_points,
                            int64_t num_cells, bool iblank_added) {
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
    const bool cells = array.location == VtkArrayLocation::kCell;
    const int64_t tuples = cells ? num_cells : num_points;
    const int64_t expected = tuples * array.num_components;
    if (static_cast<int64_t>(array.values.size()) != expected) {
      return absl::InvalidArgumentError(
          absl::StrCat("VTK ", cells ? "cell" : "point", " array '", array.name, "' has ",
                       array.values.size(), " values; ", tuples, cells ? " cells" : " points",
                       " x ", array.num_components, " components need ", expected));
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

// Appends the opening tag's role attributes (Scalars="..." Vectors="...") for `arrays` of
// `location`: the first 1- and 3-component arrays become ParaView's active ones.
std::string ActiveAttributes(std::span<const VtkPointArray> arrays, VtkArrayLocation location) {
  std::string active;
  for (const VtkPointArray& array : arrays) {
    if (array.location != location) continue;
    const char* role = array.num_components == 1   ? "Scalars"
                       : array.num_components == 3 ? "Vectors"
                                                   : nullptr;
    if (role != nullptr && active.find(role) == std::string::npos) {
      absl::StrAppend(&active, " ", role, "=\"", XmlEscape(array.name), "\"");
    }
  }
  return active;
}

}  // namespace

int64_t VtkNumCells(const StructuredBlock& block) {
  int64_t cells = 1;
  for (int d = 0; d < 3; ++d) cells *= std::max(block.extent(d) - 1, 1);
  return cells;
}

absl::StatusOr<std::string> EncodeVts(const StructuredBlock& block,
                                      std::span<const VtkPointArray> arrays,
                                      const VtkWriteOptions& options) {
  const int64_t num_points = block.num_points();
  const int64_t num_cells = VtkNumCells(block);
  const bool write_iblank =
      options.write_iblank && block.iblank().size() == static_cast<size_t>(num_points);
  SG_RETURN_IF_ERROR(ValidateArrays(arrays, num_points, num_cells, write_iblank));
  if (options.compression_level < 1 || options.compression_level > 9) {
    return absl::InvalidArgumentError(absl::StrCat(
        "VTK compression_level = ", options.compression_level, ": must be from 1 to 9"));
  }
  std::vector<ArrayToWrite> point_data, cell_data;
  for (const VtkPointArray& array : arrays) {
    ArrayToWrite data;
    data.type = "Float64";
    data.name = array.name;
    data.num_components = array.num_components;
    data.doubles = array.values;
    (array.location == VtkArrayLocation::kCell ? cell_data : point_data).push_back(data);
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
  const bool compress = !ascii && options.compress;
  std::string out = absl::StrCat(
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"StructuredGrid\" version=\"1.0\" byte_order=\"",
      MachineByteOrder(), "\" header_type=\"UInt64\"",
      compress ? " compressor=\"vtkZLibDataCompressor\"" : "",
      ">\n  <StructuredGrid WholeExtent=\"", extent, "\">\n    <Piece Extent=\"", extent, "\">\n");
  // Appended data are produced with the tags, since compressed sizes fix the next offset.
  std::string appended;
  auto add_array = [&](const ArrayToWrite& array, int64_t tuples) {
    const char* indent = "        ";
    absl::StrAppend(&out, indent, DataArrayTag(array, options, appended.size()));
    if (ascii) {
      out += ">\n";
      AppendAscii(block, array, &out);
      absl::StrAppend(&out, indent, "</DataArray>\n");
    } else {
      out += "/>\n";
      AppendData(block, array, tuples, options, &appended);
    }
  };
  absl::StrAppend(&out, "      <PointData", ActiveAttributes(arrays, VtkArrayLocation::kPoint),
                  ">\n");
  for (const ArrayToWrite& array : point_data) add_array(array, num_points);
  out += "      </PointData>\n";
  if (!cell_data.empty()) {
    absl::StrAppend(&out, "      <CellData", ActiveAttributes(arrays, VtkArrayLocation::kCell),
                    ">\n");
    for (const ArrayToWrite& array : cell_data) add_array(array, num_cells);
    out += "      </CellData>\n";
  }
  out += "      <Points>\n";
  add_array(points, num_points);
  out += "      </Points>\n    </Piece>\n  </StructuredGrid>\n";
  if (!ascii) {
    out.reserve(out.size() + appended.size() + 64);
    out += "  <AppendedData encoding=\"raw\">\n   _";
    out += appended;
    out += "\n  </AppendedData>\n";
  }
  out += "</VTKFile>\n";
  return out;
}

absl::Status WriteVts(const std::string& path, const StructuredBlock& block,
                      std::span<const VtkPointArray> arrays, const VtkWriteOptions& options) {
  SG_ASSIGN_OR_RETURN(const std::string contents, EncodeVts(block, arrays, options), "writing '",
                      path, "': ");
  return WriteFileAtomically(path, contents);
}

absl::Status WriteVtm(const std::string& path, const MultiBlockGrid& grid,
                      std::span<const std::vector<VtkPointArray>> block_arrays,
                      const VtkWriteOptions& options, std::span<const int> block_numbers) {
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
  if (!block_numbers.empty()) {
    if (block_numbers.size() != grid.blocks.size()) {
      return absl::InvalidArgumentError(absl::StrCat("writing '", path, "': ", block_numbers.size(),
                                                     " block numbers for ", grid.blocks.size(),
                                                     " blocks"));
    }
    std::set<int> seen;
    for (int n : block_numbers) {
      if (n < 0 || !seen.insert(n).second) {
        return absl::InvalidArgumentError(
            absl::StrCat("writing '", path, "': block number ", n, " is negative or given twice"));
      }
    }
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
    const int64_t number = block_numbers.empty() ? static_cast<int64_t>(b) : block_numbers[b];
    const std::string file = absl::StrCat(name, "_", number, ".vts");
    const std::span<const VtkPointArray> arrays =
        block_arrays.empty() ? std::span<const VtkPointArray>() : block_arrays[b];
    SG_RETURN_IF_ERROR(WriteVts((directory / file).string(), grid.blocks[b], arrays, options),
                       "block ", number, " of '", path, "': ");
    absl::StrAppend(&xml, "    <DataSet index=\"", b, "\" name=\"block_", number, "\" file=\"",
                    XmlEscape(absl::StrCat(name, "/", file)), "\"/>\n");
  }
  xml += "  </vtkMultiBlockDataSet>\n</VTKFile>\n";
  return WriteFileAtomically(path, xml);
}

}  // namespace splinegrid
