// Service benchmarks over loopback TCP. The server runs in a child process pinned to CPU 0
// (one server core: the worker pool has one thread), the client in this process on CPU 1.
// Beside the service runs a raw gRPC baseline (raw_baseline_server: the smallest callback
// service, gRPC's defaults) started the same way; its benchmarks run first, and the service's
// report `vs_raw`, their rate as a fraction of the baseline's in the same run.
//   BM_RawUnary              the baseline's unary call (24-byte reply), 16 in flight
//   BM_RawStream             the baseline's server stream of prebuilt 256 KiB messages
//   BM_EvaluateGridStream    payload bytes/s of EvaluateGrid for a volume of >= 50M points
//   BM_EvaluatePointsUnary   one-point EvaluatePoints calls with 16 in flight: calls/s, p50/p99
//   BM_FitThroughApi         FitGrid latency for every shared grid, tolerances by boundary kind
//   BM_IdleServerMemory      resident memory of a started, idle server
//   BM_DeformThenEvaluate    one coupling step on the pitching NACA 0012 (257 x 129): DeformGrid
//                            (rigid, reference = the fit) then EvaluateGrid at the original
//                            resolution, sequential: steps/s, p50/p99 of the step
//   BM_PitchingRun           100 steps of +-amplitude degrees (DeformGrid with reference = fit
//                            and base = previous, EvaluateGrid at level 1, client-side fold
//                            check): p50/p90/p99/max of deform, evaluate and step, folds
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sched.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "bench/grid_samples.h"
#include "bench/latency.h"
#include "bench/service/raw_baseline.grpc.pb.h"
#include "benchmark/benchmark.h"
#include "client/client.h"
#include "core/io/file_util.h"
#include "tests/core/test_data.h"

namespace splinegrid::bench {
namespace {

void PinToCpu(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  sched_setaffinity(0, sizeof(set), &set);
}

// A port that was free a moment ago.
int FreePort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr));
  socklen_t len = sizeof(addr);
  getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  close(fd);
  return ntohs(addr.sin_port);
}

// A server binary in a child process pinned to CPU 0 (exec'd, not just forked: gRPC does not
// survive fork), on a free loopback port; this process moves to CPU 1. By default the real
// `splinegrid serve` with one worker thread.
class ServerProcess {
 public:
  ServerProcess()
      : ServerProcess("splinegrid", {"serve", "--threads=1", "--log_calls=false",
                                     "--max_output_points=2147483648"}) {
    auto client = client::Client::Connect(target());
    for (int i = 0; i < 200 && !client->Health().ok(); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(25));
    }
  }
  // `binary` (in the build directory) with `args` and --address=127.0.0.1:PORT.
  ServerProcess(const std::string& binary, std::vector<std::string> args) : port_(FreePort()) {
    args.push_back(absl::StrCat("--address=127.0.0.1:", port_));
    pid_ = fork();
    if (pid_ == 0) {
      prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlive the benchmark
      PinToCpu(0);
      const std::string path = absl::StrCat(SPLINEGRID_BINARY_DIR, "/", binary);
      std::vector<char*> argv = {const_cast<char*>(path.c_str())};
      for (std::string& arg : args) argv.push_back(arg.data());
      argv.push_back(nullptr);
      execv(path.c_str(), argv.data());
      _exit(127);
    }
    PinToCpu(1);
  }
  ~ServerProcess() {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  std::string target() const { return absl::StrCat("127.0.0.1:", port_); }
  // Resident memory of the server process, MiB.
  double ResidentMiB() const {
    std::ifstream status(absl::StrCat("/proc/", pid_, "/status"));
    std::string line;
    while (std::getline(status, line)) {
      if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
    }
    return -1;
  }

 private:
  int port_;
  pid_t pid_ = -1;
};

// The raw baseline's rates in this run (0 until its benchmark ran).
struct Baseline {
  double unary_calls_per_s = 0.0;
  double stream_bytes_per_s = 0.0;
};
Baseline& RawBaselineRates() {
  static Baseline baseline;
  return baseline;
}

