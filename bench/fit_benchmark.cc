// Fit throughput of the tensor least-squares fit (FitBlock: parametrisation, knots, banded QR
// passes and the deviation at every data point), over sizes spanning >= 100x in points.
// items_per_second = data points per second; the compression per direction is fixed (~5.3x,
// 128 -> 24 points) so that cost per point is comparable across sizes.
//
// The baseline: SciPy's separable fit (make_lsq_spline direction by direction,
// bench/scipy_separable_fit.py, run with Debian's /usr/bin/python3) of the same 128^3 points,
// parameters and knots, timed in the same run. The 128^3 fit and solve report `vs_scipy`:
// SciPy's median time over this fit's mean time (2 = twice as fast as SciPy).
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "Eigen/Dense"
#include "bench/grid_samples.h"
#include "bench/peak_memory.h"
#include "benchmark/benchmark.h"
#include "core/bspline/basis.h"
#include "core/fit/solve/tensor_fit.h"

namespace splinegrid::bench {
namespace {

int Controls(int points) { return std::max(4, static_cast<int>(std::lround(points * 24.0 / 128))); }

constexpr int kScipyExtent = 128;  // the baseline's block: 128^3 points

// Parameters and knots of `block` as the kernel's FitBlock chooses them (chord length, averaged
// knots, order 4).
struct FitSetup {
  std::array<std::vector<double>, 3> params;
  std::array<KnotVector, 3> knots;
};

FitSetup SetupOf(const StructuredBlock& block) {
  FitSetup setup{ParametrizeBlock(block, Parametrization::kChordLength), {}};
  for (int d = 0; d < 3; ++d) {
    setup.knots[d] = KnotVector::Averaged(4, Controls(block.extent(d)), setup.params[d]).value();
  }
  return setup;
}

struct ScipyBaseline {
  double seconds = 0.0;  // median wall time of one separable fit; 0 when it could not run
  std::string label;     // SciPy's version, or why there is no baseline
};

// Writes the block in the format bench/scipy_separable_fit.py reads, runs the script and parses
// its one line of JSON.
ScipyBaseline RunScipy() {
  const StructuredBlock block = CurvilinearBlock({kScipyExtent, kScipyExtent, kScipyExtent});
  const FitSetup setup = SetupOf(block);
  char path[] = "/tmp/splinegrid-scipy-XXXXXX";
  const int fd = mkstemp(path);
  if (fd < 0) return {0.0, "mkstemp failed"};
  close(fd);
  {
    std::ofstream out(path, std::ios::binary);
    auto put_int = [&](int32_t v) { out.write(reinterpret_cast<const char*>(&v), sizeof v); };
    auto put_doubles = [&](std::span<const double> v) {
      put_int(static_cast<int32_t>(v.size()));
      out.write(reinterpret_cast<const char*>(v.data()), v.size_bytes());
    };
    for (int32_t v : {block.extent(0), block.extent(1), block.extent(2), block.spatial_dim(), 4}) {
      put_int(v);
    }
    for (int d = 0; d < 3; ++d) {
      put_doubles(setup.params[d]);
      put_doubles(setup.knots[d].knots());
    }
    out.write(reinterpret_cast<const char*>(block.coords().data()),
              block.coords().size() * sizeof(double));
  }
  const std::string command =
      std::string("/usr/bin/python3 " SPLINEGRID_SOURCE_DIR "/bench/scipy_separable_fit.py ") +
      path + " 7 2>&1";
  std::string output;
  if (FILE* pipe = popen(command.c_str(), "r")) {
    char buffer[4096];
    while (size_t n = fread(buffer, 1, sizeof buffer, pipe)) output.append(buffer, n);
    const int status = pclose(pipe);
    if (status != 0) output = "exit status " + std::to_string(status) + ": " + output;
  }
  std::remove(path);
  auto field = [&](const std::string& key) -> std::string {
    const size_t at = output.find("\"" + key + "\": ");
    if (at == std::string::npos) return "";
    const size_t begin = at + key.size() + 4;
    return output.substr(begin, output.find_first_of(",}", begin) - begin);
  };
  const double seconds = std::strtod(field("seconds_median").c_str(), nullptr);
  if (!(seconds > 0.0)) return {0.0, "no SciPy baseline: " + output.substr(0, 300)};
  std::string version = field("scipy");
  std::erase(version, '"');
  return {seconds, "scipy " + version + " make_lsq_spline x3, median of 7"};
}

const ScipyBaseline& Scipy() {
  static const ScipyBaseline* baseline = new ScipyBaseline(RunScipy());
  return *baseline;
}

// For the baseline's block size: vs_scipy = SciPy's time / `seconds` per fit.
void ReportVsScipy(benchmark::State& state, const Extents& points, double seconds) {
  if (points != Extents{kScipyExtent, kScipyExtent, kScipyExtent}) return;
  if (Scipy().seconds > 0.0) {
    state.counters["vs_scipy"] = Scipy().seconds / (seconds / state.iterations());
  } else {
    state.SetLabel(Scipy().label);
  }
}

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// SciPy's fit itself, first, so that its time shows beside the kernel's.
void BM_ScipySeparableFit(benchmark::State& state) {
  const ScipyBaseline& scipy = Scipy();
  if (scipy.seconds == 0.0) {
    state.SkipWithError(scipy.label.c_str());
    return;
  }
  for (auto _ : state) state.SetIterationTime(scipy.seconds);
  state.SetItemsProcessed(state.iterations() * int64_t{kScipyExtent} * kScipyExtent * kScipyExtent);
  state.SetLabel(scipy.label);
}
BENCHMARK(BM_ScipySeparableFit)
    ->Arg(kScipyExtent* kScipyExtent* kScipyExtent)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

void RunFit(benchmark::State& state, const Extents& points) {
  const StructuredBlock block = CurvilinearBlock(points);
  FitOptions options;
  for (int d = 0; d < 3; ++d) options.control_counts[d] = points[d] > 1 ? Controls(points[d]) : 0;
  double max_deviation = 0.0;
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) {
    absl::StatusOr<FittedBlock> fitted = FitBlock(block, options);
    if (!fitted.ok()) {
      state.SkipWithError(std::string(fitted.status().message()).c_str());
      return;
    }
    max_deviation = fitted->summary.deviation.max;
    benchmark::DoNotOptimize(fitted->spline.control().data());
  }
  ReportVsScipy(state, points, SecondsSince(start));
  state.SetItemsProcessed(state.iterations() * block.num_points());
  state.counters["max_deviation"] = max_deviation;
  const double input_bytes = static_cast<double>(block.coords().size() * sizeof(double));
  const int64_t extra = PeakExtraBytes([&] { benchmark::DoNotOptimize(FitBlock(block, options)); });
  if (extra >= 0) state.counters["peak_extra_over_input"] = extra / input_bytes;
}

void BM_FitCurve(benchmark::State& state) {
  RunFit(state, {static_cast<int>(state.range(0)), 1, 1});
}
BENCHMARK(BM_FitCurve)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMicrosecond);

