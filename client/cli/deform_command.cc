// `splinegrid deform`: a rigid motion of part of a grid's boundary, with --boundary parsed here.
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "client/cli/command_util.h"
#include "client/cli/commands.h"
#include "client/cli/flags.h"
#include "client/cli/output.h"
#include "client/client.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"

namespace splinegrid::cli {

namespace {

// "0.25,0" -> {0.25, 0}: `min` to `max` comma-separated numbers; `what` names the flag.
absl::StatusOr<std::vector<double>> ParseNumbers(const std::string& text, const std::string& what,
                                                 int min, int max) {
  std::vector<double> values;
  for (absl::string_view part : absl::StrSplit(text, ',')) {
    double v;
    if (!absl::SimpleAtod(part, &v) || !std::isfinite(v)) {
      return Usage(absl::StrCat(what, " = '", text, "': '", part, "' is not a finite number"));
    }
    values.push_back(v);
  }
  if (static_cast<int>(values.size()) < min || static_cast<int>(values.size()) > max) {
    return Usage(absl::StrCat(what, " = '", text, "': give ",
                              min == max ? absl::StrCat(min) : absl::StrCat(min, " or ", max),
                              " comma-separated numbers"));
  }
  return values;
}

constexpr char kDeformUsage[] =
    "usage: splinegrid deform NAME --rotate DEG [--about X,Y[,Z]] [--axis X,Y,Z] "
    "[--translate DX,DY[,DZ]] [--boundary wall|outer|interface|B:FACE[:A0:A1[:B0:B1]],...] "
    "[--reference R] [--base R] [--time T] [--step N] [--check_level L] "
    "[--propagation blend|transfinite] [--decay_radius D] [--rigid_radius R] [--smoothing N]";

// "jmin", "J_MIN", "j-min" -> BLOCK_FACE_J_MIN.
std::optional<v1::BlockFace> ParseFaceName(std::string text) {
  text = absl::AsciiStrToLower(text);
  std::erase_if(text, [](char c) { return c == '_' || c == '-'; });
  static const std::map<std::string, v1::BlockFace> kFaces = {
      {"imin", v1::BLOCK_FACE_I_MIN}, {"imax", v1::BLOCK_FACE_I_MAX},
      {"jmin", v1::BLOCK_FACE_J_MIN}, {"jmax", v1::BLOCK_FACE_J_MAX},
      {"kmin", v1::BLOCK_FACE_K_MIN}, {"kmax", v1::BLOCK_FACE_K_MAX}};
  const auto it = kFaces.find(text);
  if (it == kFaces.end()) return std::nullopt;
  return it->second;
}

// --boundary: kinds ("wall,outer") or face ranges ("0:jmin:0:256,..."). A range without index
// ranges covers its whole face: the block's extents come from the server (`extents`, asked for
// only then).
absl::StatusOr<v1::BoundarySelection> ParseBoundaryFlag(
    const std::string& text, const std::function<absl::StatusOr<v1::Grid>()>& grid) {
  v1::BoundarySelection selection;
  if (text.empty()) return selection;
  std::optional<v1::Grid> fetched;
  for (absl::string_view item : absl::StrSplit(text, ',')) {
    const std::string part(item);
    const std::string lower = absl::AsciiStrToLower(part);
    if (lower == "wall" || lower == "outer" || lower == "interface") {
      selection.add_kinds(lower == "wall"    ? v1::BOUNDARY_KIND_WALL
                          : lower == "outer" ? v1::BOUNDARY_KIND_OUTER
                                             : v1::BOUNDARY_KIND_INTERFACE);
      continue;
    }
    const std::vector<std::string> fields = absl::StrSplit(part, ':');
    const std::string bad = absl::StrCat("--boundary: '", part, "' is neither wall, outer, ",
                                         "interface nor a range BLOCK:FACE[:A0:A1[:B0:B1]]");
    if (fields.size() != 2 && fields.size() != 4 && fields.size() != 6) return Usage(bad);
    int block;
    if (!absl::SimpleAtoi(fields[0], &block) || block < 0) {
      return Usage(absl::StrCat(bad, " ('", fields[0], "' is not a block index)"));
    }
    const std::optional<v1::BlockFace> face = ParseFaceName(fields[1]);
    if (!face) {
      return Usage(absl::StrCat(bad, " ('", fields[1], "' is not imin, imax, jmin, jmax, kmin ",
                                "or kmax)"));
    }
    const int normal = (*face - 1) / 2;
    const bool upper = (*face - 1) % 2 == 1;
    // The face's tangential directions in i, j, k order, and their ranges.
    int tangential[2], n = 0;
    for (int d = 0; d < 3; ++d) {
      if (d != normal) tangential[n++] = d;
    }
    Extents begin = {0, 0, 0}, end = {0, 0, 0};
    const int given = (static_cast<int>(fields.size()) - 2) / 2;
    for (int t = 0; t < given; ++t) {
      const int d = tangential[t];
      if (!absl::SimpleAtoi(fields[2 + 2 * t], &begin[d]) ||
          !absl::SimpleAtoi(fields[3 + 2 * t], &end[d]) || begin[d] < 0 || end[d] < begin[d]) {
        return Usage(absl::StrCat(bad, " ('", fields[2 + 2 * t], ":", fields[3 + 2 * t],
                                  "' is not an index range a:b with 0 <= a <= b)"));
      }
    }
    if (given < 2) {  // the rest of the face: from the block's extents
      if (!fetched) {
        SG_ASSIGN_OR_RETURN(fetched, grid());
      }
      if (block >= fetched->source().blocks_size()) {
        return Usage(absl::StrCat("--boundary: '", part, "': block ", block, " is outside [0, ",
                                  fetched->source().blocks_size() - 1, "]"));
      }
      const v1::Extents& e = fetched->source().blocks(block);
      const int extent[3] = {e.i(), e.j(), e.k()};
      for (int t = given; t < 2; ++t) end[tangential[t]] = std::max(extent[tangential[t]] - 1, 0);
      if (upper) begin[normal] = end[normal] = std::max(extent[normal] - 1, 0);
    }
    v1::FaceRange* range = selection.add_ranges();
    range->set_block(block);
    range->set_face(*face);
    EncodeExtents(begin, range->mutable_begin());
    EncodeExtents(end, range->mutable_end());
  }
  if (selection.kinds_size() > 0 && selection.ranges_size() > 0) {
    return Usage("--boundary: give boundary kinds or face ranges, not both");
  }
  return selection;
}

}  // namespace

absl::Status Deform(const Args& args) {
  if (args.size() != 1) return Usage(kDeformUsage);
  v1::DeformGridRequest request;
  request.set_name(client::GridName(args[0]));
  request.set_reference_revision(absl::GetFlag(FLAGS_reference));
  request.set_base_revision(absl::GetFlag(FLAGS_base));
  request.set_time(absl::GetFlag(FLAGS_time));
  request.set_step(absl::GetFlag(FLAGS_step).value_or(0));
  request.set_check_level(absl::GetFlag(FLAGS_check_level));
  request.set_decay_radius(absl::GetFlag(FLAGS_decay_radius));
  request.set_rigid_radius(absl::GetFlag(FLAGS_rigid_radius));
  request.set_smoothing_iterations(absl::GetFlag(FLAGS_smoothing));
  const std::string propagation = absl::AsciiStrToLower(absl::GetFlag(FLAGS_propagation));
  if (propagation == "blend" || propagation.empty()) {
    request.set_propagation(v1::PROPAGATION_BLEND);
  } else if (propagation == "transfinite") {
    request.set_propagation(v1::PROPAGATION_TRANSFINITE);
  } else {
    return Usage(absl::StrCat("--propagation = '", absl::GetFlag(FLAGS_propagation),
                              "': give blend or transfinite"));
  }
  v1::RigidMotion* rigid = request.mutable_rigid();
  const std::optional<double> rotate = absl::GetFlag(FLAGS_rotate);
  rigid->set_angle_degrees(rotate.value_or(0.0));
  if (!std::isfinite(rigid->angle_degrees())) return Usage("--rotate must be finite");
  const struct {
    std::string text;
    const char* flag;
    int min, max;
    google::protobuf::RepeatedField<double>* into;
  } vectors[] = {
      {absl::GetFlag(FLAGS_about), "--about", 2, 3, rigid->mutable_center()},
      {absl::GetFlag(FLAGS_axis), "--axis", 3, 3, rigid->mutable_axis()},
      {absl::GetFlag(FLAGS_translate), "--translate", 2, 3, rigid->mutable_translation()},
  };
  for (const auto& v : vectors) {
    if (v.text.empty()) continue;
    SG_ASSIGN_OR_RETURN(const std::vector<double> values,
                        ParseNumbers(v.text, v.flag, v.min, v.max));
    v.into->Assign(values.begin(), values.end());
  }
  // Given, even as 0 (a solver's step at rest: the C and Python clients store it too).
  if (!rotate.has_value() && rigid->translation().empty()) {
    return Usage(absl::StrCat("give --rotate and/or --translate\n", kDeformUsage));
  }
  auto client = Connect();
  SG_ASSIGN_OR_RETURN(*request.mutable_boundary(),
                      ParseBoundaryFlag(absl::GetFlag(FLAGS_boundary),
                                        [&] { return client->Get(request.name()); }));
  SG_ASSIGN_OR_RETURN(const v1::DeformGridResponse response, client->Deform(request));
  Print(FormatDeform(request.name(), request, response), response);
  return absl::OkStatus();
}

}  // namespace splinegrid::cli