// The raw baseline server (bench/service/raw_baseline_server) and a stub on one channel with
// the settings of client::Client::Connect.
struct RawServer {
  ServerProcess process{"bench/raw_baseline_server", {}};
  std::shared_ptr<grpc::Channel> channel;
  std::unique_ptr<RawBaseline::Stub> stub;
  RawServer() {
    grpc::ChannelArguments args;
    args.SetMaxReceiveMessageSize(8 << 20);
    channel = grpc::CreateCustomChannel(process.target(), grpc::InsecureChannelCredentials(), args);
    channel->WaitForConnected(std::chrono::system_clock::now() + std::chrono::seconds(5));
    stub = RawBaseline::NewStub(channel);
  }
};
RawServer& SharedRawServer() {
  static RawServer* server = new RawServer();
  return *server;
}

ServerProcess& SharedServer() {
  static ServerProcess* server = new ServerProcess();
  return *server;
}

void BM_IdleServerMemory(benchmark::State& state) {
  ServerProcess server;  // fresh: nothing imported
  auto client = client::Client::Connect(server.target());
  if (!client->Health().ok()) return state.SkipWithError("server not healthy");
  for (auto _ : state) benchmark::DoNotOptimize(server.ResidentMiB());
  state.counters["resident_MiB"] = server.ResidentMiB();
}
BENCHMARK(BM_IdleServerMemory)->Iterations(1);

// Unary calls, kUnaryInFlight at a time (callback API): `start(done)` issues one call and runs
// done(ok) when it ends. Sets items/s, p50_us and p99_us; returns calls per second (0 when a
// call failed).
constexpr int kUnaryInFlight = 16;
double RunUnaryCalls(benchmark::State& state, int64_t calls,
                     const std::function<void(std::function<void(bool)>)>& start) {
  std::vector<double> latencies;
  latencies.reserve(calls);
  std::mutex mu;
  std::condition_variable done_cv;
  int64_t started = 0, finished = 0;
  std::atomic<int64_t> failures{0};
  std::function<void()> launch = [&] {
    const auto begin = std::chrono::steady_clock::now();
    start([&, begin](bool ok) {
      const double us = MicrosecondsSince(begin);
      if (!ok) ++failures;
      bool more;
      {
        std::lock_guard<std::mutex> lock(mu);
        latencies.push_back(us);
        ++finished;
        more = started < calls;
        if (more) ++started;
      }
      if (more) {
        launch();
      } else {
        done_cv.notify_all();
      }
    });
  };
  double seconds = 0.0;
  for (auto _ : state) {
    const auto begin = std::chrono::steady_clock::now();
    const int64_t first = std::min<int64_t>(kUnaryInFlight, calls);
    {
      std::lock_guard<std::mutex> lock(mu);
      started = first;
      finished = 0;
      latencies.clear();
    }
    for (int64_t i = 0; i < first; ++i) launch();
    std::unique_lock<std::mutex> lock(mu);
    done_cv.wait(lock, [&] { return finished == calls; });
    seconds = MicrosecondsSince(begin) * 1e-6;
  }
  if (failures > 0) {
    state.SkipWithError("some calls failed");
    return 0.0;
  }
  std::sort(latencies.begin(), latencies.end());
  state.SetItemsProcessed(calls);
  state.counters["p50_us"] = latencies[latencies.size() / 2];
  state.counters["p99_us"] = latencies[latencies.size() * 99 / 100];
  return static_cast<double>(calls) / seconds;
}