void BM_FitSurface(benchmark::State& state) {
  const int n = static_cast<int>(std::lround(std::sqrt(double(state.range(0)))));
  RunFit(state, {n, n, 1});
}
BENCHMARK(BM_FitSurface)
    ->Arg(32 * 32)
    ->Arg(100 * 100)
    ->Arg(320 * 320)
    ->Arg(1024 * 1024)
    ->Unit(benchmark::kMicrosecond);

void BM_FitVolume(benchmark::State& state) {
  const int n = static_cast<int>(std::lround(std::cbrt(double(state.range(0)))));
  RunFit(state, {n, n, n});
}
BENCHMARK(BM_FitVolume)
    ->Arg(27 * 27 * 27)
    ->Arg(48 * 48 * 48)
    ->Arg(80 * 80 * 80)
    ->Arg(128 * 128 * 128)
    ->Unit(benchmark::kMillisecond);

// The least-squares solve alone (FitTensor with the parametrisation and knots precomputed): the
// three banded-QR passes, which is what SciPy's make_lsq_spline applied direction by direction
// computes (there via normal equations).
void BM_FitVolumeSolve(benchmark::State& state) {
  const int n = static_cast<int>(std::lround(std::cbrt(double(state.range(0)))));
  const StructuredBlock block = CurvilinearBlock({n, n, n});
  const FitSetup setup = SetupOf(block);
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) {
    absl::StatusOr<TensorSpline> spline =
        FitTensor(block, setup.params, setup.knots, EndCondition::kInterpolate);
    benchmark::DoNotOptimize(spline->control().data());
  }
  ReportVsScipy(state, block.extents(), SecondsSince(start));
  state.SetItemsProcessed(state.iterations() * block.num_points());
}
BENCHMARK(BM_FitVolumeSolve)
    ->Arg(27 * 27 * 27)
    ->Arg(48 * 48 * 48)
    ->Arg(80 * 80 * 80)
    ->Arg(128 * 128 * 128)
    ->Unit(benchmark::kMillisecond);

// For contrast: the same surface fit as one dense least-squares problem on the Kronecker
// matrix (what the separable banded method avoids). Cost grows like points * controls^2.
void BM_FitSurfaceDenseReference(benchmark::State& state) {
  const int n = static_cast<int>(std::lround(std::sqrt(double(state.range(0)))));
  const StructuredBlock block = CurvilinearBlock({n, n, 1});
  const int c = Controls(n);
  std::vector<double> u(n);
  for (int i = 0; i < n; ++i) u[i] = double(i) / (n - 1);
  const KnotVector kv = KnotVector::Averaged(4, c, u).value();
  const SampledBasis b = SampleBasis(kv, u);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, c);
  for (int q = 0; q < n; ++q)
    for (int t = 0; t < 4; ++t) a(q, b.first[q] + t) = b.Row(q)[t];
  Eigen::MatrixXd rhs(n * n, 3);
  for (int p = 0; p < n * n; ++p)
    for (int x = 0; x < 3; ++x) rhs(p, x) = block.coords()[3 * p + x];
  for (auto _ : state) {
    Eigen::MatrixXd kron(n * n, c * c);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (int y = 0; y < c; ++y)
          for (int x = 0; x < c; ++x) kron(i + n * j, x + c * y) = a(i, x) * a(j, y);
    Eigen::MatrixXd p = kron.householderQr().solve(rhs);
    benchmark::DoNotOptimize(p.data());
  }
  state.SetItemsProcessed(state.iterations() * n * n);
}
BENCHMARK(BM_FitSurfaceDenseReference)
    ->Arg(32 * 32)
    ->Arg(64 * 64)
    ->Arg(100 * 100)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace splinegrid::bench
