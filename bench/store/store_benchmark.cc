// Store backends and the replicated topology, with the real processes on loopback ports, all
// started by this one run:
//
//   direct    splinegrid serve --store=memory
//   dir       splinegrid serve --store=dir:TMP
//   replica   splinegrid serve --store=redis://... (one of the topology's replicas, directly)
//   topology  nginx (deploy/nginx/render.sh's configuration)  ->  3 replicas  ->  redis-server
//             (AOF, appendfsync always)
//
// Every server process (splinegrid, nginx, redis-server) is pinned to CPU 0, one worker thread
// per splinegrid, the client to CPU 1, as in splinegrid_service_bench: the topology gets the same
// CPU as the direct server, so the ratios measure what the hops and the store cost
// (SPLINEGRID_BENCH_NO_PIN=1 leaves every process unpinned).
//
//   BM_DeformEvaluate/target   one coupling step on the pitching NACA 0012 (257 x 129): DeformGrid
//                              (rigid, reference = the fit, base = the previous revision, step
//                              and time stamped) then EvaluateGrid of the new revision at the
//                              original resolution, sequential; p50/p99 of the step and of the
//                              deform, and p50/p99 over the direct in-memory server's
//   BM_ImportFit/store         ImportGrid + FitGrid (tolerances by boundary kind, the report) of
//                              the NACA 0012 225 x 65 C-grid; import, fit and total per store,
//                              and over memory's
//
// Skips what needs redis-server or nginx when they are not installed (.ci/setup installs them).
#include <sched.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "bench/latency.h"
#include "benchmark/benchmark.h"
#include "client/client.h"
#include "core/io/file_util.h"
#include "tests/core/test_data.h"
#include "tests/store/server_process.h"

namespace splinegrid::bench {
namespace {

namespace fs = std::filesystem;
using splinegrid::testing::ChildProcess;
using splinegrid::testing::FindProgram;
using splinegrid::testing::FreePort;
using splinegrid::testing::RunShell;
using splinegrid::testing::WaitForPort;

constexpr double kPi = 3.14159265358979323846;
constexpr int kReplicas = 3;

std::string Address(int port) { return absl::StrCat("127.0.0.1:", port); }

bool Pinning() { return std::getenv("SPLINEGRID_BENCH_NO_PIN") == nullptr; }

void PinToCpu(int cpu) {
  if (!Pinning()) return;
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  sched_setaffinity(0, sizeof(set), &set);
}

// Whether the server at `port` answers SERVING within `timeout`.
bool WaitServing(int port, absl::Duration timeout) {
  if (!WaitForPort(port, timeout)) return false;
  client::ClientOptions options;
  options.timeout = absl::Seconds(2);
  options.retry.max_attempts = 1;
  auto client = client::Client::Connect(Address(port), options);
  const absl::Time end = absl::Now() + timeout;
  while (absl::Now() < end) {
    const absl::StatusOr<std::string> health = client->Health();
    if (health.ok() && *health == "SERVING") return true;
    absl::SleepFor(absl::Milliseconds(20));
  }
  return false;
}

// Every process of the run, started on first use, stopped by StopAll() at the end of main.
class Processes {
 public:
  static Processes& Get() {
    static Processes* processes = new Processes();
    return *processes;
  }

  // The port of a lone server on `store` ("memory" or "dir"), started on first use; 0 (and
  // `*error`) when it does not come up.
  int Lone(const std::string& store, std::string* error) {
    auto& [port, process] = lone_[store];
    if (port != 0) return port;
    port = FreePort();
    const std::string flag = store == "memory"
                                 ? "--store=memory"
                                 : absl::StrCat("--store=dir:", (dir_ / "dir-store").string());
    process = Serve(store, port, flag);
    if (!WaitServing(port, absl::Seconds(20))) {
      *error = absl::StrCat(store, " server not SERVING: ", process->ReadLog());
      port = 0;
    }
    return port;
  }

  // Starts redis-server, the replicas and nginx on first use; false (and `*error`) when one of
  // them is missing or does not come up.
  bool StartTopology(std::string* error) {
    if (nginx_port_ != 0) return true;
    if (!topology_error_.empty()) {
      *error = topology_error_;
      return false;
    }
    topology_error_ = StartTopologyOnce();
    *error = topology_error_;
    return topology_error_.empty();
  }
  int nginx_port() const { return nginx_port_; }
  int replica_port(int i) const { return replica_ports_[i]; }

