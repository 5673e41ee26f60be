// splinegrid_pitching: a fluid-structure coupling client, the pitching NACA 0012.
//
// Imports the 257 x 129 pitching-airfoil C-grid (its 2D view), fits it once to the paper's
// tolerances by boundary kind, then runs a solver's time loop against the server: every step
//   1. DeformGrid: the wall turned by alpha(n) = amplitude sin(2 pi n / period) about the
//      quarter chord (0.25, 0), with reference_revision = the fit (motions are absolute, no
//      drift), base_revision = the last acknowledged step's revision (a concurrent change is
//      ABORTED, so a step never forks the history), and the step's time and number stamped on
//      the new revision;
//   2. EvaluateGrid of that revision at refinement level 1 (what the solver would compute on);
//   3. a client-side fold check: the signed area of every cell of the evaluated grid against
//      its sign in the fitted grid at the same level (step 0).
// Prints latency percentiles (p50, p90, p99, max) of the deform call, the evaluate call and the
// whole step, and the number of folded cells; exits 1 if any cell folded, the server refused
// a step (a fold it found itself) or a step failed, 2 for bad flags, 3 when the setup (import,
// fit) failed.
//
// Surviving a replica's death: every call that breaks off (UNAVAILABLE, or INTERNAL
// "RST_STREAM" from a balancer) is made again with backoff (--attempts, the client's
// RetryPolicy; an evaluation from its start). A DeformGrid attempt whose answer was lost may still
// have been stored; its retry then meets base_revision and answers ABORTED. So when a deform fails
// with anything but a fold (FAILED_PRECONDITION) or a bad request, the client asks GetGrid(step=n)
// whether that step's revision landed and, if so, takes it as acknowledged. --acked FILE
// records one line "step revision" per acknowledged step (flushed at once), so every
// acknowledged revision can be checked afterwards.
//
//   splinegrid_pitching --server localhost:50051 --steps 100 [--amplitude 10] [--grid FILE]
//       [--acked FILE] [--attempts N]
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/flags/usage_config.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/client.h"
#include "core/io/file_util.h"

ABSL_FLAG(std::string, server, "",
          "splinegrid server (host:port; default: $SPLINEGRID_SERVER, else localhost:50051)");
ABSL_FLAG(int, steps, 100, "time steps");
ABSL_FLAG(double, amplitude, 10.0, "pitch amplitude in degrees");
ABSL_FLAG(int, period, 0, "steps per pitch cycle (0: --steps, one whole cycle)");
ABSL_FLAG(double, dt, 0.01, "time step of the stamped solver time");
ABSL_FLAG(int, level, 1, "refinement level the solver evaluates at");
ABSL_FLAG(int, check_level, 0, "refinement level of the server's fold check (0 to 4)");
ABSL_FLAG(std::string, grid, SPLINEGRID_SOURCE_DIR "/../shared/data/grids/n0012_pitch_257x129.fmt",
          "the pitching airfoil's Plot3D grid (stored as its 2D view)");
ABSL_FLAG(std::string, name, "pitching-cpp", "grid id on the server");
ABSL_FLAG(bool, keep, false, "keep the grid on the server");
ABSL_FLAG(bool, quiet, false, "no line per step");
ABSL_FLAG(std::string, acked, "",
          "write one line 'step revision' per acknowledged step to this file (flushed per step)");
ABSL_FLAG(int, attempts, 8,
          "attempts per call while the server is UNAVAILABLE (8: about 5 s of backoff, enough "
          "for a balancer to find another replica or a server to restart)");
ABSL_FLAG(double, timeout, 120.0, "deadline of each call in seconds, retries included");
// Connection security, as the `splinegrid` tool's.
ABSL_FLAG(std::string, token, "", "bearer token of every call (default: $SPLINEGRID_TOKEN)");
ABSL_FLAG(std::string, tls_ca, "", "connect over TLS, trusting the CA in this PEM file");
ABSL_FLAG(std::string, tls_cert, "", "PEM certificate chain of this client, for mutual TLS");
ABSL_FLAG(std::string, tls_key, "", "PEM private key of --tls_cert");

