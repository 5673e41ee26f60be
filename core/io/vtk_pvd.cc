#include "core/io/vtk_pvd.h"

#include <charconv>
#include <cmath>
#include <set>

#include "absl/strings/str_cat.h"
#include "core/io/file_util.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

// `text` with the XML special characters of an attribute value escaped.
std::string EscapeAttribute(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out.push_back(c);
    }
  }
  return out;
}

}  // namespace

absl::StatusOr<std::string> EncodePvd(std::span<const PvdEntry> entries) {
  if (entries.empty()) return absl::InvalidArgumentError("PVD collection: no time steps");
  std::set<double> times;
  std::string out =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
  for (size_t e = 0; e < entries.size(); ++e) {
    const PvdEntry& entry = entries[e];
    if (!std::isfinite(entry.time) || !times.insert(entry.time).second) {
      return absl::InvalidArgumentError(absl::StrCat("PVD collection: time step ", e, " ('",
                                                     entry.file, "') has time ", entry.time,
                                                     ", which is not finite or repeats"));
    }
    if (entry.file.empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat("PVD collection: time step ", e, " has no file"));
    }
    char buffer[40];
    char* end = std::to_chars(buffer, buffer + sizeof(buffer), entry.time).ptr;
    absl::StrAppend(&out, "    <DataSet timestep=\"", std::string(buffer, end),
                    "\" group=\"\" part=\"0\" file=\"", EscapeAttribute(entry.file), "\"/>\n");
  }
  out += "  </Collection>\n</VTKFile>\n";
  return out;
}

absl::Status WritePvd(const std::string& path, std::span<const PvdEntry> entries) {
  SG_ASSIGN_OR_RETURN(const std::string text, EncodePvd(entries), "writing '", path, "': ");
  return WriteFileAtomically(path, text);
}

}  // namespace splinegrid