  // nginx by SIGTERM (its master stops the workers), the servers, then Redis (SIGTERM: it
  // writes the AOF out); the temporary directory.
  void StopAll() {
    if (nginx_ && nginx_->Stop(SIGTERM, absl::Seconds(5)) < 0) {
      kill(-nginx_->pid(), SIGKILL);  // its own process group: master and workers
      nginx_->Wait(absl::Seconds(5));
    }
    nginx_.reset();
    replicas_.clear();
    lone_.clear();
    if (redis_) redis_->Stop(SIGTERM, absl::Seconds(10));
    redis_.reset();
    fs::remove_all(dir_);
  }

 private:
  Processes() {
    dir_ = fs::temp_directory_path() / absl::StrCat("splinegrid-store-bench-", getpid());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }

  // A splinegrid server pinned to CPU 0 (this thread's affinity is inherited, then restored).
  std::unique_ptr<ChildProcess> Serve(const std::string& name, int port, const std::string& store) {
    PinToCpu(0);
    auto process = std::make_unique<ChildProcess>(
        std::vector<std::string>{SPLINEGRID_BINARY_DIR "/splinegrid", "serve",
                                 absl::StrCat("--address=", Address(port)), store, "--threads=1",
                                 "--log_calls=false"},
        (dir_ / (name + ".log")).string());
    PinToCpu(1);
    return process;
  }

  std::string StartTopologyOnce() {
    const std::string redis_server = FindProgram("redis-server");
    const std::string nginx = FindProgram("nginx");
    if (redis_server.empty() || nginx.empty()) {
      return "redis-server or nginx is not installed (.ci/setup installs them)";
    }
    // Redis: AOF, fsync before every reply, loopback only.
    const int redis_port = FreePort();
    fs::create_directories(dir_ / "redis");
    std::ofstream(dir_ / "redis.conf")
        << "bind 127.0.0.1\nport " << redis_port << "\nprotected-mode yes\ndaemonize no\ndir "
        << (dir_ / "redis").string()
        << "\nlogfile \"\"\nappendonly yes\nappendfsync always\n"
           "save \"\"\n";
    PinToCpu(0);
    redis_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{redis_server, (dir_ / "redis.conf").string()},
        (dir_ / "redis.log").string());
    PinToCpu(1);
    if (!WaitForPort(redis_port, absl::Seconds(10))) return "redis-server: " + redis_->ReadLog();
    // The replicas.
    for (int i = 0; i < kReplicas; ++i) {
      replica_ports_.push_back(FreePort());
      replicas_.push_back(Serve(absl::StrCat("replica-", i), replica_ports_[i],
                                absl::StrCat("--store=redis://127.0.0.1:", redis_port)));
    }
    for (int i = 0; i < kReplicas; ++i) {
      if (!WaitServing(replica_ports_[i], absl::Seconds(20))) {
        return absl::StrCat("replica ", i, " not SERVING: ", replicas_[i]->ReadLog());
      }
    }
    // nginx with the shipped template, rendered.
    const int nginx_port = FreePort();
    const fs::path run = dir_ / "nginx";
    fs::create_directories(run);
    std::string command = absl::StrCat(SPLINEGRID_SOURCE_DIR "/deploy/nginx/render.sh --run-dir ",
                                       run.string(), " --listen ", Address(nginx_port));
    for (int port : replica_ports_) absl::StrAppend(&command, " --upstream ", Address(port));
    std::string rendered;
    if (RunShell(absl::StrCat(command, " 2>/dev/null"), &rendered) != 0) {
      return "deploy/nginx/render.sh failed: " + rendered;
    }
    std::ofstream(run / "nginx.conf") << rendered;
    PinToCpu(0);
    nginx_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{nginx, "-p", run.string(), "-c", (run / "nginx.conf").string(),
                                 "-g", "daemon off;"},
        (dir_ / "nginx.log").string());
    PinToCpu(1);
    if (!WaitServing(nginx_port, absl::Seconds(10))) {
      return "nginx not SERVING: " + nginx_->ReadLog() +
             ReadFileToString((run / "error.log").string()).value_or("");
    }
    nginx_port_ = nginx_port;
    return "";
  }

