// `serve --metrics_address`: the real binary on loopback ports, calls made with the CLI, then
// /metrics read with a plain HTTP GET over a socket. Every line of the body must be a valid
// line of the Prometheus text format, the call counters must match the server's own call log,
// and the gauges the store and the budget.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <signal.h>

#include <cstring>
#include <map>
#include <memory>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"
#include "tests/store/server_process.h"

namespace splinegrid::testing {
namespace {

using ::testing::HasSubstr;

const std::string kBinary = SPLINEGRID_BINARY_DIR "/splinegrid";

// The raw HTTP response to `METHOD path` (HTTP/1.0) on 127.0.0.1:port ("" when it cannot
// connect).
std::string Http(const std::string& method, int port, const std::string& path) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port);
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string response;
  if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0) {
    const std::string request =
        absl::StrCat(method, " ", path, " HTTP/1.0\r\nHost: localhost\r\n\r\n");
    if (write(fd, request.data(), request.size()) == static_cast<ssize_t>(request.size())) {
      char buffer[65536];
      for (ssize_t n; (n = read(fd, buffer, sizeof(buffer))) > 0;) response.append(buffer, n);
    }
  }
  close(fd);
  return response;
}

std::string HttpGet(int port, const std::string& path) { return Http("GET", port, path); }

struct Sample {
  std::string name;
  std::string labels;  // as written, without braces
  double value;
};

// Parses a text-format body strictly: # HELP / # TYPE lines and `name{labels} value` samples,
// each sample after the TYPE of its family (histograms: _bucket, _sum, _count). Failures are
// reported per line.
std::vector<Sample> ParseExposition(const std::string& body) {
  static const std::regex kSample(
      R"(^([a-zA-Z_:][a-zA-Z0-9_:]*)(?:\{((?:[a-zA-Z_][a-zA-Z0-9_]*="(?:\\.|[^"\\])*")(?:,[a-zA-Z_][a-zA-Z0-9_]*="(?:\\.|[^"\\])*")*)\})? (\S+)$)");
  static const std::regex kHelp(R"(^# HELP ([a-zA-Z_:][a-zA-Z0-9_:]*) \S.*$)");
  static const std::regex kType(R"(^# TYPE ([a-zA-Z_:][a-zA-Z0-9_:]*) (counter|gauge|histogram)$)");
  std::vector<Sample> samples;
  std::map<std::string, std::string> types;
  EXPECT_TRUE(absl::EndsWith(body, "\n"));
  for (absl::string_view line : absl::StrSplit(body, '\n', absl::SkipEmpty())) {
    const std::string text(line);
    std::smatch match;
    if (std::regex_match(text, match, kHelp)) continue;
    if (std::regex_match(text, match, kType)) {
      EXPECT_TRUE(types.emplace(match[1].str(), match[2].str()).second) << "second TYPE: " << text;
      continue;
    }
    if (!std::regex_match(text, match, kSample)) {
      ADD_FAILURE() << "not a text-format line: " << text;
      continue;
    }
    Sample sample{match[1].str(), match[2].str(), 0};
    EXPECT_TRUE(absl::SimpleAtod(match[3].str(), &sample.value)) << text;
    std::string family = sample.name;
    for (const char* suffix : {"_bucket", "_sum", "_count"}) {
      if (absl::EndsWith(family, suffix) && types.count(family) == 0) {
        family = family.substr(0, family.size() - std::strlen(suffix));
        EXPECT_EQ(types[family], "histogram") << text;
      }
    }
    EXPECT_TRUE(types.count(family)) << "sample before its TYPE: " << text;
    samples.push_back(sample);
  }
  return samples;
}

// The value of `name{labels}`, or -1 if absent.
double Value(const std::vector<Sample>& samples, const std::string& name,
             const std::string& labels = "") {
  for (const Sample& sample : samples) {
    if (sample.name == name && sample.labels == labels) return sample.value;
  }
  return -1;
}

int CountLines(const std::string& log, const std::string& needle) {
  int n = 0;
  for (absl::string_view line : absl::StrSplit(log, '\n')) n += absl::StrContains(line, needle);
  return n;
}

class MetricsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    port_ = FreePort();
    do {
      metrics_port_ = FreePort();
    } while (metrics_port_ == port_);
    server_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{kBinary, "serve", absl::StrCat("--address=127.0.0.1:", port_),
                                 absl::StrCat("--metrics_address=127.0.0.1:", metrics_port_),
                                 "--threads=2", "--drain_notice=0s"},
        absl::StrCat(::testing::TempDir(), "/metrics-server-", getpid(), ".log"));
    ASSERT_TRUE(WaitForPort(port_, absl::Seconds(20))) << server_->ReadLog();
    ASSERT_TRUE(WaitForPort(metrics_port_, absl::Seconds(20))) << server_->ReadLog();
  }
  void TearDown() override {
    if (server_) EXPECT_EQ(server_->Stop(SIGTERM, absl::Seconds(20)), 0) << server_->ReadLog();
  }

  int Cli(const std::string& args, std::string* out) {
    return RunShell(absl::StrCat("timeout 120 ", kBinary, " ", args, " --server=127.0.0.1:", port_),
                    out);
  }

  int port_ = 0;
  int metrics_port_ = 0;
  std::unique_ptr<ChildProcess> server_;
};

TEST_F(MetricsTest, CountsCallsAndReportsTheStoreAndBudgetInTheTextFormat) {
  std::string out;
  ASSERT_EQ(Cli("list", &out), 0) << out;
  ASSERT_EQ(Cli("list", &out), 0) << out;
  EXPECT_EQ(Cli("get nosuch", &out), 1) << out;
  ASSERT_EQ(Cli(absl::StrCat("fit ", SharedDataPath("grids/n0012_113-33.p2dfmt"),
                             " --name=naca --kinds"),
                &out),
            0)
      << out;

  const std::string response = HttpGet(metrics_port_, "/metrics");
  ASSERT_THAT(response, ::testing::StartsWith("HTTP/1.1 200 OK\r\n")) << response;
  EXPECT_THAT(response, HasSubstr("text/plain; version=0.0.4"));
  const std::string body = response.substr(response.find("\r\n\r\n") + 4);
  const std::vector<Sample> samples = ParseExposition(body);

  // The counters agree with the call log, line for line.
  const std::string log = server_->ReadLog();
  EXPECT_EQ(Value(samples, "splinegrid_calls_total", R"(method="ListGrids",code="OK")"), 2);
  EXPECT_EQ(Value(samples, "splinegrid_calls_total", R"(method="ListGrids",code="OK")"),
            CountLines(log, " ListGrids - OK "));
  EXPECT_EQ(Value(samples, "splinegrid_calls_total", R"(method="GetGrid",code="NOT_FOUND")"),
            CountLines(log, " GetGrid grids/nosuch NOT_FOUND "));
  EXPECT_EQ(Value(samples, "splinegrid_calls_total", R"(method="GetGrid",code="NOT_FOUND")"), 1);
  EXPECT_EQ(Value(samples, "splinegrid_calls_total", R"(method="FitGrid",code="OK")"), 1);
  EXPECT_EQ(Value(samples, "splinegrid_calls_total", R"(method="ImportGrid",code="OK")"), 1);
  EXPECT_EQ(Value(samples, "splinegrid_calls_total", R"(method="DeformGrid",code="OK")"), 0);

  // Histograms: cumulative buckets, +Inf equal to the count, the count to the calls.
  double previous = 0;
  for (const Sample& sample : samples) {
    if (sample.name != "splinegrid_call_duration_seconds_bucket" ||
        !absl::StartsWith(sample.labels, R"(method="ListGrids",)")) {
      continue;
    }
    EXPECT_GE(sample.value, previous) << sample.labels;
    previous = sample.value;
  }
  EXPECT_EQ(previous, 2);
  EXPECT_EQ(Value(samples, "splinegrid_call_duration_seconds_count", R"(method="ListGrids")"), 2);
  EXPECT_GT(Value(samples, "splinegrid_call_duration_seconds_sum", R"(method="FitGrid")"), 0);

  // Gauges.
  EXPECT_EQ(Value(samples, "splinegrid_grids"), 1);
  EXPECT_EQ(Value(samples, "splinegrid_revisions"), 1);
  EXPECT_GT(Value(samples, "splinegrid_memory_budget_used_bytes"), 0);
  EXPECT_GE(Value(samples, "splinegrid_memory_budget_limit_bytes"),
            Value(samples, "splinegrid_memory_budget_used_bytes"));
  EXPECT_EQ(Value(samples, "splinegrid_scheduler_queued_tasks", R"(kind="cheap")"), 0);
  EXPECT_EQ(Value(samples, "splinegrid_scheduler_queued_tasks", R"(kind="long")"), 0);
  EXPECT_EQ(Value(samples, "splinegrid_scheduler_workers"), 2);
  EXPECT_EQ(Value(samples, "splinegrid_open_streams"), 0);
  EXPECT_EQ(Value(samples, "splinegrid_draining"), 0);
  EXPECT_GT(Value(samples, "process_resident_memory_bytes"), 1 << 20);

  // Deleting the grid shows in the next scrape.
  ASSERT_EQ(Cli("rm naca", &out), 0) << out;
  const std::string after = HttpGet(metrics_port_, "/metrics");
  const std::vector<Sample> later = ParseExposition(after.substr(after.find("\r\n\r\n") + 4));
  EXPECT_EQ(Value(later, "splinegrid_grids"), 0);
  EXPECT_EQ(Value(later, "splinegrid_calls_total", R"(method="DeleteGrid",code="OK")"), 1);
}

