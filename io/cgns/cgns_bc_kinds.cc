// BCType_t names (SIDS 9.7) to boundary kinds, and the file signatures.
#include <array>
#include <string_view>

#include "io/cgns/cgns_io.h"

namespace splinegrid {

std::optional<BoundaryKind> KindOfBcType(const std::string& bc_type) {
  if (bc_type.rfind("BCWall", 0) == 0) return BoundaryKind::kWall;
  static constexpr std::array<std::string_view, 3> kSymmetry = {
      "BCSymmetryPlane", "BCSymmetryPolar", "BCAxisymmetricWedge"};
  for (std::string_view s : kSymmetry) {
    if (bc_type == s) return BoundaryKind::kInterface;
  }
  static constexpr std::array<std::string_view, 15> kOuter = {
      "BCFarfield",          "BCInflow",         "BCInflowSubsonic",
      "BCInflowSupersonic",  "BCOutflow",        "BCOutflowSubsonic",
      "BCOutflowSupersonic", "BCTunnelInflow",   "BCTunnelOutflow",
      "BCExtrapolate",       "BCDegenerateLine", "BCDegeneratePoint",
      "BCDirichlet",         "BCNeumann",        "BCGeneral"};
  for (std::string_view s : kOuter) {
    if (bc_type == s) return BoundaryKind::kOuter;
  }
  return std::nullopt;
}

bool LooksLikeCgns(std::string_view bytes) {
  // HDF5 superblock signature (HDF5 File Format Specification, "Format Signature"): at offset
  // 0, or at 512, 1024, 2048, ... after a user block.
  static constexpr std::string_view kHdf5 = "\x89HDF\r\n\x1a\n";
  for (size_t at :
       {size_t{0}, size_t{512}, size_t{1024}, size_t{2048}, size_t{4096}, size_t{8192}}) {
    if (bytes.size() >= at + kHdf5.size() && bytes.substr(at, kHdf5.size()) == kHdf5) return true;
  }
  // ADF files begin with a "what" string naming the ADF database version.
  return bytes.substr(0, 64).find("ADF Database Version") != std::string_view::npos;
}

}  // namespace splinegrid
