// `splinegrid offset`: an O-grid generated around an airfoil file's profile, or a volume grid
// marched off a stored surface grid (GenerateGrid).
#include <filesystem>
#include <optional>

#include "absl/flags/flag.h"
#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "client/cli/cgns_output.h"
#include "client/cli/command_util.h"
#include "client/cli/commands.h"
#include "client/cli/eval_output.h"
#include "client/cli/flags.h"
#include "client/cli/grid_output.h"
#include "client/cli/output.h"
#include "client/client.h"
#include "core/io/airfoil.h"
#include "core/io/file_util.h"
#include "core/util/status_macros.h"

namespace splinegrid::cli {

namespace {

// The profile (an airfoil file) or, for an argument that is no file and no path (or starts
// with grids/), the stored surface grid;
// the new grid's id (--name, else from the file or the surface's id) and display name.
absl::Status SetSource(const std::string& argument, v1::GenerateGridRequest& request) {
  SG_ASSIGN_OR_RETURN(const std::string name, NameFlagId());
  // The surface flags: a profile request that sets them is refused by the server, by name.
  const std::string side = absl::AsciiStrToLower(absl::GetFlag(FLAGS_side));
  if (side == "along") {
    request.set_side(v1::MARCH_SIDE_ALONG_NORMAL);
  } else if (side == "against") {
    request.set_side(v1::MARCH_SIDE_AGAINST_NORMAL);
  } else if (!side.empty() && side != "outward") {
    return Usage(
        absl::StrCat("--side = '", absl::GetFlag(FLAGS_side), "': give outward, along or against"));
  }
  if (const auto v = absl::GetFlag(FLAGS_normal_smoothing)) request.set_normal_smoothing(*v);
  if (const auto v = absl::GetFlag(FLAGS_symmetry)) request.set_symmetry_planes(*v);
  // A grid id has no '.' or '/': anything else is a path (a mistyped one is "no such file").
  const bool path =
      !argument.starts_with("grids/") && (std::filesystem::is_regular_file(argument) ||
                                          argument.find_first_of("./") != std::string::npos);
  if (path) {
    request.set_grid_id(name.empty() ? IdFromPath(argument) : name);
    request.set_display_name(std::filesystem::path(argument).filename().string());
    SG_ASSIGN_OR_RETURN(*request.mutable_airfoil_file(), ReadFileToString(argument));
    // Parsed here too, so that a bad file is named by its path (the server knows only the
    // request's field, airfoil_file).
    SG_RETURN_IF_ERROR(ParseAirfoil(request.airfoil_file(), argument).status());
    return absl::OkStatus();
  }
  const std::string surface = client::GridName(argument);
  request.mutable_stored_surface()->set_name(surface);
  request.set_grid_id(name.empty() ? absl::StrCat(surface.substr(6), "-volume") : name);
  return absl::OkStatus();
}

}  // namespace

absl::Status Offset(const Args& args) {
  constexpr char kUsage[] =
      "usage: splinegrid offset FILE.dat|SURFACE [--name N] [--layers 128] [--first H] "
      "[--far D] [--points 257] [--method offsets|transfinite|elliptic] [--orthogonalize=false] "
      "[--profile_tol T] [--side outward|along|against] [--normal_smoothing 80] "
      "[--symmetry=false] "
      "[--tol T | --kinds [--wall W ...] | --ctl a,b,c] [-o OUT.{vts,vtm,x,xyz,cgns}]";
  if (args.size() != 1) return Usage(kUsage);
  const std::string out = absl::GetFlag(FLAGS_o);
  if (!out.empty()) SG_RETURN_IF_ERROR(CheckGridOutput(out));
  v1::GenerateGridRequest request;
  SG_RETURN_IF_ERROR(SetSource(args[0], request));
  const std::string method = absl::AsciiStrToLower(absl::GetFlag(FLAGS_method));
  if (method == "offsets") {
    request.set_method(v1::LAYER_METHOD_OFFSETS);
  } else if (method == "transfinite") {
    request.set_method(v1::LAYER_METHOD_TRANSFINITE);
  } else if (method == "elliptic") {
    request.set_method(v1::LAYER_METHOD_ELLIPTIC);
  } else if (!method.empty()) {
    return Usage(absl::StrCat("--method = '", absl::GetFlag(FLAGS_method),
                              "': give offsets, transfinite or elliptic"));
  }
  if (const auto v = absl::GetFlag(FLAGS_layers)) request.set_layers(*v);
  if (const auto v = absl::GetFlag(FLAGS_first)) request.set_first_height(*v);
  if (const auto v = absl::GetFlag(FLAGS_far)) request.set_distance(*v);
  if (const auto v = absl::GetFlag(FLAGS_points)) request.set_wall_points(*v);
  if (const auto v = absl::GetFlag(FLAGS_orthogonalize)) request.set_orthogonalize(*v);
  if (const auto v = absl::GetFlag(FLAGS_profile_tol)) request.set_fit_tolerance(*v);
  // The grid fit: the fit flags when given, else the server's default (interpolation).
  SG_ASSIGN_OR_RETURN(v1::FitSpec spec, SpecFromFlags());
  if (spec.resolution_case() != v1::FitSpec::RESOLUTION_NOT_SET || spec.has_fairing()) {
    if (spec.resolution_case() == v1::FitSpec::RESOLUTION_NOT_SET) {
      spec.mutable_boundary_tolerances();
    }
    *request.mutable_spec() = spec;
  }
  request.set_allow_folds(absl::GetFlag(FLAGS_allow_folds));
  auto client = out.empty() ? Connect() : ConnectForEvaluation(OutputCopies(out, true));
  SG_ASSIGN_OR_RETURN(const v1::GenerateGridResponse response, client->Generate(request));
  std::string human =
      request.has_stored_surface() ? FormatGenerateVolume(response) : FormatGenerate(response);
  if (!out.empty()) {
    v1::EvaluateGridRequest evaluate;
    evaluate.set_name(response.grid().name());
    evaluate.set_revision(response.fit().revision());
    evaluate.set_refinement_level(0);
    ProgressLine download("evaluate");
    absl::StatusOr<client::EvaluatedGrid> evaluated =
        client->Evaluate(evaluate, download.callback());
    if (!evaluated.ok()) return ExplainEvaluationLimit(evaluated.status(), out, true);
    client::EvaluatedGrid result = *std::move(evaluated);
    download.Done();
    const int64_t revision = result.revision;
    // Through eval's writers: no source layout (a generated grid has no file), parametric
    // dimensions from the extents; a .cgns carries the grid's connectivity (an O-grid's seam, a
    // volume's block interfaces) as eval writes it.
    std::optional<CgnsOutputContext> cgns;
    if (IsCgnsPath(out)) {
      SG_ASSIGN_OR_RETURN(cgns, FetchCgnsOutputContext(*client, evaluate));
    }
    SG_ASSIGN_OR_RETURN(const int64_t points,
                        WriteGridOutput(out, std::move(result), EvalGridFacts{},
                                        EvalOutputOptions{}, cgns ? &*cgns : nullptr));
    absl::StrAppend(&human, "wrote ", out, ": ", points, " points (revision ", revision, ")\n");
  }
  Print(human, response);
  return StoredNotAsAsked(response.grid().name(), response.fit());
}

}  // namespace splinegrid::cli
