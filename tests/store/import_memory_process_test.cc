// The real server's resident memory under header amplification (issue 12, point 4): ImportGrid
// streams whose headers announce 1.9 GiB each, open and quiet or trickling a little data, keep
// `splinegrid serve --memory_budget_mb=64` within its budget plus the fixed overhead of the
// process, while another client's ordinary import and fit go through.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "client/client.h"
#include "core/io/file_util.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"
#include "tests/store/server_process.h"

namespace splinegrid::testing {
namespace {

const std::string kBinary = SPLINEGRID_BINARY_DIR "/splinegrid";
constexpr int64_t kMiB = int64_t{1} << 20;
constexpr int64_t kBudgetMiB = 64;
// What the budget does not count, measured on this server (see the report in
// server/memory_limit.h's kDefaultBudgetFraction): an idle server is ~15-20 MiB resident (gRPC,
// the worker and watchdog threads' stacks touched, the allocator's arenas); streams add gRPC's
// per-call buffers. 48 MiB leaves room for allocator slack.
constexpr int64_t kOverheadMiB = 48;

// VmRSS of `pid` in bytes (0 when unreadable).
int64_t ResidentBytes(int pid) {
  std::ifstream status(absl::StrCat("/proc/", pid, "/status"));
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) {
      int64_t kib = 0;
      std::string digits;
      for (char c : line) {
        if (c >= '0' && c <= '9') digits += c;
      }
      if (absl::SimpleAtoi(digits, &kib)) return kib * 1024;
    }
  }
  return 0;
}

struct Stream {
  grpc::ClientContext context;
  v1::Grid grid;
  std::unique_ptr<grpc::ClientWriter<v1::ImportGridRequest>> writer;
};

v1::ImportGridRequest HugePointsHeader() {
  v1::ImportGridRequest r;
  r.mutable_header()->mutable_points()->set_spatial_dim(3);
  v1::Extents* x = r.mutable_header()->mutable_points()->add_blocks();
  x->set_i(4096);
  x->set_j(4096);
  x->set_k(5);
  return r;
}

TEST(ImportMemoryProcessTest, HeaderAmplificationStaysWithinBudgetPlusOverhead) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / absl::StrCat("splinegrid-import-rss-", getpid());
  std::filesystem::create_directories(dir);
  const int port = FreePort();
  ChildProcess server({kBinary, "serve", absl::StrCat("--address=127.0.0.1:", port),
                       absl::StrCat("--memory_budget_mb=", kBudgetMiB), "--threads=2",
                       "--import_idle_timeout=60s", "--log_calls=false"},
                      (dir / "server.log").string());
  ASSERT_TRUE(WaitForPort(port, absl::Seconds(20))) << server.ReadLog();
  client::ClientOptions options;
  options.timeout = absl::Seconds(60);
  std::unique_ptr<client::Client> client =
      client::Client::Connect(absl::StrCat("127.0.0.1:", port), options);
  ASSERT_TRUE(client->List().ok());
  const int64_t idle = ResidentBytes(server.pid());
  const int64_t limit = (kBudgetMiB + kOverheadMiB) * kMiB;

  // 12 header-only streams and 4 that trickle 800 KB each, every header announcing 1.9 GiB;
  // and 4 Plot3D uploads announcing 2 GiB that send 64 KiB.
  std::vector<std::unique_ptr<Stream>> streams;
  for (int s = 0; s < 20; ++s) {
    auto stream = std::make_unique<Stream>();
    stream->writer = client->stub().ImportGrid(&stream->context, &stream->grid);
    if (s < 16) {
      ASSERT_TRUE(stream->writer->Write(HugePointsHeader()));
    } else {
      v1::ImportGridRequest header;
      header.mutable_header()->mutable_plot3d()->set_total_bytes(int64_t{2} << 30);
      ASSERT_TRUE(stream->writer->Write(header));
      v1::ImportGridRequest chunk;
      chunk.set_plot3d_chunk(std::string(64 << 10, ' '));
      ASSERT_TRUE(stream->writer->Write(chunk));
    }
    if (s >= 12 && s < 16) {
      v1::ImportGridRequest points;
      points.mutable_points()->set_block(0);
      points.mutable_points()->mutable_coordinates()->Resize(100000, 1.0);
      ASSERT_TRUE(stream->writer->Write(points));
    }
    streams.push_back(std::move(stream));
  }
  // And one that really sends 20 MiB of its announced 1.9 GiB, in 1 MiB messages: held (and
  // charged) as it grows, up to half the budget.
  {
    auto big = std::make_unique<Stream>();
    big->writer = client->stub().ImportGrid(&big->context, &big->grid);
    ASSERT_TRUE(big->writer->Write(HugePointsHeader()));
    v1::ImportGridRequest points;
    points.mutable_points()->set_block(0);
    points.mutable_points()->mutable_coordinates()->Resize(131072, 0.5);
    for (int m = 0; m < 20; ++m) ASSERT_TRUE(big->writer->Write(points));
    streams.push_back(std::move(big));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const int64_t with_streams = ResidentBytes(server.pid());
  EXPECT_LT(with_streams, limit);

  // Another client imports and fits meanwhile.
  std::unique_ptr<client::Client> other =
      client::Client::Connect(absl::StrCat("127.0.0.1:", port), options);
  int64_t peak = with_streams;
  for (const char* name :
       {"grids/n0012_225-65.p2dfmt", "grids/rae2822_257x97.fmt", "grids/n0012_113-33.p2dfmt"}) {
    const std::string bytes = ReadFileToString(SharedDataPath(name)).value();
    absl::StatusOr<v1::Grid> grid = other->ImportPlot3d(bytes, "", name, false);
    ASSERT_TRUE(grid.ok()) << name << ": " << grid.status();
    v1::FitSpec spec;
    spec.mutable_control_counts();  // 0 x 0 x 0: as many controls as points
    spec.set_allow_folds(true);     // interpolating these C-grids folds sub-cells at level 1-2
    absl::StatusOr<v1::FitGridResponse> fit = other->Fit(grid->name(), spec);
    EXPECT_TRUE(fit.ok()) << name << ": " << fit.status();
    peak = std::max(peak, ResidentBytes(server.pid()));
  }
  EXPECT_LT(peak, limit);

  for (auto& stream : streams) {
    stream->writer->WritesDone();
    EXPECT_EQ(stream->writer->Finish().error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  }
  const int64_t after = ResidentBytes(server.pid());
  std::printf(
      "VmRSS: idle %.1f MiB, 21 amplified streams (20 MiB sent) %.1f MiB, peak with 3 imports + "
      "fits "
      "%.1f MiB, after %.1f MiB; budget %lld MiB + stated overhead %lld MiB\n",
      idle / 1048576.0, with_streams / 1048576.0, peak / 1048576.0, after / 1048576.0,
      static_cast<long long>(kBudgetMiB), static_cast<long long>(kOverheadMiB));
  EXPECT_THAT(server.ReadLog(), ::testing::HasSubstr("memory budget 64 MiB (--memory_budget_mb)"));
  server.Stop(SIGTERM);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace splinegrid::testing
