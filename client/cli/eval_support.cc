#include "client/cli/eval_support.h"

#include <stdlib.h>

#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "absl/cleanup/cleanup.h"
#include "absl/flags/flag.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "client/cli/command_line.h"
#include "client/cli/flags.h"
#include "client/cli/grid_output.h"
#include "core/io/file_util.h"
#include "core/io/record_file.h"
#include "core/util/status_macros.h"
#include "proto/convert/archive_convert.h"
#include "splinegrid/v1/archive.pb.h"

namespace splinegrid::cli {
namespace {

// "a:b" -> {a, b} with 0 <= a <= b.
absl::StatusOr<std::pair<int64_t, int64_t>> ParseSteps(const std::string& text) {
  const std::vector<std::string> ends = absl::StrSplit(text, ':');
  int64_t first = 0, last = 0;
  if (ends.size() != 2 || !absl::SimpleAtoi(ends[0], &first) || !absl::SimpleAtoi(ends[1], &last) ||
      first < 0 || last < first) {
    return absl::InvalidArgumentError(
        absl::StrCat("--steps = '", text, "': give a:b with 0 <= a <= b (time steps a to b)"));
  }
  return std::make_pair(first, last);
}

// The source points in the archive at `path` (the records up to the last source chunk).
absl::StatusOr<MultiBlockGrid> ReadArchiveSource(const std::string& path) {
  SG_ASSIGN_OR_RETURN(RecordReader reader, RecordReader::Open(path));
  std::string payload;
  SG_ASSIGN_OR_RETURN(bool more, reader.Next(&payload));
  v1::ArchiveRecord record;
  if (!more || !record.ParseFromString(payload) || !record.has_header()) {
    return absl::InvalidArgumentError(absl::StrCat("archive '", path, "': no header record"));
  }
  SG_ASSIGN_OR_RETURN(SourceAssembler source, SourceAssembler::Create(record.header()));
  while (!source.complete()) {
    SG_ASSIGN_OR_RETURN(more, reader.Next(&payload));
    if (!more || !record.ParseFromString(payload) || !record.has_source()) {
      return absl::InvalidArgumentError(
          absl::StrCat("archive '", path, "': the source points end early"));
    }
    SG_RETURN_IF_ERROR(source.Add(record.source()));
  }
  return std::move(source).Finish();
}

}  // namespace

absl::Status ParseDistributionFlag(const std::string& text, v1::EvaluateGridRequest* request) {
  if (text.empty()) return absl::OkStatus();  // no distributions field: the original clustering
  v1::Distributions* distributions = request->mutable_distributions();
  std::set<std::string> seen;
  for (absl::string_view part : absl::StrSplit(text, ',', absl::SkipEmpty())) {
    const std::vector<std::string> sides = absl::StrSplit(part, absl::MaxSplits('=', 1));
    v1::Distribution* out = nullptr;
    if (sides.size() == 2 && sides[0] == "i") out = distributions->mutable_i();
    if (sides.size() == 2 && sides[0] == "j") out = distributions->mutable_j();
    if (sides.size() == 2 && sides[0] == "k") out = distributions->mutable_k();
    if (out == nullptr) {
      return absl::InvalidArgumentError(
          absl::StrCat("--dist: '", part, "' is not DIR=KIND with DIR i, j or k"));
    }
    if (!seen.insert(sides[0]).second) {
      return absl::InvalidArgumentError(
          absl::StrCat("--dist: direction ", sides[0], " is given twice"));
    }
    const std::vector<std::string> kind = absl::StrSplit(sides[1], ':');
    if (kind.size() == 1 && kind[0] == "original") {
      out->set_kind(v1::Distribution::KIND_ORIGINAL);
    } else if (kind.size() == 1 && kind[0] == "parameter") {
      out->set_kind(v1::Distribution::KIND_UNIFORM_PARAMETER);
    } else if (kind.size() == 1 && kind[0] == "arclength") {
      out->set_kind(v1::Distribution::KIND_UNIFORM_ARC_LENGTH);
    } else if (kind[0] == "geometric" && (kind.size() == 2 || kind.size() == 3)) {
      double first = 0.0;
      if (!absl::SimpleAtod(kind[1], &first)) {
        return absl::InvalidArgumentError(
            absl::StrCat("--dist: '", kind[1], "' in '", part, "' is not a number"));
      }
      if (kind.size() == 3 && kind[2] != "end") {
        return absl::InvalidArgumentError(
            absl::StrCat("--dist: '", kind[2], "' in '", part, "' is not 'end'"));
      }
      out->set_kind(v1::Distribution::KIND_GEOMETRIC);
      out->set_first_spacing(first);
      out->set_from_end(kind.size() == 3);
    } else {
      return absl::InvalidArgumentError(
          absl::StrCat("--dist: '", sides[1], "' in '", part,
                       "' is not original, parameter, arclength or geometric:FIRST[:end]"));
    }
  }
  return absl::OkStatus();
}

bool Redistributes(const v1::EvaluateGridRequest& request) {
  const v1::Distributions& d = request.distributions();
  return d.i().kind() != v1::Distribution::KIND_ORIGINAL ||
         d.j().kind() != v1::Distribution::KIND_ORIGINAL ||
         d.k().kind() != v1::Distribution::KIND_ORIGINAL;
}

bool IsSeriesPath(const std::string& out) {
  return std::filesystem::path(out).extension() == ".pvd";
}

absl::StatusOr<EvalOutputOptions> EvalOutputOptionsFromFlags(const std::string& out,
                                                             v1::EvaluateGridRequest* request) {
  EvalOutputOptions options;
  options.derivatives = absl::GetFlag(FLAGS_derivs);
  options.jacobian = absl::GetFlag(FLAGS_jacobian);
  options.quality = absl::GetFlag(FLAGS_quality);
  options.deviation = absl::GetFlag(FLAGS_deviation);
  options.compress = absl::GetFlag(FLAGS_compress);
  if (options.deviation && (request->has_counts() || request->refinement_level() != 0 ||
                            request->has_index_box() || Redistributes(*request))) {
    return absl::InvalidArgumentError(
        "--deviation is measured at the source points: evaluate with --level 0, no --box and "
        "no --dist");
  }
  const std::string ext = std::filesystem::path(out).extension().string();
  if ((options.jacobian || options.quality || options.deviation) && ext != ".vts" &&
      ext != ".vtm" && ext != ".pvd") {
    return absl::InvalidArgumentError(
        absl::StrCat("-o ", out,
                     ": --jacobian, --quality and --deviation are VTK fields; write "
                     ".vts, .vtm or .pvd"));
  }
  // zlib is a storage option of VTK XML files: refused, not ignored, for Plot3D and CGNS.
  if (FlagGiven("compress") && ext != ".vts" && ext != ".vtm" && ext != ".pvd") {
    return absl::InvalidArgumentError(
        absl::StrCat("-o ", out, ": ", options.compress ? "--compress" : "--nocompress",
                     " applies to VTK files (.vts, .vtm, .pvd) only; drop it for this output"));
  }
  if (IsSeriesPath(out) == absl::GetFlag(FLAGS_steps).empty()) {
    return absl::InvalidArgumentError(
        "a time series takes both --steps a:b and -o NAME.pvd (and only a series writes .pvd)");
  }
  if (IsSeriesPath(out) && (request->revision() != 0 || request->has_step())) {
    return absl::InvalidArgumentError("--steps selects the revisions; drop --revision/--step");
  }
  request->set_derivatives(options.derivatives || options.jacobian);
  return options;
}

absl::StatusOr<EvalGridFacts> FetchEvalFacts(client::Client& client,
                                             const v1::EvaluateGridRequest& request,
                                             const EvalOutputOptions& options) {
  v1::GetGridRequest get;
  get.set_name(request.name());
  get.set_view(v1::GRID_VIEW_BASIC);
  get.set_revision(request.revision());
  if (request.has_step()) get.set_step(request.step());
  SG_ASSIGN_OR_RETURN(const v1::Grid grid, client.Get(get));
  SG_ASSIGN_OR_RETURN(EvalGridFacts facts, EvalFactsFromGrid(grid));
  if (options.deviation && grid.revision().origin() == v1::REVISION_ORIGIN_DEFORM) {
    std::fprintf(stderr,
                 "note: revision %lld is deformed: its deviation from the imported points is "
                 "mostly the deformation\n",
                 static_cast<long long>(grid.revision().revision()));
  }
  if (options.deviation) {
    // The archive goes to a private directory (mkdtemp: mode 0700, an unpredictable name under
    // $TMPDIR), so that no other user can read, replace or pre-create it; the directory and
    // whatever ExportGrid left in it are removed on every path out of this block.
    std::error_code error;  // the overload that does not throw for a TMPDIR that is no directory
    const std::filesystem::path temp = std::filesystem::temp_directory_path(error);
    if (error) {
      return ErrnoToStatusWithMessage(
          error.value(), "--deviation: no temporary directory (set TMPDIR to a writable one)");
    }
    std::string directory = (temp / "splinegrid-eval-XXXXXX").string();
    if (mkdtemp(directory.data()) == nullptr) {
      return ErrnoToStatusWithMessage(
          errno, absl::StrCat("--deviation: cannot create a temporary directory '", directory,
                              "' (set TMPDIR to a writable directory)"));
    }
    const absl::Cleanup remove_directory = [&directory] {
      std::error_code ignored;
      std::filesystem::remove_all(directory, ignored);
    };
    const std::string path = (std::filesystem::path(directory) / "source.sgrid").string();
    SG_RETURN_IF_ERROR(client.ExportGrid(request.name(), path).status());
    SG_ASSIGN_OR_RETURN(MultiBlockGrid source, ReadArchiveSource(path));
    facts.source = std::move(source);
  }
  return facts;
}

absl::StatusOr<std::string> RunEvalSeries(client::Client& client, v1::EvaluateGridRequest request,
                                          const std::string& out, const EvalGridFacts& facts,
                                          const EvalOutputOptions& options) {
  SG_ASSIGN_OR_RETURN(const auto range, ParseSteps(absl::GetFlag(FLAGS_steps)));
  v1::GetGridRequest get;
  get.set_name(request.name());
  get.set_view(v1::GRID_VIEW_BASIC);
  SG_ASSIGN_OR_RETURN(const v1::Grid grid, client.Get(get));
  // The latest deformed revision of each step, as --step picks it.
  std::map<int64_t, const v1::RevisionInfo*> by_step;
  for (const v1::RevisionInfo& info : grid.revisions()) {
    if (info.origin() != v1::REVISION_ORIGIN_DEFORM) continue;
    if (info.step() < range.first || info.step() > range.second) continue;
    const v1::RevisionInfo*& latest = by_step[info.step()];
    if (latest == nullptr || latest->revision() < info.revision()) latest = &info;
  }
  if (by_step.empty()) {
    return absl::NotFoundError(absl::StrCat(grid.name(), " has no deformed revision of steps ",
                                            range.first, " to ", range.second));
  }
  std::vector<SeriesStep> steps;
  for (const auto& [step, info] : by_step) steps.push_back({step, info->time(), info->revision()});
  request.clear_step();
  auto evaluate = [&](const SeriesStep& step) -> absl::StatusOr<client::EvaluatedGrid> {
    request.set_revision(step.revision);
    absl::StatusOr<client::EvaluatedGrid> result = client.Evaluate(request);
    if (!result.ok()) return ExplainEvaluationLimit(result.status(), out, options.compress);
    return result;
  };
  std::string note;
  const int64_t written_steps = static_cast<int64_t>(steps.size());
  SG_ASSIGN_OR_RETURN(const int64_t points,
                      WriteSeries(out, steps, evaluate, facts, options, &note));
  const int64_t missing = range.second - range.first + 1 - written_steps;
  std::string summary = absl::StrCat("wrote ", out, ": ", written_steps, " time step(s) (steps ",
                                     by_step.begin()->first, " to ", by_step.rbegin()->first, "), ",
                                     points, " points\n");
  if (missing > 0) {
    absl::StrAppend(&summary, "note: ", missing, " step(s) from ", range.first, " to ",
                    range.second, " have no deformed revision (retention or not deformed)\n");
  }
  if (!note.empty()) absl::StrAppend(&summary, "note: ", note, "\n");
  return summary;
}

}  // namespace splinegrid::cli
