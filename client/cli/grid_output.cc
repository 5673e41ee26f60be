#include "client/cli/grid_output.h"

#include <filesystem>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid::cli {

absl::Status CheckGridOutput(const std::string& out, absl::string_view also) {
  const std::string ext = std::filesystem::path(out).extension().string();
  if (ext != ".vts" && ext != ".vtm" && ext != ".x" && ext != ".xyz" && ext != ".cgns") {
    return absl::InvalidArgumentError(
        absl::StrCat("-o ", out, ": the extension must be .vts, .vtm, .x, .xyz or .cgns", also));
  }
  // Checked before a call that stores something (offset), so a typo does not leave a grid
  // stored and its file unwritten.
  const std::filesystem::path dir = std::filesystem::path(out).parent_path();
  if (!dir.empty() && !std::filesystem::is_directory(dir)) {
    return absl::NotFoundError(
        absl::StrCat("-o ", out, ": the directory ", dir.string(), " does not exist"));
  }
  return absl::OkStatus();
}

absl::StatusOr<int64_t> WriteGridOutput(const std::string& out, client::EvaluatedGrid result,
                                        const EvalGridFacts& facts,
                                        const EvalOutputOptions& options,
                                        const CgnsOutputContext* cgns) {
  SG_RETURN_IF_ERROR(CheckGridOutput(out));
  if (IsCgnsPath(out)) return WriteCgnsOutput(out, std::move(result), cgns);
  return WriteEvaluation(out, std::move(result), facts, options);
}

double OutputCopies(const std::string& out, bool compress) {
  if (IsCgnsPath(out)) return 2.5;
  if (absl::EndsWith(out, ".xyz")) return 9.5;
  if (absl::EndsWith(out, ".x")) return 7.0;
  return compress ? 5.0 : 6.5;  // .vts, .vtm (and each step of a .pvd series)
}

absl::Status ExplainEvaluationLimit(absl::Status status, const std::string& out, bool compress) {
  if (!absl::IsResourceExhausted(status) ||
      !absl::StrContains(status.message(), "this client may hold")) {
    return status;
  }
  return absl::Status(
      status.code(), absl::StrCat(status.message(), "; writing ", out, " holds about ",
                                  OutputCopies(out, compress),
                                  " copies of the values (--max_memory_mb sets what may be used)"));
}

}  // namespace splinegrid::cli