namespace splinegrid {
namespace {

// --server, else $SPLINEGRID_SERVER (what deploy/local/start.sh prints), else localhost:50051:
// the CLI's rule.
std::string ServerAddress() {
  if (std::string flag = absl::GetFlag(FLAGS_server); !flag.empty()) return flag;
  const char* env = std::getenv("SPLINEGRID_SERVER");
  return env != nullptr && *env != '\0' ? env : "localhost:50051";
}

constexpr double kPi = 3.14159265358979323846;

// Signed areas of the cells of 2D blocks: (p11 - p00) x (p01 - p10) / 2, block after block.
std::vector<double> SignedCellAreas(const client::EvaluatedGrid& grid) {
  std::vector<double> areas;
  for (const client::EvaluatedBlock& b : grid.blocks) {
    const StructuredBlock& p = b.points;
    for (int j = 0; j + 1 < p.extent(1); ++j) {
      for (int i = 0; i + 1 < p.extent(0); ++i) {
        const double* p00 = p.Point(i, j, 0);
        const double* p10 = p.Point(i + 1, j, 0);
        const double* p01 = p.Point(i, j + 1, 0);
        const double* p11 = p.Point(i + 1, j + 1, 0);
        areas.push_back(
            0.5 * ((p11[0] - p00[0]) * (p01[1] - p10[1]) - (p11[1] - p00[1]) * (p01[0] - p10[0])));
      }
    }
  }
  return areas;
}

// Nearest-rank percentile of sorted values.
double Percentile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0.0;
  const size_t rank = static_cast<size_t>(std::ceil(q * sorted.size()));
  return sorted[std::clamp<size_t>(rank, 1, sorted.size()) - 1];
}

std::string PercentileRow(const char* label, std::vector<double> ms) {
  std::sort(ms.begin(), ms.end());
  return absl::StrFormat("  %-16s %9.3f %9.3f %9.3f %9.3f\n", label, Percentile(ms, 0.5),
                         Percentile(ms, 0.9), Percentile(ms, 0.99), ms.empty() ? 0.0 : ms.back());
}

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// The --acked file: one line "step revision" per acknowledged step, flushed at once so that a
// killed run leaves every line it acknowledged. Without a path it records nothing.
class AckLog {
 public:
  explicit AckLog(std::FILE* file) : file_(file) {}
  ~AckLog() {
    if (file_ != nullptr) std::fclose(file_);
  }
  AckLog(const AckLog&) = delete;
  AckLog& operator=(const AckLog&) = delete;

  void Add(int64_t step, int64_t revision) {
    if (file_ == nullptr) return;
    std::fprintf(file_, "%lld %lld\n", static_cast<long long>(step),
                 static_cast<long long>(revision));
    std::fflush(file_);
  }