  fs::path dir_;
  std::map<std::string, std::pair<int, std::unique_ptr<ChildProcess>>> lone_;
  std::unique_ptr<ChildProcess> redis_, nginx_;
  std::vector<std::unique_ptr<ChildProcess>> replicas_;
  std::vector<int> replica_ports_;
  int nginx_port_ = 0;
  std::string topology_error_;
};

// Where a benchmark's calls go, by its argument.
enum Target { kDirectMemory = 0, kDirectDir = 1, kReplica = 2, kTopology = 3 };

const char* TargetLabel(int target) {
  switch (target) {
    case kDirectMemory:
      return "memory, direct";
    case kDirectDir:
      return "dir:, direct";
    case kReplica:
      return "redis://, one replica directly";
    default:
      return "redis://, nginx + 3 replicas";
  }
}

// A client of the target (default retries and deadline); nullptr and the reason in `*error`.
std::unique_ptr<client::Client> Connect(int target, std::string* error) {
  Processes& processes = Processes::Get();
  int port = 0;
  if (target == kDirectMemory || target == kDirectDir) {
    port = processes.Lone(target == kDirectMemory ? "memory" : "dir", error);
  } else if (processes.StartTopology(error)) {
    port = target == kReplica ? processes.replica_port(0) : processes.nginx_port();
  }
  if (port == 0) return nullptr;
  return client::Client::Connect(Address(port));
}

// Results of earlier benchmarks of this run, for the ratios ("deform/0/p50" ...).
std::map<std::string, double>& Results() {
  static auto* results = new std::map<std::string, double>();
  return *results;
}

// Imports `file` as `id` (its 2D view when it is a two-plane grid) and fits it by boundary kind
// (0.15e-3 wall, 2e-3 interface, 8e-3 outer); the fit, or the error. `import_us` and `fit_us`
// get the two calls' times.
absl::StatusOr<v1::FitGridResponse> ImportAndFit(client::Client& client, const std::string& file,
                                                 const std::string& id, double* import_us,
                                                 double* fit_us) {
  absl::StatusOr<std::string> bytes = ReadFileToString(SharedDataPath(file));
  if (!bytes.ok()) return bytes.status();
  v1::Plot3dSource as_the_cli_does;
  as_the_cli_does.set_planar_view_if_two_planes(true);
  auto start = std::chrono::steady_clock::now();
  if (absl::Status s = client.ImportPlot3d(*bytes, id, file, as_the_cli_does).status(); !s.ok()) {
    return s;
  }
  *import_us = MicrosecondsSince(start);
  v1::FitSpec spec;
  spec.mutable_boundary_tolerances();
  start = std::chrono::steady_clock::now();
  absl::StatusOr<v1::FitGridResponse> fit = client.Fit(id, spec);
  *fit_us = MicrosecondsSince(start);
  return fit;
}

