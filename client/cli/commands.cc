#include "client/cli/commands.h"

#include <cstdio>
#include <filesystem>
#include <optional>

#include "absl/flags/flag.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "client/cli/flags.h"
#include "client/cli/output.h"
#include "client/client.h"
#include "core/fit/airfoil_fit.h"
#include "core/io/airfoil.h"
#include "core/io/file_util.h"
#include "core/io/planar_view.h"
#include "core/io/plot3d.h"
#include "core/io/vtk.h"
#include "core/util/status_macros.h"
#include "server/server.h"

namespace splinegrid::cli {
namespace {

absl::Status Usage(const std::string& message) { return absl::InvalidArgumentError(message); }

std::unique_ptr<client::Client> Connect() {
  client::ClientOptions options;
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

absl::Status Serve(const Args& args) {
  if (!args.empty()) return Usage("serve takes no arguments, only flags");
  server::ServerOptions options;
  options.address = absl::GetFlag(FLAGS_address);
  options.worker_threads = absl::GetFlag(FLAGS_threads);
  options.memory_budget_bytes = absl::GetFlag(FLAGS_memory_budget_mb) << 20;
  options.max_output_points = absl::GetFlag(FLAGS_max_output_points);
  options.shutdown_grace = absl::GetFlag(FLAGS_shutdown_grace);
  options.log_calls = absl::GetFlag(FLAGS_log_calls);
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

// The FitSpec of the fit flags.
absl::StatusOr<v1::FitSpec> SpecFromFlags() {
  const double tol = absl::GetFlag(FLAGS_tol);
  const std::string ctl = absl::GetFlag(FLAGS_ctl);
  const bool kinds = absl::GetFlag(FLAGS_kinds) || absl::GetFlag(FLAGS_wall) != 0.0 ||
                     absl::GetFlag(FLAGS_interface) != 0.0 || absl::GetFlag(FLAGS_outer) != 0.0 ||
                     absl::GetFlag(FLAGS_interior) != 0.0 || absl::GetFlag(FLAGS_edge) >= 0.0;
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
    spec.set_max_controls_per_direction(absl::GetFlag(FLAGS_max_ctl));
  } else if (!ctl.empty()) {
    SG_ASSIGN_OR_RETURN(const Extents counts, ParseTriple(ctl, "--ctl"));
    spec.mutable_control_counts()->set_i(counts[0]);
    spec.mutable_control_counts()->set_j(counts[1]);
    spec.mutable_control_counts()->set_k(counts[2]);
  }
  SG_ASSIGN_OR_RETURN(const std::optional<v1::Fairing> fairing, ParseFairFlag());
  if (fairing) *spec.mutable_fairing() = *fairing;
  return spec;
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
  // Only two-plane files get the planar view; anything else is stored as read.
  bool planar = false;
  if (absl::GetFlag(FLAGS_planar)) {
    absl::StatusOr<MultiBlockGrid> local = ParsePlot3d(bytes, path);
    if (!local.ok()) return local.status();
    planar = IsTwoPlaneGrid(*local);
  }
  ProgressLine upload("upload");
  SG_ASSIGN_OR_RETURN(const v1::Grid grid,
                      client->ImportPlot3d(bytes, client::GridName(id).substr(6),
                                           std::filesystem::path(path).filename().string(), planar,
                                           upload.callback()));
  upload.Done();
  absl::StatusOr<v1::FitGridResponse> fit = client->Fit(grid.name(), spec);
  if (!fit.ok()) {
    (void)client->Delete(grid.name());  // do not leave an unfitted grid behind
    return fit.status();
  }
  Print(FormatFit(grid.name(), *fit), *fit);
  return absl::OkStatus();
}

absl::Status Get(const Args& args) {
  if (args.size() != 1) return Usage("usage: splinegrid get NAME [--revision R] [--full]");
  SG_ASSIGN_OR_RETURN(
      const v1::Grid grid,
      Connect()->Get(args[0], absl::GetFlag(FLAGS_revision),
                     absl::GetFlag(FLAGS_full) ? v1::GRID_VIEW_FULL : v1::GRID_VIEW_BASIC));
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
        "usage: splinegrid eval NAME (--level L | --res a,b,c) [--block b] -o OUT.{vts,vtm,x,xyz}");
  }
  v1::EvaluateGridRequest request;
  request.set_name(args[0]);
  request.set_revision(absl::GetFlag(FLAGS_revision));
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
  const std::string ext = std::filesystem::path(out).extension().string();
  if (ext != ".vts" && ext != ".vtm" && ext != ".x" && ext != ".xyz") {
    return Usage(absl::StrCat("-o ", out, ": the extension must be .vts, .vtm, .x or .xyz"));
  }
  ProgressLine download("evaluate");
  SG_ASSIGN_OR_RETURN(client::EvaluatedGrid result,
                      Connect()->Evaluate(request, download.callback()));
  download.Done();
  MultiBlockGrid grid;
  std::vector<std::vector<VtkPointArray>> arrays;
  int64_t points = 0;
  for (client::EvaluatedBlock& block : result.blocks) {
    points += block.points.num_points();
    std::vector<VtkPointArray> fields;
    if (!block.du.empty()) {
      const int s = block.points.spatial_dim();
      fields = {{"dX_du", s, block.du}, {"dX_dv", s, block.dv}, {"dX_dw", s, block.dw}};
    }
    arrays.push_back(std::move(fields));
    grid.blocks.push_back(block.points);
  }
  if (ext == ".vts") {
    if (grid.blocks.size() != 1) {
      return Usage(
          absl::StrCat(grid.blocks.size(), " blocks: write .vtm, or choose one with --block"));
    }
    SG_RETURN_IF_ERROR(WriteVts(out, grid.blocks[0], arrays[0]));
  } else if (ext == ".vtm") {
    SG_RETURN_IF_ERROR(WriteVtm(out, grid, arrays));
  } else {
    SG_RETURN_IF_ERROR(
        WritePlot3dFile(out, grid,
                        DefaultPlot3dFormat(grid, ext == ".x" ? Plot3dEncoding::kBinaryLittleEndian
                                                              : Plot3dEncoding::kAscii)));
  }
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
      Connect()->Fair(args[0], absl::GetFlag(FLAGS_revision), fairing ? &*fairing : nullptr));
  Print(FormatFit(client::GridName(args[0]), fit), fit);
  return absl::OkStatus();
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
  if (!out.empty()) SG_RETURN_IF_ERROR(WriteFileAtomically(out, AirfoilCurvatureCsv(fit)));
  std::string text = FormatAirfoilFit(coordinates.name, options.tolerance, fit);
  if (!out.empty()) absl::StrAppend(&text, "  curvature written to ", out, "\n");
  std::fwrite(text.data(), 1, text.size(), stdout);
  return fit.met ? absl::OkStatus()
                 : absl::FailedPreconditionError(absl::StrCat("not met: ", fit.unmet_reason));
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
