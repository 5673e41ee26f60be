#include "client/cli/commands.h"

#include <pthread.h>
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <thread>

#include "absl/flags/flag.h"
#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "client/cli/cgns_output.h"
#include "client/cli/command_line.h"
#include "client/cli/eval_command.h"
#include "client/cli/eval_output.h"
#include "client/cli/flags.h"
#include "client/cli/grid_output.h"
#include "client/cli/output.h"
#include "client/cli/serve_flags.h"
#include "client/client.h"
#include "core/fit/airfoil_fit.h"
#include "core/io/airfoil.h"
#include "core/io/file_util.h"
#include "core/io/record_file.h"
#include "core/util/status_macros.h"
#include "io/cgns/cgns_io.h"
#include "proto/convert/plot3d_format_convert.h"
#include "server/server.h"

namespace splinegrid::cli {
namespace {

absl::Status Usage(const std::string& message) { return absl::InvalidArgumentError(message); }

// The token and TLS settings of the client commands (set by PrepareConnection).
client::ClientOptions& ConnectionOptions() {
  static client::ClientOptions* const options = new client::ClientOptions();
  return *options;
}

std::unique_ptr<client::Client> Connect() {
  client::ClientOptions options = ConnectionOptions();
  options.timeout = absl::GetFlag(FLAGS_timeout);
  return client::Client::Connect(absl::GetFlag(FLAGS_server), options);
}

void Print(const std::string& human, const google::protobuf::Message& message) {
  const std::string text = absl::GetFlag(FLAGS_json) ? ToJson(message) : human;
  std::fwrite(text.data(), 1, text.size(), stdout);
}

// "24,16" -> {24, 16, 0}; `what` names the flag in errors.
absl::StatusOr<Extents> ParseTriple(const std::string& text, const std::string& what) {
  Extents values = {0, 0, 0};
  const std::vector<std::string> parts = absl::StrSplit(text, ',');
  if (parts.empty() || parts.size() > 3) {
    return Usage(absl::StrCat(what, " = '", text, "': give 1 to 3 comma-separated integers"));
  }
  for (size_t d = 0; d < parts.size(); ++d) {
    if (!absl::SimpleAtoi(parts[d], &values[d]) || values[d] < 0) {
      return Usage(
          absl::StrCat(what, " = '", text, "': '", parts[d], "' is not a non-negative integer"));
    }
  }
  return values;
}

// --revision or --step (not both) into a request.
template <typename SetRevision, typename SetStep>
absl::Status RevisionOrStep(const SetRevision& set_revision, const SetStep& set_step) {
  const std::optional<int64_t> step = absl::GetFlag(FLAGS_step);
  if (step.has_value()) {
    if (absl::GetFlag(FLAGS_revision) != 0) return Usage("give --revision or --step, not both");
    set_step(*step);
  } else {
    set_revision(absl::GetFlag(FLAGS_revision));
  }
  return absl::OkStatus();
}

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

// A grid id from a file name: lower case, [a-z0-9-], starting with a letter.
std::string IdFromPath(const std::string& path) {
  std::string id;
  for (char c : std::filesystem::path(path).stem().string()) {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    id += (std::isalnum(static_cast<unsigned char>(c)) ? c : '-');
  }
  if (id.empty() || !std::isalpha(static_cast<unsigned char>(id[0]))) id = "grid-" + id;
  return id.substr(0, 63);
}

}  // namespace

absl::Status PrepareConnection() {
  client::ClientOptions options;
  std::string token = absl::GetFlag(FLAGS_token);
  if (token.empty()) {
    if (const char* env = std::getenv("SPLINEGRID_TOKEN")) token = env;
  }
  if (!std::all_of(token.begin(), token.end(), [](char c) { return c > 0x20 && c < 0x7F; })) {
    return Usage("the token (--token or SPLINEGRID_TOKEN) must be printable ASCII without blanks");
  }
  options.token = token;
  SG_RETURN_IF_ERROR(client::LoadTlsFiles(absl::GetFlag(FLAGS_tls_ca),
                                          absl::GetFlag(FLAGS_tls_cert),
                                          absl::GetFlag(FLAGS_tls_key), &options));
  options.tls_server_name = absl::GetFlag(FLAGS_tls_server_name);
  if (!options.tls_server_name.empty()) options.use_tls = true;
  ConnectionOptions() = options;
  return absl::OkStatus();
}

absl::Status Serve(const Args& args) {
  if (!args.empty()) return Usage("serve takes no arguments, only flags");
  server::ServerOptions options;
  SG_RETURN_IF_ERROR(CheckServeFlags(&options.log_format));  // before << 20 can overflow
  options.drain_notice = absl::GetFlag(FLAGS_drain_notice);
  options.address = absl::GetFlag(FLAGS_address);
  options.store = absl::GetFlag(FLAGS_store);
  options.worker_threads = absl::GetFlag(FLAGS_threads);
  options.memory_budget_bytes = absl::GetFlag(FLAGS_memory_budget_mb) << 20;
  options.import_idle_timeout = absl::GetFlag(FLAGS_import_idle_timeout);
  options.cgns_decoder.executable = absl::GetFlag(FLAGS_cgns_decoder);
  options.cgns_decoder.memory_limit_bytes = absl::GetFlag(FLAGS_cgns_decoder_memory_mb) << 20;
  options.cgns_decoder.cpu_limit = absl::Seconds(absl::GetFlag(FLAGS_cgns_decoder_cpu_seconds));
  options.cgns_decoder.wall_limit =
      absl::Seconds(absl::GetFlag(FLAGS_cgns_decoder_timeout_seconds));
  options.max_output_points = absl::GetFlag(FLAGS_max_output_points);
  options.shutdown_grace = absl::GetFlag(FLAGS_shutdown_grace);
  options.log_calls = absl::GetFlag(FLAGS_log_calls);
  options.max_deform_revisions = absl::GetFlag(FLAGS_keep_revisions);
  // Transport security and tokens.
  options.tls_cert_file = absl::GetFlag(FLAGS_tls_cert);
  options.tls_key_file = absl::GetFlag(FLAGS_tls_key);
  options.tls_client_ca_file = absl::GetFlag(FLAGS_tls_client_ca);
  options.insecure = absl::GetFlag(FLAGS_insecure);
  options.tokens_file = absl::GetFlag(FLAGS_tokens);
  // Fair scheduling and per-principal limits.
  options.max_running_long_tasks = absl::GetFlag(FLAGS_max_running_long_tasks);
  options.max_queued_long_calls_per_principal =
      absl::GetFlag(FLAGS_max_queued_long_calls_per_principal);
  options.max_streams_per_principal = absl::GetFlag(FLAGS_max_streams_per_principal);
  // The Prometheus endpoint.
  options.metrics_address = absl::GetFlag(FLAGS_metrics_address);
  options.metrics_insecure = absl::GetFlag(FLAGS_metrics_insecure);
  return server::RunServerUntilSignal(options);
}

namespace {

// --fair: "" (none), "tol" (to tolerance) or a weight.
absl::StatusOr<std::optional<v1::Fairing>> ParseFairFlag() {
  const std::string text = absl::GetFlag(FLAGS_fair);
  if (text.empty()) return std::nullopt;
  v1::Fairing fairing;
  if (text == "tol") {
    fairing.set_mode(v1::FAIRING_MODE_TO_TOLERANCE);
    return fairing;
  }
  double weight;
  if (!absl::SimpleAtod(text, &weight) || !(weight > 0.0)) {
    return Usage(absl::StrCat("--fair = '", text, "': give 'tol' or a positive weight"));
  }
  fairing.set_mode(v1::FAIRING_MODE_WEIGHT);
  fairing.set_weight(weight);
  return fairing;
}

// --face: BLOCK:FACE=KIND[,...] (flags.cc), as FitSpec.face_kinds. Errors name the token.
// There is no symmetry kind: the kernel knows wall, interface and outer
// (core/grid/boundary_kinds.h), and a symmetry plane is fitted as an outer boundary.
absl::StatusOr<std::vector<v1::FaceKind>> ParseFaceFlag(const std::string& text) {
  static const std::map<std::string, v1::BlockFace> kFaces = {
      {"imin", v1::BLOCK_FACE_I_MIN}, {"imax", v1::BLOCK_FACE_I_MAX},
      {"jmin", v1::BLOCK_FACE_J_MIN}, {"jmax", v1::BLOCK_FACE_J_MAX},
      {"kmin", v1::BLOCK_FACE_K_MIN}, {"kmax", v1::BLOCK_FACE_K_MAX}};
  static const std::map<std::string, v1::BoundaryKind> kKinds = {
      {"wall", v1::BOUNDARY_KIND_WALL},
      {"interface", v1::BOUNDARY_KIND_INTERFACE},
      {"outer", v1::BOUNDARY_KIND_OUTER}};
  std::vector<v1::FaceKind> out;
  std::map<std::pair<int32_t, int>, v1::BoundaryKind> seen;
  for (absl::string_view raw : absl::StrSplit(text, ',')) {
    const std::string token(absl::StripAsciiWhitespace(raw));
    auto bad = [&](const std::string& why) {
      return Usage(absl::StrCat("--face: '", token, "': ", why,
                                " (give BLOCK:FACE=KIND, FACE imin, imax, jmin, jmax, kmin or "
                                "kmax, KIND wall, interface or outer)"));
    };
    const std::vector<std::string> block_rest = absl::StrSplit(token, absl::MaxSplits(':', 1));
    if (block_rest.size() != 2) return bad("no ':' after the block number");
    int32_t block = 0;
    if (!absl::SimpleAtoi(block_rest[0], &block) || block < 0) {
      return bad(absl::StrCat("block '", block_rest[0], "' is not a block number >= 0"));
    }
    const std::vector<std::string> face_kind =
        absl::StrSplit(block_rest[1], absl::MaxSplits('=', 1));
    if (face_kind.size() != 2) return bad("no '=' before the kind");
    const std::string face = absl::AsciiStrToLower(face_kind[0]);
    const std::string kind = absl::AsciiStrToLower(face_kind[1]);
    const auto f = kFaces.find(face);
    if (f == kFaces.end()) return bad(absl::StrCat("unknown face '", face_kind[0], "'"));
    const auto k = kKinds.find(kind);
    if (k == kKinds.end()) {
      return bad(kind == "symmetry"
                     ? std::string("there is no symmetry kind (fit a symmetry plane as outer)")
                     : absl::StrCat("unknown kind '", face_kind[1], "'"));
    }
    const auto [it, inserted] = seen.insert({{block, f->second}, k->second});
    if (!inserted && it->second != k->second) return bad("the face is given another kind before");
    if (!inserted) continue;
    v1::FaceKind& entry = out.emplace_back();
    entry.set_block(block);
    entry.set_face(f->second);
    entry.set_kind(k->second);
  }
  return out;
}

// The FitSpec of the fit flags.
absl::StatusOr<v1::FitSpec> SpecFromFlags() {
  const double tol = absl::GetFlag(FLAGS_tol);
  const std::string ctl = absl::GetFlag(FLAGS_ctl);
  const bool kinds = absl::GetFlag(FLAGS_kinds) || absl::GetFlag(FLAGS_wall) != 0.0 ||
                     absl::GetFlag(FLAGS_interface) != 0.0 || absl::GetFlag(FLAGS_outer) != 0.0 ||
                     absl::GetFlag(FLAGS_interior) != 0.0 || absl::GetFlag(FLAGS_edge) >= 0.0 ||
                     absl::GetFlag(FLAGS_ref_length) != 0.0 || !absl::GetFlag(FLAGS_face).empty();
  if ((tol != 0.0) + !ctl.empty() + kinds > 1) {
    return Usage("give one of --tol, --ctl and the tolerances by kind (--kinds, --wall, ...)");
  }
  v1::FitSpec spec;
  spec.set_order(absl::GetFlag(FLAGS_order));
  if (tol != 0.0) {
    spec.set_tolerance(tol);
    spec.set_max_controls_per_direction(absl::GetFlag(FLAGS_max_ctl));
  } else if (kinds) {
    v1::BoundaryTolerances* t = spec.mutable_boundary_tolerances();
    t->set_wall(absl::GetFlag(FLAGS_wall));
    t->set_interface(absl::GetFlag(FLAGS_interface));
    t->set_outer(absl::GetFlag(FLAGS_outer));
    t->set_interior(absl::GetFlag(FLAGS_interior));
    if (absl::GetFlag(FLAGS_edge) >= 0.0) t->set_edge(absl::GetFlag(FLAGS_edge));
    spec.set_reference_length(absl::GetFlag(FLAGS_ref_length));
    spec.set_max_controls_per_direction(absl::GetFlag(FLAGS_max_ctl));
  } else if (!ctl.empty()) {
    SG_ASSIGN_OR_RETURN(const Extents counts, ParseTriple(ctl, "--ctl"));
    spec.mutable_control_counts()->set_i(counts[0]);
    spec.mutable_control_counts()->set_j(counts[1]);
    spec.mutable_control_counts()->set_k(counts[2]);
  }
  SG_ASSIGN_OR_RETURN(const std::optional<v1::Fairing> fairing, ParseFairFlag());
  if (fairing) *spec.mutable_fairing() = *fairing;
  if (const std::string face = absl::GetFlag(FLAGS_face); !face.empty()) {
    SG_ASSIGN_OR_RETURN(const std::vector<v1::FaceKind> kinds, ParseFaceFlag(face));
    for (const v1::FaceKind& kind : kinds) *spec.add_face_kinds() = kind;
  }
  spec.set_allow_folds(absl::GetFlag(FLAGS_allow_folds));
  return spec;
}

// --plot3d_layout: "" (detect), "whole" or "planes".
absl::StatusOr<v1::Plot3dLayout> Plot3dLayoutFlag() {
  const std::string text = absl::GetFlag(FLAGS_plot3d_layout);
  if (text.empty()) return v1::PLOT3D_LAYOUT_UNSPECIFIED;
  if (text == "whole") return v1::PLOT3D_LAYOUT_WHOLE;
  if (text == "planes") return v1::PLOT3D_LAYOUT_PLANES;
  return Usage(absl::StrCat("--plot3d_layout = '", text, "': give whole or planes"));
}

// After a stored fit: FAILED_PRECONDITION with exit status kExitQualityNotMet (3) when
// --allow_folds let the server store a revision whose cells fold (its report says quality_met =
// false), so that a script cannot mistake it for a good grid, nor for a call that failed (1).
absl::Status FoldsStored(const std::string& name, const v1::FitGridResponse& fit) {
  if (fit.report().folded_cells() == 0) return absl::OkStatus();
  absl::Status status = absl::FailedPreconditionError(absl::StrCat(
      name, " revision ", fit.revision(), " was stored with ", fit.report().folded_cells(),
      " folded sub-cells (--allow_folds); do not use it as a valid grid"));
  return WithExitCode(std::move(status), kExitQualityNotMet);
}

}  // namespace

absl::Status Fit(const Args& args) {
  if (args.size() != 1) {
    return Usage(
        "usage: splinegrid fit FILE [--name N] [--tol T | --kinds [--wall W ...] | --ctl a,b,c] "
        "[--fair tol|LAMBDA]");
  }
  const std::string& path = args[0];
  SG_ASSIGN_OR_RETURN(const v1::FitSpec spec, SpecFromFlags());
  SG_ASSIGN_OR_RETURN(const std::string bytes, ReadFileToString(path));
  const std::string id =
      absl::GetFlag(FLAGS_name).empty() ? IdFromPath(path) : absl::GetFlag(FLAGS_name);
  auto client = Connect();
  // A CGNS file (by extension or signature) is decoded by the server, BCs included; it is
  // stored as its zones are (--planar is about two-plane Plot3D files).
  const bool cgns = IsCgnsPath(path) || LooksLikeCgns(bytes);
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
  SG_ASSIGN_OR_RETURN(
      const v1::Grid grid,
      cgns ? client->ImportCgns(bytes, grid_id, display_name, upload.callback())
           : client->ImportPlot3d(bytes, grid_id, display_name, plot3d_options, upload.callback()));
  upload.Done();
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
  return FoldsStored(grid.name(), *fit);
}

absl::Status Get(const Args& args) {
  if (args.size() != 1) {
    return Usage("usage: splinegrid get NAME [--revision R | --step N] [--full]");
  }
  v1::GetGridRequest request;
  request.set_name(args[0]);
  request.set_view(absl::GetFlag(FLAGS_full) ? v1::GRID_VIEW_FULL : v1::GRID_VIEW_BASIC);
  SG_RETURN_IF_ERROR(RevisionOrStep([&](int64_t r) { request.set_revision(r); },
                                    [&](int64_t s) { request.set_step(s); }));
  SG_ASSIGN_OR_RETURN(const v1::Grid grid, Connect()->Get(request));
  Print(FormatGrid(grid), grid);
  return absl::OkStatus();
}

absl::Status List(const Args& args) {
  if (!args.empty()) return Usage("usage: splinegrid list");
  SG_ASSIGN_OR_RETURN(const std::vector<v1::Grid> grids, Connect()->List());
  v1::ListGridsResponse all;
  std::string human;
  for (const v1::Grid& grid : grids) {
    *all.add_grids() = grid;
    absl::StrAppend(&human, absl::StrFormat("%-32s %4d blocks %10d points  revision %d\n",
                                            grid.name(), grid.source().blocks_size(),
                                            grid.source().num_points(), grid.latest_revision()));
  }
  Print(human, all);
  return absl::OkStatus();
}

absl::Status Eval(const Args& args) {
  const std::string out = absl::GetFlag(FLAGS_o);
  if (args.size() != 1 || out.empty()) {
    return Usage(
        "usage: splinegrid eval NAME (--level L | --res a,b,c) [--revision R | --step N] "
        "[--block b] [--derivs] [--jacobian] [--quality] [--deviation] [--nocompress] "
        "-o OUT.{vts,vtm,x,xyz,cgns}, or --steps A:B -o OUT.pvd");
  }
  v1::EvaluateGridRequest request;
  request.set_name(args[0]);
  SG_RETURN_IF_ERROR(RevisionOrStep([&](int64_t r) { request.set_revision(r); },
                                    [&](int64_t s) { request.set_step(s); }));
  const int level = absl::GetFlag(FLAGS_level);
  const std::string res = absl::GetFlag(FLAGS_res);
  if ((level >= 0) == !res.empty()) return Usage("give exactly one of --level and --res");
  if (level >= 0) {
    request.set_refinement_level(level);
  } else {
    SG_ASSIGN_OR_RETURN(Extents counts, ParseTriple(res, "--res"));
    for (int& c : counts) c = std::max(c, 1);
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
    int begin[3] = {0, 0, 0}, end[3] = {0, 0, 0};
    if (ranges.size() > 3) return Usage("--box: at most three ranges i0:i1,j0:j1,k0:k1");
    for (size_t d = 0; d < ranges.size(); ++d) {
      const std::vector<std::string> ends = absl::StrSplit(ranges[d], ':');
      if (ends.size() != 2 || !absl::SimpleAtoi(ends[0], &begin[d]) ||
          !absl::SimpleAtoi(ends[1], &end[d])) {
        return Usage(absl::StrCat("--box: '", ranges[d], "' is not a range a:b"));
      }
    }
    box->mutable_begin()->set_i(begin[0]);
    box->mutable_begin()->set_j(begin[1]);
    box->mutable_begin()->set_k(begin[2]);
    box->mutable_end()->set_i(end[0]);
    box->mutable_end()->set_j(end[1]);
    box->mutable_end()->set_k(end[2]);
  }
  request.set_derivatives(absl::GetFlag(FLAGS_derivs));
  request.set_precision(absl::GetFlag(FLAGS_float32) ? v1::PRECISION_FLOAT : v1::PRECISION_DOUBLE);
  // Output fields, the source's Plot3D layout and ParaView time series (eval_command.h).
  SG_ASSIGN_OR_RETURN(const EvalOutputOptions eval_options,
                      EvalOutputOptionsFromFlags(out, &request));
  if (IsSeriesPath(out)) {
    auto series_client = Connect();
    SG_ASSIGN_OR_RETURN(const EvalGridFacts facts,
                        FetchEvalFacts(*series_client, request, eval_options));
    SG_ASSIGN_OR_RETURN(const std::string summary,
                        RunEvalSeries(*series_client, request, out, facts, eval_options));
    std::fwrite(summary.data(), 1, summary.size(), stdout);
    return absl::OkStatus();
  }
  SG_RETURN_IF_ERROR(CheckGridOutput(out));
  auto client = Connect();
  // A CGNS file also carries the grid's boundary conditions and connectivity at the level.
  std::optional<CgnsOutputContext> cgns;
  if (IsCgnsPath(out)) {
    SG_ASSIGN_OR_RETURN(cgns, FetchCgnsOutputContext(*client, request));
  }
  EvalGridFacts facts;  // VTK and Plot3D outputs (eval_output.h)
  if (!cgns) {
    SG_ASSIGN_OR_RETURN(facts, FetchEvalFacts(*client, request, eval_options));
  }
  ProgressLine download("evaluate");
  SG_ASSIGN_OR_RETURN(client::EvaluatedGrid result, client->Evaluate(request, download.callback()));
  download.Done();
  SG_ASSIGN_OR_RETURN(const int64_t points,
                      WriteGridOutput(out, result, facts, eval_options, cgns ? &*cgns : nullptr));
  v1::EvaluationHeader summary;  // for --json
  summary.set_revision(result.revision);
  summary.set_total_points(points);
  for (const client::EvaluatedBlock& block : result.blocks) {
    v1::EvaluatedBlock* eb = summary.add_blocks();
    eb->set_block(block.block);
    eb->mutable_extents()->set_i(block.points.extent(0));
    eb->mutable_extents()->set_j(block.points.extent(1));
    eb->mutable_extents()->set_k(block.points.extent(2));
  }
  Print(absl::StrCat("wrote ", out, ": ", result.blocks.size(), " block(s), ", points,
                     " points (revision ", result.revision, ")\n"),
        summary);
  return absl::OkStatus();
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
  return FoldsStored(client::GridName(args[0]), fit);
}

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
  const int level = absl::GetFlag(FLAGS_level) < 0 ? 2 : absl::GetFlag(FLAGS_level);
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
  if (absl::GetFlag(FLAGS_tol) != 0.0) options.tolerance = absl::GetFlag(FLAGS_tol);
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

namespace {

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
    int begin[3] = {0, 0, 0}, end[3] = {0, 0, 0};
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
    range->mutable_begin()->set_i(begin[0]);
    range->mutable_begin()->set_j(begin[1]);
    range->mutable_begin()->set_k(begin[2]);
    range->mutable_end()->set_i(end[0]);
    range->mutable_end()->set_j(end[1]);
    range->mutable_end()->set_k(end[2]);
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
  rigid->set_angle_degrees(absl::GetFlag(FLAGS_rotate));
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
  if (rigid->angle_degrees() == 0.0 && rigid->translation().empty()) {
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

absl::Status Offset(const Args& args) {
  constexpr char kUsage[] =
      "usage: splinegrid offset FILE.dat [--name N] [--layers 128] [--first 1e-5] [--far 50] "
      "[--points 257] [--method offsets|transfinite|elliptic] [--orthogonalize=false] "
      "[--profile_tol T] "
      "[--tol T | --kinds [--wall W ...] | --ctl a,b,c] [-o OUT.{vts,vtm,x,xyz,cgns}]";
  if (args.size() != 1) return Usage(kUsage);
  const std::string& path = args[0];
  const std::string out = absl::GetFlag(FLAGS_o);
  if (!out.empty()) SG_RETURN_IF_ERROR(CheckGridOutput(out));
  v1::GenerateGridRequest request;
  request.set_grid_id(absl::GetFlag(FLAGS_name).empty()
                          ? IdFromPath(path)
                          : client::GridName(absl::GetFlag(FLAGS_name)).substr(6));
  request.set_display_name(std::filesystem::path(path).filename().string());
  SG_ASSIGN_OR_RETURN(*request.mutable_airfoil_file(), ReadFileToString(path));
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
  auto client = Connect();
  SG_ASSIGN_OR_RETURN(const v1::GenerateGridResponse response, client->Generate(request));
  std::string human = FormatGenerate(response);
  if (!out.empty()) {
    v1::EvaluateGridRequest evaluate;
    evaluate.set_name(response.grid().name());
    evaluate.set_revision(response.fit().revision());
    evaluate.set_refinement_level(0);
    ProgressLine download("evaluate");
    SG_ASSIGN_OR_RETURN(const client::EvaluatedGrid result,
                        client->Evaluate(evaluate, download.callback()));
    download.Done();
    // Points only, through eval's writers: no source layout (a generated grid has no file),
    // parametric dimensions from the extents, no boundary conditions in a .cgns.
    SG_ASSIGN_OR_RETURN(const int64_t points, WriteGridOutput(out, result, EvalGridFacts{},
                                                              EvalOutputOptions{}, nullptr));
    absl::StrAppend(&human, "wrote ", out, ": ", points, " points (revision ", result.revision,
                    ")\n");
  }
  Print(human, response);
  return FoldsStored(response.grid().name(), response.fit());
}

absl::Status Watch(const Args& args) {
  if (args.size() != 1) return Usage("usage: splinegrid watch NAME [--after R]");
  // SIGINT and SIGTERM end the watch cleanly: blocked here (before gRPC starts threads, which
  // inherit the mask) and taken by a thread that cancels the call.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  auto cancel = std::make_shared<client::WatchCancel>();
  std::atomic<bool> done{false};
  std::thread waiter([&] {
    int signal = 0;
    sigwait(&signals, &signal);
    if (!done) cancel->Cancel();
  });
  const std::string name = client::GridName(args[0]);
  const bool json = absl::GetFlag(FLAGS_json);
  const absl::Status status = Connect()->Watch(
      name, absl::GetFlag(FLAGS_after),
      [&](const v1::WatchGridResponse& message) {
        const std::string line =
            json ? ToJsonLine(message) : FormatRevisionLine(message.revision());
        std::fwrite(line.data(), 1, line.size(), stdout);
        std::fflush(stdout);
        return true;
      },
      cancel);
  done = true;
  pthread_kill(waiter.native_handle(), SIGTERM);  // wakes the waiter (the signal stays blocked)
  waiter.join();
  if (!status.ok()) return status;
  std::fprintf(stderr, "splinegrid watch: %s: %s\n", name.c_str(),
               cancel->cancelled() ? "interrupted"
                                   : "the stream ended (the grid was deleted or the server "
                                     "stopped)");
  return absl::OkStatus();
}

absl::Status Export(const Args& args) {
  const std::string out = absl::GetFlag(FLAGS_o);
  if (args.size() != 1 || out.empty()) return Usage("usage: splinegrid export NAME -o FILE.sgrid");
  const std::string name = client::GridName(args[0]);
  ProgressLine download("export");
  SG_ASSIGN_OR_RETURN(const client::ArchiveSummary summary,
                      Connect()->ExportGrid(name, out, download.callback()));
  download.Done();
  Print(absl::StrCat("exported ", name, " to ", out, ": ", summary.revisions, " revision(s), ",
                     summary.source_chunks, " source chunk(s), ", summary.bytes, " bytes\n"),
        summary.header);
  return absl::OkStatus();
}

namespace {

// Whether the file at `path` starts like a record file (an unreadable one: the import says why).
bool LooksLikeRecordFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return true;
  std::string start(kRecordFileMagic.size(), '\0');
  in.read(start.data(), static_cast<std::streamsize>(start.size()));
  return in.gcount() == static_cast<std::streamsize>(start.size()) && start == kRecordFileMagic;
}

}  // namespace

absl::Status Import(const Args& args) {
  if (args.size() != 1) return Usage("usage: splinegrid import FILE.sgrid [--name NEW]");
  const std::string& path = args[0];
  if (!LooksLikeRecordFile(path)) {
    return Usage(absl::StrCat(path, " is not a splinegrid archive (a record file written by ",
                              "`splinegrid export`); for a Plot3D grid use `splinegrid fit ", path,
                              "`"));
  }
  const std::string name = absl::GetFlag(FLAGS_name);
  ProgressLine upload("import");
  SG_ASSIGN_OR_RETURN(
      const v1::Grid grid,
      Connect()->ImportArchive(path, name.empty() ? "" : client::GridId(name), upload.callback()));
  upload.Done();
  Print(absl::StrCat("imported ", path, " as ", grid.name(), " (", grid.revisions_size(),
                     " revision(s))\n", FormatGrid(grid)),
        grid);
  return absl::OkStatus();
}

absl::Status Remove(const Args& args) {
  if (args.size() != 1) return Usage("usage: splinegrid rm NAME");
  SG_RETURN_IF_ERROR(Connect()->Delete(args[0]));
  google::protobuf::Empty empty;
  Print(absl::StrCat("deleted ", client::GridName(args[0]), "\n"), empty);
  return absl::OkStatus();
}

absl::Status Health(const Args& args) {
  if (!args.empty()) return Usage("usage: splinegrid health [--service S]");
  SG_ASSIGN_OR_RETURN(const std::string status, Connect()->Health(absl::GetFlag(FLAGS_service)));
  std::printf(absl::GetFlag(FLAGS_json) ? "{\"status\": \"%s\"}\n" : "%s\n", status.c_str());
  if (status != "SERVING") return absl::UnavailableError(absl::StrCat("status ", status));
  return absl::OkStatus();
}

}  // namespace splinegrid::cli