 private:
  std::FILE* file_;
};

// What became of one step's deformation.
struct DeformOutcome {
  enum Kind {
    kAcknowledged,  // stored as `revision`
    kRefused,       // the server's fold check refused it (FAILED_PRECONDITION): not stored
    kFailed,        // not stored (a bad request, or the server could not be reached)
    kConflict,      // ABORTED, and not by an attempt of ours: someone else changed the grid
  } kind;
  int64_t revision = 0;
  v1::DeformReport report;  // of the acknowledged revision
  bool answered = false;    // the deform call itself answered OK (not a later GetGrid)
  std::string note;         // what happened, for the step's line
};

// The revision stored for solver step `step` (GetGrid with step), nullopt when there is none.
absl::StatusOr<std::optional<v1::Revision>> RevisionOfStep(client::Client& client,
                                                           const std::string& name, int64_t step) {
  v1::GetGridRequest request;
  request.set_name(name);
  request.set_step(step);
  absl::StatusOr<v1::Grid> grid = client.Get(request);
  if (absl::IsNotFound(grid.status())) return std::nullopt;
  if (!grid.ok()) return grid.status();
  if (grid->revision().origin() != v1::REVISION_ORIGIN_DEFORM || grid->revision().step() != step) {
    return std::nullopt;
  }
  return grid->revision();
}

// One step's DeformGrid (retried on UNAVAILABLE by the client) and, when it fails without a
// verdict, whether one of its attempts was stored anyway:
//   - OK: acknowledged;
//   - FAILED_PRECONDITION (a fold), INVALID_ARGUMENT, NOT_FOUND: nothing was stored;
//   - anything else (UNAVAILABLE after all retries, DEADLINE_EXCEEDED, ABORTED because a retry
//     met the revision its own earlier attempt stored, ...): GetGrid(step) says whether the
//     step's revision landed; if it did, it is acknowledged. ABORTED without one means the
//     grid moved past `base_revision` for another reason: the newest revision is adopted when
//     it is a deformation of this run (same reference) for an unacknowledged earlier step,
//     whose lost attempt landed after the client gave up on it (`late`), and the step is made
//     again on top of it; anything else is a conflict, never deformed over.
DeformOutcome DeformStep(client::Client& client, v1::DeformGridRequest request, int64_t acked_step,
                         std::optional<v1::Revision>* late) {
  for (int round = 0;; ++round) {
    absl::StatusOr<v1::DeformGridResponse> moved = client.Deform(request);
    if (moved.ok()) {
      return {DeformOutcome::kAcknowledged, moved->revision(), moved->report(), true, ""};
    }
    const absl::Status& error = moved.status();
    if (absl::IsFailedPrecondition(error)) {
      return {DeformOutcome::kRefused, 0, {}, false, error.ToString()};
    }
    if (absl::IsInvalidArgument(error) || absl::IsNotFound(error)) {
      return {DeformOutcome::kFailed, 0, {}, false, error.ToString()};
    }
    absl::StatusOr<std::optional<v1::Revision>> landed =
        RevisionOfStep(client, request.name(), request.step());
    if (!landed.ok()) {
      return {DeformOutcome::kFailed,
              0,
              {},
              false,
              absl::StrCat(error.ToString(),
                           "; whether it was stored is unknown: ", landed.status().ToString())};
    }
    if (landed->has_value()) {
      return {DeformOutcome::kAcknowledged, (*landed)->revision(), (*landed)->deform_report(),
              false,
              absl::StrCat(error.ToString(), "; its revision ", (*landed)->revision(),
                           " had been stored: acknowledged")};
    }
    if (!absl::IsAborted(error)) {
      return {DeformOutcome::kFailed, 0, {}, false, absl::StrCat(error.ToString(), "; not stored")};
    }
    absl::StatusOr<v1::Grid> latest = client.Get(request.name());
    if (round == 0 && latest.ok()) {
      const v1::Revision& r = latest->revision();
      if (r.origin() == v1::REVISION_ORIGIN_DEFORM &&
          r.parent_revision() == request.reference_revision() && r.step() > acked_step &&
          r.step() < request.step()) {
        *late = r;
        request.set_base_revision(r.revision());
        continue;
      }
    }
    return {DeformOutcome::kConflict,
            0,
            {},
            false,
            absl::StrCat(error.ToString(), "; the grid was changed by another client")};
  }
}

int Run() {
  const int steps = absl::GetFlag(FLAGS_steps);
  const double amplitude = absl::GetFlag(FLAGS_amplitude);
  const int period = absl::GetFlag(FLAGS_period) > 0 ? absl::GetFlag(FLAGS_period) : steps;
  const int level = absl::GetFlag(FLAGS_level);
  const bool quiet = absl::GetFlag(FLAGS_quiet);
  if (steps < 1 || level < 0 || !std::isfinite(amplitude)) {
    std::fprintf(stderr, "--steps must be >= 1, --level >= 0 and --amplitude finite\n");
    return 2;
  }
  client::ClientOptions options;
  options.retry.max_attempts = absl::GetFlag(FLAGS_attempts);
  options.timeout = absl::Seconds(absl::GetFlag(FLAGS_timeout));
  if (options.retry.max_attempts < 1 || !(absl::GetFlag(FLAGS_timeout) > 0.0)) {
    std::fprintf(stderr, "--attempts must be >= 1 and --timeout positive\n");
    return 2;
  }
  options.token = absl::GetFlag(FLAGS_token);
  if (const char* env = std::getenv("SPLINEGRID_TOKEN"); options.token.empty() && env) {
    options.token = env;
  }
  if (const absl::Status tls =
          client::LoadTlsFiles(absl::GetFlag(FLAGS_tls_ca), absl::GetFlag(FLAGS_tls_cert),
                               absl::GetFlag(FLAGS_tls_key), &options);
      !tls.ok()) {
    std::fprintf(stderr, "%s\n", std::string(tls.message()).c_str());
    return 2;
  }
  std::FILE* acked_file = nullptr;
  if (const std::string path = absl::GetFlag(FLAGS_acked); !path.empty()) {
    acked_file = std::fopen(path.c_str(), "w");
    if (acked_file == nullptr) {
      std::fprintf(stderr, "--acked %s: %s\n", path.c_str(), std::strerror(errno));
      return 2;
    }
  }
  AckLog acked(acked_file);
  auto client = client::Client::Connect(ServerAddress(), options);
  const std::string name = client::GridName(absl::GetFlag(FLAGS_name));

  // Setup: import (2D view of the two-plane file) and fit to the tolerances by kind.
  absl::StatusOr<std::string> bytes = ReadFileToString(absl::GetFlag(FLAGS_grid));
  if (!bytes.ok()) {
    std::fprintf(stderr, "%s\n", bytes.status().ToString().c_str());
    return 3;
  }
  absl::StatusOr<v1::Grid> imported =
      client->ImportPlot3d(*bytes, name.substr(6), "pitching NACA 0012", /*planar_view=*/true);
  if (!imported.ok()) {
    std::fprintf(stderr, "import: %s\n", imported.status().ToString().c_str());
    return 3;
  }
  v1::FitSpec spec;
  spec.mutable_boundary_tolerances();  // defaults: 0.15e-3 wall, 2e-3 interface, 8e-3 outer
  absl::StatusOr<v1::FitGridResponse> fit = client->Fit(name, spec);
  if (!fit.ok()) {
    std::fprintf(stderr, "fit: %s\n", fit.status().ToString().c_str());
    (void)client->Delete(name);
    return 3;
  }
  std::printf("%s revision %d: %d points -> %d control points (%.1fx), max deviation %.3g\n",
              name.c_str(), static_cast<int>(fit->revision()), static_cast<int>(fit->num_points()),
              static_cast<int>(fit->num_control_points()), fit->compression_ratio(),
              fit->max_deviation());

  v1::EvaluateGridRequest evaluate;
  evaluate.set_name(name);
  evaluate.set_refinement_level(level);
  evaluate.set_revision(fit->revision());
  absl::StatusOr<client::EvaluatedGrid> start = client->Evaluate(evaluate);
  if (!start.ok()) {
    std::fprintf(stderr, "evaluate: %s\n", start.status().ToString().c_str());
    return 3;
  }
  const std::vector<double> reference = SignedCellAreas(*start);
  std::printf(
      "%d steps, pitch +-%g degrees about (0.25, 0), period %d steps; %zu cells at "
      "level %d checked per step\n",
      steps, amplitude, period, reference.size(), level);

  std::vector<double> deform_ms, server_ms, evaluate_ms, step_ms;
  int64_t folded_cells = 0, refused = 0, failed = 0;
  // The base of every deformation: the last acknowledged revision (the fit's at first). A step
  // whose deformation was not stored leaves it, so the next step still builds on it.
  int64_t previous = fit->revision();
  int64_t acked_step = 0;
  for (int n = 1; n <= steps; ++n) {
    const double alpha = amplitude * std::sin(2.0 * kPi * n / period);
    const auto step_start = std::chrono::steady_clock::now();
    v1::DeformGridRequest deform;
    deform.set_name(name);
    deform.set_reference_revision(fit->revision());
    deform.set_base_revision(previous);
    deform.set_time(n * absl::GetFlag(FLAGS_dt));
    deform.set_step(n);
    deform.set_check_level(absl::GetFlag(FLAGS_check_level));
    deform.mutable_rigid()->set_angle_degrees(alpha);
    deform.mutable_rigid()->add_center(0.25);
    deform.mutable_rigid()->add_center(0.0);
    std::optional<v1::Revision> late;
    const DeformOutcome outcome = DeformStep(*client, deform, acked_step, &late);
    deform_ms.push_back(MillisecondsSince(step_start));
    if (late.has_value()) {
      std::printf("step %d: the revision %d of step %d had been stored after all: acknowledged\n",
                  n, static_cast<int>(late->revision()), static_cast<int>(late->step()));
      acked.Add(late->step(), late->revision());
      previous = late->revision();
      acked_step = late->step();
    }
    if (outcome.kind != DeformOutcome::kAcknowledged) {
      std::printf("step %d alpha %.3f: %s\n", n, alpha, outcome.note.c_str());
      (outcome.kind == DeformOutcome::kRefused ? refused : failed) += 1;
      if (outcome.kind == DeformOutcome::kConflict) break;  // never deform over someone else
      continue;
    }
    if (!outcome.note.empty())
      std::printf("step %d alpha %.3f: %s\n", n, alpha, outcome.note.c_str());
    acked.Add(n, outcome.revision);
    previous = outcome.revision;
    acked_step = n;
    if (outcome.answered) server_ms.push_back(1e3 * outcome.report.seconds());

    const auto evaluate_start = std::chrono::steady_clock::now();
    evaluate.set_revision(outcome.revision);
    absl::StatusOr<client::EvaluatedGrid> grid = client->Evaluate(evaluate);
    evaluate_ms.push_back(MillisecondsSince(evaluate_start));
    if (!grid.ok()) {
      std::printf("step %d: evaluate: %s\n", n, grid.status().ToString().c_str());
      ++failed;
      continue;
    }
    const std::vector<double> areas = SignedCellAreas(*grid);
    int64_t folds = 0;
    if (areas.size() != reference.size()) {
      std::printf("step %d: %zu cells, expected %zu\n", n, areas.size(), reference.size());
      ++failed;
      continue;
    }
    for (size_t c = 0; c < areas.size(); ++c) {
      if (reference[c] != 0.0 && !(areas[c] * reference[c] > 0.0)) ++folds;
    }
    folded_cells += folds;
    step_ms.push_back(MillisecondsSince(step_start));
    if (!quiet) {
      std::printf(
          "step %3d t %.3f alpha %8.3f revision %4d min Jacobian ratio %.4f "
          "deform %7.3f ms evaluate %7.3f ms folds %d\n",
          n, deform.time(), alpha, static_cast<int>(outcome.revision),
          outcome.report.min_jacobian_ratio(), deform_ms.back(), evaluate_ms.back(),
          static_cast<int>(folds));
    }
  }

  std::printf("latency over %d steps, ms:      p50       p90       p99       max\n", steps);
  std::string table = PercentileRow("deform", deform_ms);
  absl::StrAppend(&table, PercentileRow("  (server)", server_ms));
  absl::StrAppend(&table, PercentileRow("evaluate", evaluate_ms));
  absl::StrAppend(&table, PercentileRow("step", step_ms));
  std::fputs(table.c_str(), stdout);
  std::printf(
      "folds: %d (folded cells over all steps), %d steps refused by the server, "
      "%d failed\n",
      static_cast<int>(folded_cells), static_cast<int>(refused), static_cast<int>(failed));
  if (!absl::GetFlag(FLAGS_keep)) (void)client->Delete(name);
  return folded_cells == 0 && refused == 0 && failed == 0 ? 0 : 1;
}

}  // namespace
}  // namespace splinegrid

int main(int argc, char** argv) {
  // --help lists this file's flags (absl matches the program's name by default, which this
  // file's does not).
  absl::FlagsUsageConfig usage;
  usage.contains_help_flags = [](absl::string_view file) {
    return absl::EndsWith(file, "examples/pitching.cc");
  };
  absl::SetFlagsUsageConfig(usage);
  absl::SetProgramUsageMessage(
      "splinegrid_pitching --server host:port --steps N [--amplitude DEG]: a pitching NACA 0012 "
      "coupling loop (deform, evaluate, fold check) with latency percentiles");
  absl::ParseCommandLine(argc, argv);
  return splinegrid::Run();
}
