// `splinegrid eval`: the EvaluateGrid request from the flags, then one output file or a series.
#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "client/cli/cgns_output.h"
#include "client/cli/command_util.h"
#include "client/cli/commands.h"
#include "client/cli/eval_output.h"
#include "client/cli/eval_support.h"
#include "client/cli/flags.h"
#include "client/cli/grid_output.h"
#include "client/cli/output.h"
#include "client/client.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"

namespace splinegrid::cli {

namespace {

// --res and --box give a value for every direction of the grid (its largest parametric
// dimension): left out, a 2-D grid's j read as one point (--res 10: a line of 10 points at
// j = 0) or as the range 0:0 (--box 0:5), without a word.
absl::Status CheckEveryDirectionGiven(const EvalGridFacts& facts, const std::string& name) {
  int dims = 1;
  for (const auto& [block, dim] : facts.parametric_dim) dims = std::max(dims, dim);
  for (const auto& [flag, text, what] : {std::tuple{"res", absl::GetFlag(FLAGS_res), "counts"},
                                         std::tuple{"box", absl::GetFlag(FLAGS_box), "ranges"}}) {
    if (text.empty()) continue;
    const int given = static_cast<int>(std::vector<std::string>(absl::StrSplit(text, ',')).size());
    if (given < dims) {
      return Usage(absl::StrCat("--", flag, " = '", text, "' gives ", given, " of the ", dims,
                                " directions of ", name, ": give ", dims, " ", what, " (i,j",
                                dims == 3 ? ",k" : "", ")"));
    }
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status Eval(const Args& args) {
  const std::string out = absl::GetFlag(FLAGS_o);
  if (args.size() != 1 || out.empty()) {
    return Usage(
        "usage: splinegrid eval NAME (--level L | --res a,b,c) [--revision R | --step N] "
        "[--block b] [--box ...] [--dist DIR=KIND,...] [--derivs] [--jacobian] [--quality] "
        "[--deviation] [--nocompress] "
        "-o OUT.{vts,vtm,x,xyz,cgns}, or --steps A:B -o OUT.pvd");
  }
  v1::EvaluateGridRequest request;
  request.set_name(args[0]);
  SG_RETURN_IF_ERROR(RevisionOrStep([&](int64_t r) { request.set_revision(r); },
                                    [&](int64_t s) { request.set_step(s); }));
  SG_ASSIGN_OR_RETURN(const std::optional<int> level, LevelFlag());
  if (level.has_value() == !absl::GetFlag(FLAGS_res).empty()) {
    return Usage("give exactly one of --level and --res");
  }
  if (level.has_value()) {
    request.set_refinement_level(*level);
  } else {
    SG_ASSIGN_OR_RETURN(const Extents counts, ResolutionFlag());
    request.mutable_counts()->set_i(counts[0]);
    request.mutable_counts()->set_j(counts[1]);
    request.mutable_counts()->set_k(counts[2]);
  }
  if (!absl::GetFlag(FLAGS_block).empty()) {
    for (absl::string_view part : absl::StrSplit(absl::GetFlag(FLAGS_block), ',')) {
      int b;
      if (!absl::SimpleAtoi(part, &b))
        return Usage(absl::StrCat("--block: '", part, "' is not an integer"));
      request.add_blocks(b);
    }
  }
  if (!absl::GetFlag(FLAGS_box).empty()) {
    const std::vector<std::string> ranges = absl::StrSplit(absl::GetFlag(FLAGS_box), ',');
    v1::IndexBox* box = request.mutable_index_box();
    Extents begin = {0, 0, 0}, end = {0, 0, 0};
    if (ranges.size() > 3) return Usage("--box: at most three ranges i0:i1,j0:j1,k0:k1");
    for (size_t d = 0; d < ranges.size(); ++d) {
      const std::vector<std::string> ends = absl::StrSplit(ranges[d], ':');
      if (ends.size() != 2 || !absl::SimpleAtoi(ends[0], &begin[d]) ||
          !absl::SimpleAtoi(ends[1], &end[d])) {
        return Usage(absl::StrCat("--box: '", ranges[d], "' is not a range a:b"));
      }
    }
    EncodeExtents(begin, box->mutable_begin());
    EncodeExtents(end, box->mutable_end());
  }
  SG_RETURN_IF_ERROR(ParseDistributionFlag(absl::GetFlag(FLAGS_dist), &request));
  request.set_derivatives(absl::GetFlag(FLAGS_derivs));
  request.set_precision(absl::GetFlag(FLAGS_float32) ? v1::PRECISION_FLOAT : v1::PRECISION_DOUBLE);
  // Output fields, the source's Plot3D layout and ParaView time series (eval_support.h).
  SG_ASSIGN_OR_RETURN(const EvalOutputOptions eval_options,
                      EvalOutputOptionsFromFlags(out, &request));
  if (IsSeriesPath(out)) {
    // One step at a time is held (WriteSeries), with its writer's copies.
    auto series_client = ConnectForEvaluation(OutputCopies(out, eval_options.compress));
    SG_ASSIGN_OR_RETURN(const EvalGridFacts facts,
                        FetchEvalFacts(*series_client, request, eval_options));
    SG_RETURN_IF_ERROR(CheckEveryDirectionGiven(facts, args[0]));
    SG_ASSIGN_OR_RETURN(const std::string summary,
                        RunEvalSeries(*series_client, request, out, facts, eval_options));
    std::fwrite(summary.data(), 1, summary.size(), stdout);
    return absl::OkStatus();
  }
  SG_RETURN_IF_ERROR(CheckGridOutput(out, ", or .pvd with --steps A:B"));
  auto client = ConnectForEvaluation(OutputCopies(out, eval_options.compress));
  // A CGNS file also carries the grid's boundary conditions and connectivity at the level.
  std::optional<CgnsOutputContext> cgns;
  if (IsCgnsPath(out)) {
    SG_ASSIGN_OR_RETURN(cgns, FetchCgnsOutputContext(*client, request));
  }
  EvalGridFacts facts;  // VTK and Plot3D outputs (eval_output.h)
  if (!cgns) {
    SG_ASSIGN_OR_RETURN(facts, FetchEvalFacts(*client, request, eval_options));
    SG_RETURN_IF_ERROR(CheckEveryDirectionGiven(facts, args[0]));
  }
  ProgressLine download("evaluate");
  absl::StatusOr<client::EvaluatedGrid> evaluated = client->Evaluate(request, download.callback());
  if (!evaluated.ok()) {
    return ExplainEvaluationLimit(evaluated.status(), out, eval_options.compress);
  }
  client::EvaluatedGrid result = *std::move(evaluated);
  download.Done();
  v1::EvaluationHeader summary;  // for --json; taken before the blocks move to the writer
  summary.set_revision(result.revision);
  for (const client::EvaluatedBlock& block : result.blocks) {
    v1::EvaluatedBlock* eb = summary.add_blocks();
    eb->set_block(block.block);
    eb->mutable_extents()->set_i(block.points.extent(0));
    eb->mutable_extents()->set_j(block.points.extent(1));
    eb->mutable_extents()->set_k(block.points.extent(2));
  }
  SG_ASSIGN_OR_RETURN(const int64_t points, WriteGridOutput(out, std::move(result), facts,
                                                            eval_options, cgns ? &*cgns : nullptr));
  summary.set_total_points(points);
  Print(absl::StrCat("wrote ", out, ": ", summary.blocks_size(), " block(s), ", points,
                     " points (revision ", summary.revision(), ")\n"),
        summary);
  return absl::OkStatus();
}

}  // namespace splinegrid::cli