// The baseline's unary call: request and reply shaped like a one-point EvaluatePoints.
void BM_RawUnary(benchmark::State& state) {
  RawServer& raw = SharedRawServer();
  UnaryRequest request;
  request.set_name("grids/m6");
  request.add_blocks(1);
  for (double p : {0.3, 0.7, 0.0}) request.add_parameters(p);
  struct Call {
    grpc::ClientContext context;
    UnaryReply reply;
  };
  RawBaselineRates().unary_calls_per_s =
      RunUnaryCalls(state, state.range(0), [&](std::function<void(bool)> done) {
        auto* call = new Call();
        raw.stub->async()->Unary(&call->context, &request, &call->reply,
                                 [call, done = std::move(done)](grpc::Status status) {
                                   const bool ok = status.ok() && call->reply.values_size() == 3;
                                   delete call;
                                   done(ok);
                                 });
      });
}
BENCHMARK(BM_RawUnary)
    ->Arg(200000)
    ->ArgName("calls")
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// The baseline's server stream: as many payload bytes as BM_EvaluateGridStream's double
// evaluation (370^3 points x 3 doubles), in messages of EvaluateGrid's chunk size (256 KiB).
constexpr int64_t kStreamPoints = int64_t{370} * 370 * 370;
void BM_RawStream(benchmark::State& state) {
  RawServer& raw = SharedRawServer();
  StreamRequest request;
  request.set_total_bytes(kStreamPoints * 3 * 8);
  request.set_chunk_bytes(256 << 10);
  int64_t bytes = 0;
  double seconds = 0.0;
  double best = 0.0;  // bytes/s of the fastest stream (they vary by 2x within a run here)
  for (auto _ : state) {
    const auto begin = std::chrono::steady_clock::now();
    grpc::ClientContext context;
    std::unique_ptr<grpc::ClientReader<StreamChunk>> reader = raw.stub->Stream(&context, request);
    StreamChunk chunk;
    int64_t streamed = 0;
    while (reader->Read(&chunk)) streamed += 8 * int64_t{chunk.values_size()};
    if (!reader->Finish().ok()) return state.SkipWithError("Stream failed");
    const double elapsed = MicrosecondsSince(begin) * 1e-6;
    best = std::max(best, static_cast<double>(streamed) / elapsed);
    bytes += streamed;
    seconds += elapsed;
  }
  state.SetBytesProcessed(bytes);
  state.counters["best_bytes_per_s"] = best;
  // The same measure as BM_EvaluateGridStream's: all bytes over all time.
  RawBaselineRates().stream_bytes_per_s = static_cast<double>(bytes) / seconds;
}
BENCHMARK(BM_RawStream)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

// A 64^3 volume fitted with 24^3 control points, evaluated at 370^3 = 50.65M points.
void BM_EvaluateGridStream(benchmark::State& state) {
  const bool single = state.range(0) == 1;
  auto client = client::Client::Connect(SharedServer().target());
  static bool imported = false;
  if (!imported) {
    MultiBlockGrid grid;
    grid.blocks.push_back(CurvilinearBlock({64, 64, 64}));
    if (!client->ImportPoints(grid, "volume", "").ok()) return state.SkipWithError("import");
    v1::FitSpec spec;
    spec.mutable_control_counts()->set_i(24);
    spec.mutable_control_counts()->set_j(24);
    spec.mutable_control_counts()->set_k(24);
    if (!client->Fit("volume", spec).ok()) return state.SkipWithError("fit");
    imported = true;
  }
  v1::EvaluateGridRequest request;
  request.set_name("grids/volume");
  request.mutable_counts()->set_i(370);  // kStreamPoints
  request.mutable_counts()->set_j(370);
  request.mutable_counts()->set_k(370);
  request.set_precision(single ? v1::PRECISION_FLOAT : v1::PRECISION_DOUBLE);
  int64_t bytes = 0, points = 0;
  double seconds = 0.0;
  for (auto _ : state) {
    const auto begin = std::chrono::steady_clock::now();
    grpc::ClientContext context;
    auto reader = client->stub().EvaluateGrid(&context, request);
    v1::EvaluateGridResponse message;
    while (reader->Read(&message)) {
      if (message.has_header()) {
        points += message.header().total_points();
        continue;
      }
      bytes += message.chunk().values_size() * 8 + message.chunk().float_values_size() * 4;
    }
    if (!reader->Finish().ok()) return state.SkipWithError("EvaluateGrid failed");
    seconds += MicrosecondsSince(begin) * 1e-6;
  }
  state.SetBytesProcessed(bytes);
  state.SetItemsProcessed(points);
  if (RawBaselineRates().stream_bytes_per_s > 0.0) {
    state.counters["vs_raw"] =
        static_cast<double>(bytes) / seconds / RawBaselineRates().stream_bytes_per_s;
  }
}
BENCHMARK(BM_EvaluateGridStream)
    ->Arg(0)
    ->Arg(1)
    ->ArgName("float")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);

