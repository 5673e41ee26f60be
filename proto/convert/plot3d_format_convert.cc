#include "proto/convert/plot3d_format_convert.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace splinegrid {
namespace {

absl::Status Invalid(const std::string& field, const std::string& what) {
  return absl::InvalidArgumentError(absl::StrCat(field, ".", what));
}

}  // namespace

std::optional<Plot3dLayout> Plot3dLayoutFromProto(v1::Plot3dLayout layout) {
  switch (layout) {
    case v1::PLOT3D_LAYOUT_WHOLE:
      return Plot3dLayout::kWhole;
    case v1::PLOT3D_LAYOUT_PLANES:
      return Plot3dLayout::kPlanes;
    default:
      return std::nullopt;
  }
}

v1::Plot3dLayout Plot3dLayoutToProto(Plot3dLayout layout) {
  return layout == Plot3dLayout::kPlanes ? v1::PLOT3D_LAYOUT_PLANES : v1::PLOT3D_LAYOUT_WHOLE;
}

void EncodePlot3dSourceFormat(const Plot3dSourceFormat& format, v1::Plot3dFileFormat* out) {
  const Plot3dFormat& file = format.file;
  switch (file.encoding) {
    case Plot3dEncoding::kAscii:
      out->set_encoding(v1::PLOT3D_ENCODING_ASCII);
      break;
    case Plot3dEncoding::kBinaryLittleEndian:
      out->set_encoding(v1::PLOT3D_ENCODING_BINARY_LITTLE_ENDIAN);
      break;
    case Plot3dEncoding::kBinaryBigEndian:
      out->set_encoding(v1::PLOT3D_ENCODING_BINARY_BIG_ENDIAN);
      break;
  }
  out->set_spatial_dim(file.spatial_dim);
  out->set_has_block_count(file.has_block_count);
  out->set_has_iblank(file.has_iblank);
  out->set_bytes_per_real(file.bytes_per_real);
  out->set_c_stream(file.framing == Plot3dFraming::kCStream);
  out->set_layout(Plot3dLayoutToProto(file.layout));
  for (const TwoPlaneLayout& planes : format.two_planes) {
    v1::TwoPlaneLayout* p = out->add_two_planes();
    p->set_plane_direction(planes.plane_direction);
    p->set_normal_coordinate(planes.normal_coordinate);
    p->set_plane_value_0(planes.plane_values[0]);
    p->set_plane_value_1(planes.plane_values[1]);
  }
}

absl::StatusOr<Plot3dSourceFormat> ParsePlot3dSourceFormat(const v1::Plot3dFileFormat& in,
                                                           int num_blocks,
                                                           const std::string& field) {
  Plot3dSourceFormat format;
  Plot3dFormat& file = format.file;
  switch (in.encoding()) {
    case v1::PLOT3D_ENCODING_ASCII:
      file.encoding = Plot3dEncoding::kAscii;
      break;
    case v1::PLOT3D_ENCODING_BINARY_LITTLE_ENDIAN:
      file.encoding = Plot3dEncoding::kBinaryLittleEndian;
      break;
    case v1::PLOT3D_ENCODING_BINARY_BIG_ENDIAN:
      file.encoding = Plot3dEncoding::kBinaryBigEndian;
      break;
    default:
      return Invalid(field, absl::StrCat("encoding = ", in.encoding(), " is not a known encoding"));
  }
  if (in.spatial_dim() != 2 && in.spatial_dim() != 3) {
    return Invalid(field, absl::StrCat("spatial_dim = ", in.spatial_dim(), " must be 2 or 3"));
  }
  if (in.bytes_per_real() != 4 && in.bytes_per_real() != 8) {
    return Invalid(field,
                   absl::StrCat("bytes_per_real = ", in.bytes_per_real(), " must be 4 or 8"));
  }
  file.spatial_dim = in.spatial_dim();
  file.has_block_count = in.has_block_count();
  file.has_iblank = in.has_iblank();
  file.bytes_per_real = in.bytes_per_real();
  file.framing = in.c_stream() ? Plot3dFraming::kCStream : Plot3dFraming::kFortranRecords;
  file.layout = Plot3dLayoutFromProto(in.layout()).value_or(Plot3dLayout::kWhole);
  if (in.two_planes_size() == 0) return format;
  if (in.two_planes_size() != num_blocks || file.spatial_dim != 3) {
    return Invalid(field,
                   absl::StrCat("two_planes has ", in.two_planes_size(), " entries; a 3D file of ",
                                num_blocks, " blocks needs none or one per block"));
  }
  for (int b = 0; b < in.two_planes_size(); ++b) {
    const v1::TwoPlaneLayout& p = in.two_planes(b);
    const std::string at = absl::StrCat("two_planes[", b, "]");
    if (p.plane_direction() < 0 || p.plane_direction() > 2 || p.normal_coordinate() < 0 ||
        p.normal_coordinate() > 2) {
      return Invalid(field, absl::StrCat(at, ": plane_direction ", p.plane_direction(),
                                         " and normal_coordinate ", p.normal_coordinate(),
                                         " must be from 0 to 2"));
    }
    if (!std::isfinite(p.plane_value_0()) || !std::isfinite(p.plane_value_1()) ||
        p.plane_value_0() == p.plane_value_1()) {
      return Invalid(field, absl::StrCat(at, ": plane values ", p.plane_value_0(), " and ",
                                         p.plane_value_1(), " must be finite and differ"));
    }
    format.two_planes.push_back(TwoPlaneLayout{
        p.plane_direction(), p.normal_coordinate(), {p.plane_value_0(), p.plane_value_1()}});
  }
  return format;
}

}  // namespace splinegrid
