// `splinegrid fit` (import a file and fit it, or fit a stored grid again) and `splinegrid fair`
// (refit a stored grid with fairing).
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "absl/flags/flag.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "client/cli/cgns_output.h"
#include "client/cli/command_line.h"
#include "client/cli/command_util.h"
#include "client/cli/commands.h"
#include "client/cli/flags.h"
#include "client/cli/output.h"
#include "client/client.h"
#include "core/io/file_util.h"
#include "core/util/status_macros.h"
#include "io/cgns/cgns_io.h"

namespace splinegrid::cli {

namespace {

// --plot3d_layout: "" (detect), "whole" or "planes".
absl::StatusOr<v1::Plot3dLayout> Plot3dLayoutFlag() {
  const std::string text = absl::GetFlag(FLAGS_plot3d_layout);
  if (text.empty()) return v1::PLOT3D_LAYOUT_UNSPECIFIED;
  if (text == "whole") return v1::PLOT3D_LAYOUT_WHOLE;
  if (text == "planes") return v1::PLOT3D_LAYOUT_PLANES;
  return Usage(absl::StrCat("--plot3d_layout = '", text, "': give whole or planes"));
}

// Whether `text` could be a stored grid's name: "grids/ID" or ID, ID of [a-z0-9-] starting with
// a letter (the server's rule); a path with a directory or an extension is not.
bool LooksLikeGridName(const std::string& text) {
  const std::string id = client::GridId(text);
  if (id.empty() || id.size() > 63 || !std::islower(static_cast<unsigned char>(id[0])))
    return false;
  return std::all_of(id.begin(), id.end(), [](char c) {
    return std::islower(static_cast<unsigned char>(c)) ||
           std::isdigit(static_cast<unsigned char>(c)) || c == '-';
  });
}

// `splinegrid fit NAME`: fits the source points of a stored grid again (a new revision), e.g.
// one imported by a fit that was interrupted, or with other tolerances.
absl::Status FitStored(const std::string& name, const v1::FitSpec& spec) {
  for (const char* flag : {"name", "planar", "plot3d_layout"}) {
    if (FlagGiven(flag)) {
      return Usage(absl::StrCat("--", flag, " is about importing a file; ", client::GridName(name),
                                " is a stored grid: drop --", flag));
    }
  }
  SG_ASSIGN_OR_RETURN(const v1::FitGridResponse fit, Connect()->Fit(name, spec));
  Print(FormatFit(client::GridName(name), fit), fit);
  return StoredNotAsAsked(client::GridName(name), fit);
}

}  // namespace

absl::Status Fit(const Args& args) {
  if (args.size() != 1) {
    return Usage(
        "usage: splinegrid fit FILE|NAME [--name N] [--tol T | --kinds [--wall W ...] | "
        "--ctl a,b,c] [--fair tol|LAMBDA]");
  }
  const std::string& path = args[0];
  SG_ASSIGN_OR_RETURN(const v1::FitSpec spec, SpecFromFlags());
  SG_ASSIGN_OR_RETURN(const std::string named, NameFlagId());
  // Not a file but a grid's name: that stored grid is fitted again.
  std::error_code no_file;
  if (!std::filesystem::exists(path, no_file) && LooksLikeGridName(path)) {
    absl::Status fitted = FitStored(path, spec);
    if (fitted.code() == absl::StatusCode::kNotFound &&
        absl::StrContains(fitted.message(), client::GridName(path))) {
      return absl::NotFoundError(
          absl::StrCat(path, " is neither a file nor a stored grid (", fitted.message(), ")"));
    }
    return fitted;
  }
  SG_ASSIGN_OR_RETURN(const std::string bytes, ReadFileToString(path));
  if (bytes.empty()) {  // the server would name only its header field, total_bytes = 0
    return absl::InvalidArgumentError(absl::StrCat(path, " is empty: no grid to fit"));
  }
  const std::string id = named.empty() ? IdFromPath(path) : named;
  auto client = Connect();
  // A CGNS file (by extension or signature) is decoded by the server, BCs included; it is
  // stored as its zones are (--planar is about two-plane Plot3D files).
  const bool cgns = IsCgnsPath(path) || LooksLikeCgns(bytes);
  if (cgns && !LooksLikeCgns(bytes)) {
    return absl::InvalidArgumentError(absl::StrCat(
        path,
        " is named .cgns but is not a CGNS file: it starts with neither the HDF5 signature "
        "nor an ADF header (a Plot3D file is recognised by its content under another name)"));
  }
  // Plot3D read options given for a CGNS file would be ignored: refused instead (the defaults,
  // --planar=true included, are not "given").
  for (const char* flag : {"planar", "plot3d_layout"}) {
    if (cgns && FlagGiven(flag)) {
      return Usage(absl::StrCat("--", flag, " is about Plot3D files; ", path,
                                " is CGNS (stored as its zones are): drop --", flag));
    }
  }
  // --plot3d_layout: the value order of 3D text and C-stream files (Fortran records show it).
  SG_ASSIGN_OR_RETURN(const v1::Plot3dLayout layout, Plot3dLayoutFlag());
  // --planar: the server stores the planar view of two-plane files, anything else as read.
  v1::Plot3dSource plot3d_options;
  plot3d_options.set_planar_view_if_two_planes(absl::GetFlag(FLAGS_planar));
  plot3d_options.set_layout(layout);
  ProgressLine upload("upload");
  const std::string grid_id = client::GridName(id).substr(6);
  const std::string display_name = std::filesystem::path(path).filename().string();
  absl::StatusOr<v1::Grid> imported =
      cgns ? client->ImportCgns(bytes, grid_id, display_name, upload.callback())
           : client->ImportPlot3d(bytes, grid_id, display_name, plot3d_options, upload.callback());
  upload.Done();
  if (imported.status().code() == absl::StatusCode::kAlreadyExists) {
    return absl::AlreadyExistsError(absl::StrCat(
        imported.status().message(), ": to fit its stored points again, `splinegrid fit ", grid_id,
        "` (with the tolerance flags); to replace it, `splinegrid rm ", grid_id,
        "` first, or import under another --name"));
  }
  SG_RETURN_IF_ERROR(imported.status());
  const v1::Grid& grid = *imported;
  // What the import mapped with a choice or left out (CGNS), never silently.
  for (const std::string& note : grid.source().boundaries().notes()) {
    std::fprintf(stderr, "note: %s\n", note.c_str());
  }
  absl::StatusOr<v1::FitGridResponse> fit = client->Fit(grid.name(), spec);
  if (!fit.ok()) {
    (void)client->Delete(grid.name());  // do not leave an unfitted grid behind
    return fit.status();
  }
  Print(FormatFit(grid.name(), *fit), *fit);
  return StoredNotAsAsked(grid.name(), *fit);
}

absl::Status Fair(const Args& args) {
  if (args.size() != 1)
    return Usage("usage: splinegrid fair NAME [--revision R] [--fair tol|LAMBDA]");
  SG_ASSIGN_OR_RETURN(const std::optional<v1::Fairing> fairing, ParseFairFlag());
  SG_ASSIGN_OR_RETURN(
      const v1::FitGridResponse fit,
      Connect()->Fair(args[0], absl::GetFlag(FLAGS_revision), fairing ? &*fairing : nullptr,
                      absl::GetFlag(FLAGS_allow_folds)));
  Print(FormatFit(client::GridName(args[0]), fit), fit);
  return StoredNotAsAsked(client::GridName(args[0]), fit);
}

}  // namespace splinegrid::cli