// Coupling steps against the target: DeformGrid then EvaluateGrid at the original resolution.
void BM_DeformEvaluate(benchmark::State& state) {
  const int target = static_cast<int>(state.range(0));
  state.SetLabel(TargetLabel(target));
  std::string error;
  std::unique_ptr<client::Client> client = Connect(target, &error);
  if (!client) return state.SkipWithError(error.c_str());
  const std::string id = absl::StrCat("pitch-", target);
  (void)client->Delete(id);
  double import_us = 0, fit_us = 0;
  const absl::StatusOr<v1::FitGridResponse> fit =
      ImportAndFit(*client, "grids/n0012_pitch_257x129.fmt", id, &import_us, &fit_us);
  if (!fit.ok()) return state.SkipWithError(fit.status().ToString().c_str());
  v1::EvaluateGridRequest evaluate;
  evaluate.set_name(id);
  evaluate.set_refinement_level(0);
  int64_t previous = fit->revision();
  int64_t n = 0;
  // One step; its deform time in `*deform_us`; false (the state skipped) on an error.
  auto step = [&](double* deform_us) {
    ++n;
    const auto start = std::chrono::steady_clock::now();
    v1::DeformGridRequest deform;
    deform.set_name(id);
    deform.set_reference_revision(fit->revision());
    deform.set_base_revision(previous);
    deform.set_step(n);
    deform.set_time(0.01 * static_cast<double>(n));
    deform.mutable_rigid()->set_angle_degrees(10.0 *
                                              std::sin(2.0 * kPi * static_cast<double>(n) / 200));
    deform.mutable_rigid()->add_center(0.25);
    deform.mutable_rigid()->add_center(0.0);
    const absl::StatusOr<v1::DeformGridResponse> moved = client->Deform(deform);
    if (!moved.ok()) {
      state.SkipWithError(moved.status().ToString().c_str());
      return false;
    }
    *deform_us = MicrosecondsSince(start);
    previous = moved->revision();
    evaluate.set_revision(previous);
    const absl::StatusOr<client::EvaluatedGrid> grid = client->Evaluate(evaluate);
    if (!grid.ok()) {
      state.SkipWithError(grid.status().ToString().c_str());
      return false;
    }
    return true;
  };
  double deform_us = 0;
  for (int warm = 0; warm < 20; ++warm) {
    if (!step(&deform_us)) return;
  }
  std::vector<double> step_us, deforms_us;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    if (!step(&deform_us)) return;
    step_us.push_back(MicrosecondsSince(start));
    deforms_us.push_back(deform_us);
  }
  (void)client->Delete(id);
  const double p50 = Percentile(step_us, 0.5), p99 = Percentile(step_us, 0.99);
  state.SetItemsProcessed(state.iterations());
  state.counters["p50_us"] = p50;
  state.counters["p99_us"] = p99;
  state.counters["deform_p50_us"] = Percentile(deforms_us, 0.5);
  state.counters["deform_p99_us"] = Percentile(deforms_us, 0.99);
  Results()[absl::StrCat("deform/", target, "/p50")] = p50;
  Results()[absl::StrCat("deform/", target, "/p99")] = p99;
  if (const auto direct = Results().find("deform/0/p50"); direct != Results().end()) {
    state.counters["p50_over_direct"] = p50 / direct->second;
    state.counters["p99_over_direct"] = p99 / Results()["deform/0/p99"];
  }
}
BENCHMARK(BM_DeformEvaluate)
    ->Arg(kDirectMemory)
    ->Arg(kReplica)
    ->Arg(kTopology)
    ->ArgName("target")
    ->Iterations(1000)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// ImportGrid + FitGrid of the NACA 0012 225 x 65 C-grid into a fresh grid each iteration.
void BM_ImportFit(benchmark::State& state) {
  const int target = static_cast<int>(state.range(0));
  state.SetLabel(TargetLabel(target));
  std::string error;
  std::unique_ptr<client::Client> client = Connect(target, &error);
  if (!client) return state.SkipWithError(error.c_str());
  std::vector<double> import_ms, fit_ms, total_ms;
  double compression = 0;
  for (auto _ : state) {
    const std::string id = absl::StrCat("naca-", target, "-", import_ms.size());
    double import_us = 0, fit_us = 0;
    const absl::StatusOr<v1::FitGridResponse> fit =
        ImportAndFit(*client, "grids/n0012_225-65.p2dfmt", id, &import_us, &fit_us);
    if (!fit.ok()) return state.SkipWithError(fit.status().ToString().c_str());
    compression = fit->compression_ratio();
    import_ms.push_back(import_us / 1e3);
    fit_ms.push_back(fit_us / 1e3);
    total_ms.push_back((import_us + fit_us) / 1e3);
    state.PauseTiming();
    (void)client->Delete(id);
    state.ResumeTiming();
  }
  const double total = Percentile(total_ms, 0.5), fitted = Percentile(fit_ms, 0.5);
  state.counters["import_ms"] = Percentile(import_ms, 0.5);
  state.counters["fit_ms"] = fitted;
  state.counters["total_ms"] = total;
  state.counters["compression"] = compression;
  Results()[absl::StrCat("fit/", target, "/total")] = total;
  Results()[absl::StrCat("fit/", target, "/fit")] = fitted;
  if (const auto memory = Results().find("fit/0/total"); memory != Results().end()) {
    state.counters["total_over_memory"] = total / memory->second;
    state.counters["fit_over_memory"] = fitted / Results()["fit/0/fit"];
  }
}
BENCHMARK(BM_ImportFit)
    ->Arg(kDirectMemory)
    ->Arg(kDirectDir)
    ->Arg(kReplica)
    ->Arg(kTopology)
    ->ArgName("store")
    ->Iterations(7)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace splinegrid::bench

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  splinegrid::bench::PinToCpu(1);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  splinegrid::bench::Processes::Get().StopAll();
  return 0;
}