// One-point EvaluatePoints calls, 16 in flight (callback API), latencies recorded per call.
void BM_EvaluatePointsUnary(benchmark::State& state) {
  auto client = client::Client::Connect(SharedServer().target());
  static bool imported = false;
  if (!imported) {
    const std::string bytes = ReadFileToString(SharedDataPath("surfaces/m6_small.fmt")).value();
    if (absl::Status s = client->ImportPlot3d(bytes, "m6", "", false).status(); !s.ok()) {
      return state.SkipWithError(s.ToString().c_str());
    }
    v1::FitSpec spec;
    spec.set_tolerance(1e-4);
    if (!client->Fit("m6", spec).ok()) return state.SkipWithError("fit");
    imported = true;
  }
  v1::EvaluatePointsRequest request;
  request.set_name("grids/m6");
  request.add_blocks(1);
  request.add_parameters(0.3);
  request.add_parameters(0.7);
  request.add_parameters(0.0);
  struct Call {
    grpc::ClientContext context;
    v1::EvaluatePointsResponse response;
  };
  const double rate = RunUnaryCalls(state, state.range(0), [&](std::function<void(bool)> done) {
    auto* call = new Call();
    client->stub().async()->EvaluatePoints(&call->context, &request, &call->response,
                                           [call, done = std::move(done)](grpc::Status status) {
                                             delete call;
                                             done(status.ok());
                                           });
  });
  if (RawBaselineRates().unary_calls_per_s > 0.0) {
    state.counters["vs_raw"] = rate / RawBaselineRates().unary_calls_per_s;
  }
}
BENCHMARK(BM_EvaluatePointsUnary)
    ->Arg(200000)
    ->ArgName("calls")
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// FitGrid latency through the API for each shared grid, fitted to the paper's tolerances by
// boundary kind (0.15e-3 wall, 2e-3 interface, 8e-3 outer, in the file's unit), with the
// report (cell quality at levels 0-2, gaps, wall curvature).
void BM_FitThroughApi(benchmark::State& state) {
  static const std::vector<std::string> kFiles = {
      "grids/n0012_113-33.p2dfmt",     "grids/n0012_225-65.p2dfmt", "grids/rae2822_257x97.fmt",
      "grids/n0012_pitch_257x129.fmt", "surfaces/m6_small.fmt",     "surfaces/even_sphere.fmt",
      "surfaces/ffd_box_6x2x6.fmt"};
  const std::string& file = kFiles[state.range(0)];
  state.SetLabel(file);
  auto client = client::Client::Connect(SharedServer().target());
  const std::string bytes = ReadFileToString(SharedDataPath(file)).value();
  v1::Plot3dSource as_the_cli_does;
  as_the_cli_does.set_planar_view_if_two_planes(true);
  const std::string id = absl::StrCat("fit-", state.range(0));
  (void)client->Delete(id);
  if (!client->ImportPlot3d(bytes, id, file, as_the_cli_does).ok()) {
    return state.SkipWithError("import");
  }
  v1::FitSpec spec;
  spec.mutable_boundary_tolerances();
  double ratio = 0.0;
  for (auto _ : state) {
    absl::StatusOr<v1::FitGridResponse> fit = client->Fit(id, spec);
    if (!fit.ok()) return state.SkipWithError(std::string(fit.status().message()).c_str());
    ratio = fit->compression_ratio();
  }
  state.counters["compression"] = ratio;
}
BENCHMARK(BM_FitThroughApi)->DenseRange(0, 6)->Unit(benchmark::kMillisecond);

