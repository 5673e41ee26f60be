// The curvature reports: `splinegrid curvature` (a stored grid's walls) and `airfoil` (local).
#include <cstdio>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "client/cli/command_util.h"
#include "client/cli/commands.h"
#include "client/cli/flags.h"
#include "client/cli/output.h"
#include "client/client.h"
#include "core/fit/airfoil/airfoil_fit.h"
#include "core/generate/profile_grid.h"
#include "core/io/airfoil.h"
#include "core/io/file_util.h"
#include "core/util/status_macros.h"

namespace splinegrid::cli {

absl::Status Curvature(const Args& args) {
  const std::string out = absl::GetFlag(FLAGS_o);
  if (args.size() != 1) {
    return Usage(
        "usage: splinegrid curvature NAME [--revision R] [--level L] [--block b] [-o OUT.csv]");
  }
  std::vector<int> blocks;
  if (!absl::GetFlag(FLAGS_block).empty()) {
    for (absl::string_view part : absl::StrSplit(absl::GetFlag(FLAGS_block), ',')) {
      int b;
      if (!absl::SimpleAtoi(part, &b)) {
        return Usage(absl::StrCat("--block: '", part, "' is not an integer"));
      }
      blocks.push_back(b);
    }
  }
  SG_ASSIGN_OR_RETURN(const std::optional<int> level_flag, LevelFlag());
  const int level = level_flag.value_or(2);
  SG_ASSIGN_OR_RETURN(
      const v1::GetWallCurvatureResponse curvature,
      Connect()->WallCurvature(args[0], absl::GetFlag(FLAGS_revision), level, blocks));
  if (!out.empty()) SG_RETURN_IF_ERROR(WriteFileAtomically(out, CurvatureCsv(curvature)));
  Print(FormatCurvature(client::GridName(args[0]), curvature, out), curvature.metrics());
  return absl::OkStatus();
}

absl::Status Airfoil(const Args& args) {
  if (args.size() != 1) {
    return Usage(
        "usage: splinegrid airfoil FILE.dat [--tol T] [--fair tol|LAMBDA|off] [-o OUT.csv]");
  }
  SG_ASSIGN_OR_RETURN(const AirfoilCoordinates coordinates, ReadAirfoilFile(args[0]));
  AirfoilFitOptions options;
  // The default is a fraction of the chord, as GenerateGrid's: a file in millimetres is fitted
  // as one in chords.
  options.tolerance = absl::GetFlag(FLAGS_tol) != 0.0
                          ? absl::GetFlag(FLAGS_tol)
                          : kDefaultProfileFitTolerance * ProfileChord(coordinates.points);
  const std::string fair = absl::GetFlag(FLAGS_fair);
  if (fair == "off") {
    options.fairing.mode = FairingMode::kOff;
  } else if (!fair.empty() && fair != "tol") {
    if (!absl::SimpleAtod(fair, &options.fairing.weight)) {
      return Usage(absl::StrCat("--fair = '", fair, "': give 'tol', 'off' or a weight"));
    }
    options.fairing.mode = FairingMode::kWeight;
  }
  SG_ASSIGN_OR_RETURN(const AirfoilFit fit, FitAirfoil(coordinates.points, options));
  const std::string out = absl::GetFlag(FLAGS_o);
  // The curvature of a fit that missed its tolerance (or has a cusp) is not the profile's: a
  // failure writes no file, and says so.
  if (!out.empty() && fit.met) {
    SG_RETURN_IF_ERROR(WriteFileAtomically(out, AirfoilCurvatureCsv(fit)));
  }
  std::string text = FormatAirfoilFit(coordinates.name, options.tolerance, fit);
  if (!out.empty()) {
    absl::StrAppend(&text, fit.met ? "  curvature written to " : "  curvature not written to ", out,
                    fit.met ? "\n" : " (the fit failed)\n");
  }
  std::fwrite(text.data(), 1, text.size(), stdout);
  return fit.met ? absl::OkStatus()
                 : absl::FailedPreconditionError(absl::StrCat("not met: ", fit.unmet_reason));
}

}  // namespace splinegrid::cli
