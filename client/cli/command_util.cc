// The helpers several subcommands share (command_util.h) and PrepareConnection (commands.h).
#include "client/cli/command_util.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "client/cli/commands.h"
#include "client/cli/output.h"
#include "core/util/status_macros.h"
#include "server/grid_id.h"
#include "server/memory_limit.h"

namespace splinegrid::cli {
namespace {

// The token and TLS settings of the client commands (set by PrepareConnection).
client::ClientOptions& ConnectionOptions() {
  static client::ClientOptions* const options = new client::ClientOptions();
  return *options;
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

// The settings of PrepareConnection with --timeout.
client::ClientOptions CommandOptions() {
  client::ClientOptions options = ConnectionOptions();
  options.timeout = absl::GetFlag(FLAGS_timeout);
  return options;
}

}  // namespace

absl::Status Usage(const std::string& message) { return absl::InvalidArgumentError(message); }

std::string ServerAddress() {
  if (std::string address = absl::GetFlag(FLAGS_server); !address.empty()) return address;
  if (const char* env = std::getenv("SPLINEGRID_SERVER"); env != nullptr && *env != '\0') {
    return env;
  }
  return "localhost:50051";
}

std::unique_ptr<client::Client> Connect(const client::RetryPolicy& retry) {
  client::ClientOptions options = CommandOptions();
  options.retry = retry;
  return client::Client::Connect(ServerAddress(), options);
}

std::unique_ptr<client::Client> ConnectForEvaluation(double output_copies) {
  client::ClientOptions options = CommandOptions();
  if (const int64_t mb = absl::GetFlag(FLAGS_max_memory_mb); mb > 0) {
    options.max_evaluation_bytes = mb << 20;
  }
  if (options.max_evaluation_bytes > 0 && output_copies > 1.0) {
    options.max_evaluation_bytes =
        static_cast<int64_t>(static_cast<double>(options.max_evaluation_bytes) / output_copies);
  }
  return client::Client::Connect(ServerAddress(), options);
}

void Print(const std::string& human, const google::protobuf::Message& message) {
  const std::string text = absl::GetFlag(FLAGS_json) ? ToJson(message) : human;
  std::fwrite(text.data(), 1, text.size(), stdout);
}

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

absl::StatusOr<std::optional<int>> LevelFlag() {
  const std::optional<int> level = absl::GetFlag(FLAGS_level);
  if (level.has_value() && *level < 0) {
    return Usage(
        absl::StrCat("--level = ", *level, " is negative; level 0 is the original points"));
  }
  return level;
}

absl::StatusOr<Extents> ResolutionFlag() {
  const std::string text = absl::GetFlag(FLAGS_res);
  SG_ASSIGN_OR_RETURN(Extents counts, ParseTriple(text, "--res"));
  const size_t given = std::vector<std::string>(absl::StrSplit(text, ',')).size();
  for (size_t d = 0; d < 3; ++d) {
    if (d >= given) {
      counts[d] = 1;
    } else if (counts[d] < 1) {
      return Usage(absl::StrCat("--res = '", text, "': ", counts[d], " points in direction ",
                                std::string(1, "ijk"[d]), "; give at least 1 per direction"));
    }
  }
  return counts;
}

std::string IdFromPath(const std::string& path) {
  std::string id;
  for (char c : std::filesystem::path(path).stem().string()) {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    id += (std::isalnum(static_cast<unsigned char>(c)) ? c : '-');
  }
  if (id.empty() || !std::isalpha(static_cast<unsigned char>(id[0]))) id = "grid-" + id;
  return id.substr(0, 63);
}

absl::StatusOr<std::string> NameFlagId() {
  const std::string name = absl::GetFlag(FLAGS_name);
  if (name.empty()) return std::string();
  const std::string id = client::GridId(name);
  SG_RETURN_IF_ERROR(server::CheckRequestedGridId(id, "--name"));
  return id;
}

// Three quarters of the memory this process may use: MemAvailable (/proc/meminfo), or what its
// cgroup has left under its limit when that is lower (a container, a batch job's allocation
// shared with a solver; server/memory_limit.h). 0, no limit, when neither can be read.
int64_t EvaluationMemoryLimit() {
  int64_t available = 0;
  std::ifstream meminfo("/proc/meminfo");
  for (std::string line; std::getline(meminfo, line);) {
    long long kib = 0;  // "MemAvailable:   12345678 kB"
    if (std::sscanf(line.c_str(), "MemAvailable: %lld kB", &kib) == 1 && kib > 0) {
      available = static_cast<int64_t>(kib) * 1024;
      break;
    }
  }
  // What the cgroup has left when it says (shared with a solver in one job, say), else its limit.
  const server::MemoryLimit limit = server::DetectMemoryLimit();
  const int64_t group = limit.headroom.value_or(limit.bytes);
  if (group > 0 && (available == 0 || group < available)) available = group;
  return available / 4 * 3;
}

absl::Status PrepareConnection() {
  client::ClientOptions options;
  options.max_evaluation_bytes = EvaluationMemoryLimit();
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
  if (const int64_t mb = absl::GetFlag(FLAGS_max_memory_mb); mb < 0 || mb >= (int64_t{1} << 43)) {
    return Usage(absl::StrCat("--max_memory_mb = ", mb, " is outside [0, 2^43)"));
  }
  if (const absl::Duration timeout = absl::GetFlag(FLAGS_timeout);
      !(timeout > absl::ZeroDuration())) {
    return Usage(absl::StrCat("--timeout = ", absl::FormatDuration(timeout),
                              " is not a positive duration (e.g. 30s, 10m)"));
  }
  ConnectionOptions() = options;
  return absl::OkStatus();
}

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

absl::StatusOr<v1::FitSpec> SpecFromFlags() {
  const double tol = absl::GetFlag(FLAGS_tol);
  const std::string ctl = absl::GetFlag(FLAGS_ctl);
  // --edge below 0 means unset; anything else, NaN included, goes to the server to be checked.
  const double edge = absl::GetFlag(FLAGS_edge);
  const bool edge_set = !(edge < 0.0);
  const bool kinds = absl::GetFlag(FLAGS_kinds) || absl::GetFlag(FLAGS_wall) != 0.0 ||
                     absl::GetFlag(FLAGS_interface) != 0.0 || absl::GetFlag(FLAGS_outer) != 0.0 ||
                     absl::GetFlag(FLAGS_interior) != 0.0 || edge_set ||
                     absl::GetFlag(FLAGS_first_layer) != 0.0 ||
                     absl::GetFlag(FLAGS_ref_length) != 0.0 || !absl::GetFlag(FLAGS_face).empty();
  if ((tol != 0.0) + !ctl.empty() + kinds > 1) {
    return Usage("give one of --tol, --ctl and the tolerances by kind (--kinds, --wall, ...)");
  }
  // 0 would read as unset on the wire and fit at the default order.
  if (const int order = absl::GetFlag(FLAGS_order); order < 1) {
    return Usage(
        absl::StrCat("--order = ", order, " is not a spline order (degree + 1, at least 2)"));
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
    if (edge_set) t->set_edge(edge);
    t->set_first_layer(absl::GetFlag(FLAGS_first_layer));
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

absl::Status StoredNotAsAsked(const std::string& name, const v1::FitGridResponse& fit) {
  const v1::FitReport& report = fit.report();
  std::string what;
  if (report.folded_cells() > 0) {
    what = absl::StrCat("was stored with ", report.folded_cells(),
                        " folded sub-cells (--allow_folds); do not use it as a valid grid");
  } else if (report.tolerances_given() && !report.tolerance_met()) {
    what = absl::StrCat("was stored, but its tolerances are NOT met: ", report.unmet_reason());
  } else {
    return absl::OkStatus();
  }
  return WithExitCode(
      absl::FailedPreconditionError(absl::StrCat(name, " revision ", fit.revision(), " ", what)),
      kExitQualityNotMet);
}

}  // namespace splinegrid::cli