constexpr double kPi = 3.14159265358979323846;

// Imports the pitching NACA 0012 as `id` (its 2D view) and fits it to the default tolerances by
// boundary kind; the fit's revision, or 0 (and the error in `error`).
int64_t ImportPitchGrid(client::Client& client, const std::string& id, std::string* error) {
  absl::StatusOr<std::string> bytes =
      ReadFileToString(SharedDataPath("grids/n0012_pitch_257x129.fmt"));
  if (!bytes.ok()) {
    *error = bytes.status().ToString();
    return 0;
  }
  (void)client.Delete(id);
  if (absl::Status s = client.ImportPlot3d(*bytes, id, "", true).status(); !s.ok()) {
    *error = s.ToString();
    return 0;
  }
  v1::FitSpec spec;
  spec.mutable_boundary_tolerances();
  absl::StatusOr<v1::FitGridResponse> fit = client.Fit(id, spec);
  if (!fit.ok()) {
    *error = fit.status().ToString();
    return 0;
  }
  return fit->revision();
}

v1::DeformGridRequest PitchRequest(const std::string& id, int64_t reference, double degrees) {
  v1::DeformGridRequest request;
  request.set_name(id);
  request.set_reference_revision(reference);
  request.mutable_rigid()->set_angle_degrees(degrees);
  request.mutable_rigid()->add_center(0.25);
  request.mutable_rigid()->add_center(0.0);
  return request;
}

// Signed areas of the cells of the evaluated 2D blocks.
std::vector<double> CellAreas(const client::EvaluatedGrid& grid) {
  std::vector<double> areas;
  for (const client::EvaluatedBlock& b : grid.blocks) {
    const StructuredBlock& p = b.points;
    for (int j = 0; j + 1 < p.extent(1); ++j) {
      for (int i = 0; i + 1 < p.extent(0); ++i) {
        const double *a = p.Point(i, j, 0), *b1 = p.Point(i + 1, j, 0), *c = p.Point(i, j + 1, 0),
                     *d = p.Point(i + 1, j + 1, 0);
        areas.push_back(0.5 * ((d[0] - a[0]) * (c[1] - b1[1]) - (d[1] - a[1]) * (c[0] - b1[0])));
      }
    }
  }
  return areas;
}

// Sequential coupling steps: DeformGrid (rigid pitch about the quarter chord, reference = the
// fit, the angle changing every step) then EvaluateGrid of the new revision at the original
// resolution (257 x 129 points).
void BM_DeformThenEvaluate(benchmark::State& state) {
  auto client = client::Client::Connect(SharedServer().target());
  static int64_t fitted = 0;
  if (fitted == 0) {
    std::string error;
    fitted = ImportPitchGrid(*client, "pitch-step", &error);
    if (fitted == 0) return state.SkipWithError(error.c_str());
  }
  v1::EvaluateGridRequest evaluate;
  evaluate.set_name("grids/pitch-step");
  evaluate.set_refinement_level(0);
  std::vector<double> step_us, deform_us;
  int64_t n = 0, points = 0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const double degrees = 10.0 * std::sin(0.0628 * static_cast<double>(++n));
    absl::StatusOr<v1::DeformGridResponse> moved =
        client->Deform(PitchRequest("pitch-step", fitted, degrees));
    if (!moved.ok()) return state.SkipWithError(moved.status().ToString().c_str());
    deform_us.push_back(MicrosecondsSince(start));
    evaluate.set_revision(moved->revision());
    absl::StatusOr<client::EvaluatedGrid> grid = client->Evaluate(evaluate);
    if (!grid.ok()) return state.SkipWithError(grid.status().ToString().c_str());
    points = grid->blocks.front().points.num_points();
    step_us.push_back(MicrosecondsSince(start));
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["points"] = static_cast<double>(points);
  state.counters["p50_us"] = Percentile(step_us, 0.5);
  state.counters["p99_us"] = Percentile(step_us, 0.99);
  state.counters["deform_p50_us"] = Percentile(deform_us, 0.5);
  state.counters["deform_p99_us"] = Percentile(deform_us, 0.99);
}
BENCHMARK(BM_DeformThenEvaluate)->Iterations(1000)->UseRealTime()->Unit(benchmark::kMillisecond);