TEST_F(MetricsTest, OtherPathsAndMethodsAreRefused) {
  EXPECT_THAT(HttpGet(metrics_port_, "/"), ::testing::StartsWith("HTTP/1.1 404"));
  EXPECT_THAT(HttpGet(metrics_port_, "/metrics/x"), ::testing::StartsWith("HTTP/1.1 404"));
  EXPECT_THAT(Http("POST", metrics_port_, "/metrics"), ::testing::StartsWith("HTTP/1.1 405"));
  // The endpoint still answers after those.
  EXPECT_THAT(HttpGet(metrics_port_, "/metrics"), ::testing::StartsWith("HTTP/1.1 200"));
}

TEST(MetricsAddress, NonLoopbackNeedsMetricsInsecureAndAMalformedOneIsRefused) {
  std::string out;
  EXPECT_EQ(RunShell(absl::StrCat("timeout 60 ", kBinary,
                                  " serve --address=127.0.0.1:1 --metrics_address=0.0.0.0:9100"),
                     &out),
            2);
  EXPECT_THAT(out, HasSubstr("--metrics_address = '0.0.0.0:9100' is not a loopback address"));
  EXPECT_THAT(out, HasSubstr("--metrics_insecure"));
  EXPECT_EQ(RunShell(absl::StrCat("timeout 60 ", kBinary,
                                  " serve --address=127.0.0.1:1 --metrics_address=localhost"),
                     &out),
            2);
  EXPECT_THAT(out, HasSubstr("--metrics_address"));
}

TEST(MetricsAddress, APortInUseStopsTheServerWithAClearError) {
  const int port = FreePort();
  const int taken = FreePort();
  ChildProcess first({kBinary, "serve", absl::StrCat("--address=127.0.0.1:", taken),
                      "--drain_notice=0s"},
                     absl::StrCat(::testing::TempDir(), "/metrics-taken-", getpid(), ".log"));
  ASSERT_TRUE(WaitForPort(taken, absl::Seconds(20))) << first.ReadLog();
  std::string out;
  EXPECT_EQ(RunShell(absl::StrCat("timeout 60 ", kBinary, " serve --address=127.0.0.1:", port,
                                  " --drain_notice=0s --metrics_address=127.0.0.1:", taken),
                     &out),
            1);
  EXPECT_THAT(out, HasSubstr("UNAVAILABLE: --metrics_address = '127.0.0.1:"));
  EXPECT_EQ(first.Stop(SIGTERM, absl::Seconds(20)), 0);
}

}  // namespace
}  // namespace splinegrid::testing