// The pitching example's loop as a benchmark: `steps` steps of amplitude sin(2 pi n / steps)
// degrees, each DeformGrid (reference = fit, base = previous revision, time and step set) and
// EvaluateGrid at level 1, every cell's signed area compared with the fitted grid's.
void BM_PitchingRun(benchmark::State& state) {
  const double amplitude = static_cast<double>(state.range(0));
  constexpr int kSteps = 100;
  auto client = client::Client::Connect(SharedServer().target());
  const std::string id = absl::StrCat("pitch-run-", state.range(0));
  std::string error;
  const int64_t fitted = ImportPitchGrid(*client, id, &error);
  if (fitted == 0) return state.SkipWithError(error.c_str());
  v1::EvaluateGridRequest evaluate;
  evaluate.set_name(id);
  evaluate.set_refinement_level(1);
  evaluate.set_revision(fitted);
  const std::vector<double> reference = CellAreas(client->Evaluate(evaluate).value());
  std::vector<double> deform_us, evaluate_us, step_us;
  int64_t folds = 0, refused = 0;
  for (auto _ : state) {
    int64_t previous = fitted;
    for (int n = 1; n <= kSteps; ++n) {
      const auto start = std::chrono::steady_clock::now();
      v1::DeformGridRequest request =
          PitchRequest(id, fitted, amplitude * std::sin(2.0 * kPi * n / kSteps));
      request.set_base_revision(previous);
      request.set_time(0.01 * n);
      request.set_step(n);
      absl::StatusOr<v1::DeformGridResponse> moved = client->Deform(request);
      deform_us.push_back(MicrosecondsSince(start));
      if (!moved.ok()) {
        if (!absl::IsFailedPrecondition(moved.status())) {
          return state.SkipWithError(moved.status().ToString().c_str());
        }
        ++refused;
        continue;
      }
      previous = moved->revision();
      const auto evaluate_start = std::chrono::steady_clock::now();
      evaluate.set_revision(moved->revision());
      absl::StatusOr<client::EvaluatedGrid> grid = client->Evaluate(evaluate);
      if (!grid.ok()) return state.SkipWithError(grid.status().ToString().c_str());
      evaluate_us.push_back(MicrosecondsSince(evaluate_start));
      const std::vector<double> areas = CellAreas(*grid);
      for (size_t c = 0; c < areas.size() && c < reference.size(); ++c) {
        if (reference[c] != 0.0 && !(areas[c] * reference[c] > 0.0)) ++folds;
      }
      step_us.push_back(MicrosecondsSince(start));
    }
  }
  (void)client->Delete(id);
  state.counters["folds"] = static_cast<double>(folds);
  state.counters["refused"] = static_cast<double>(refused);
  for (const auto& [name, values] :
       {std::pair<const char*, const std::vector<double>*>{"deform", &deform_us},
        {"evaluate", &evaluate_us},
        {"step", &step_us}}) {
    state.counters[absl::StrCat(name, "_p50_us")] = Percentile(*values, 0.5);
    state.counters[absl::StrCat(name, "_p90_us")] = Percentile(*values, 0.9);
    state.counters[absl::StrCat(name, "_p99_us")] = Percentile(*values, 0.99);
    state.counters[absl::StrCat(name, "_max_us")] = Percentile(*values, 1.0);
  }
  state.SetLabel(folds > 0 || refused > 0 ? "FOLDS" : "no folds");
}
BENCHMARK(BM_PitchingRun)
    ->Arg(10)
    ->Arg(20)
    ->ArgName("amplitude")
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace splinegrid::bench
