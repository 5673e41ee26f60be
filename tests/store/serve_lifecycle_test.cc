// Issue 12 (5, 6) on the real binary: `serve` flags out of range stop it with a message naming
// the flag; SIGTERM turns health NOT_SERVING while calls are still served for --drain_notice,
// then the server drains and exits 0; the JSON call log has one parseable object per line.
#include <signal.h>

#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "client/client.h"
#include "gmock/gmock.h"
#include "google/protobuf/struct.pb.h"
#include "google/protobuf/util/json_util.h"
#include "gtest/gtest.h"
#include "tests/store/server_process.h"

namespace splinegrid::testing {
namespace {

using ::testing::HasSubstr;

const std::string kBinary = SPLINEGRID_BINARY_DIR "/splinegrid";

struct FlagCase {
  std::string flag;     // the bad flag
  std::string message;  // a part of the message it gets
};

TEST(ServeFlagsTest, OutOfRangeFlagsExitNonZeroNamingTheFlag) {
  const int port = FreePort();
  const std::string address = absl::StrCat("--address=127.0.0.1:", port);
  const std::vector<FlagCase> cases = {
      {"--address=127.0.0.1:99999", "the port '99999' of '127.0.0.1:99999'"},
      {"--address=127.0.0.1:0", "not a number in 1-65535"},
      {"--address=127.0.0.1:-5", "the port '-5'"},
      {"--address=127.0.0.1", "has no port"},
      {"--address=[::1]:70000", "the port '70000' of '[::1]:70000'"},
      {"--address=::1:5000", "[IPV6]:PORT"},
      {"--memory_budget_mb=17592186044417", "--memory_budget_mb = 17592186044417 is outside"},
      {"--memory_budget_mb=-1", "--memory_budget_mb = -1 is outside"},
      {"--threads=-1", "--threads = -1 is outside [0, 1024]"},
      {"--threads=100000", "--threads = 100000 is outside"},
      {"--max_output_points=0", "--max_output_points = 0 is outside"},
      {"--keep_revisions=0", "--keep_revisions = 0 is outside"},
      {"--max_streams_per_principal=0", "--max_streams_per_principal = 0 is outside"},
      {"--drain_notice=-1s", "--drain_notice = -1s is outside"},
      {"--shutdown_grace=-2s", "--shutdown_grace = -2s is outside"},
      {"--log_format=xml", "--log_format = 'xml' is not text or json"},
  };
  for (const FlagCase& c : cases) {
    // `timeout`: a flag that slipped through would serve forever.
    const bool sets_address = c.flag.rfind("--address", 0) == 0;
    std::string out;
    const int code = RunShell(
        absl::StrCat("timeout 20 ", kBinary, " serve ", sets_address ? "" : address + " ", c.flag),
        &out);
    EXPECT_NE(code, 0) << c.flag << "\n" << out;
    EXPECT_NE(code, 124) << c.flag << " was served:\n" << out;
    EXPECT_THAT(out, HasSubstr(c.message)) << c.flag;
    EXPECT_THAT(out, ::testing::Not(HasSubstr("serving on port"))) << c.flag;
  }
}

// The lines of `text` that are JSON objects.
std::vector<std::string> JsonLines(const std::string& text) {
  std::vector<std::string> lines;
  for (absl::string_view line : absl::StrSplit(text, '\n', absl::SkipEmpty())) {
    if (!line.empty() && line.front() == '{') lines.emplace_back(line);
  }
  return lines;
}

class DrainTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           absl::StrCat("splinegrid-drain-", ::getpid(), "-", FreePort());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path dir_;
};

TEST_F(DrainTest, SigtermTurnsNotServingWhileCallsSucceedThenExits) {
  const int port = FreePort();
  ChildProcess server({kBinary, "serve", absl::StrCat("--address=127.0.0.1:", port), "--threads=2",
                       "--drain_notice=2s", "--shutdown_grace=2s", "--log_format=json"},
                      (dir_ / "server.log").string());
  ASSERT_TRUE(WaitForPort(port, absl::Seconds(20))) << server.ReadLog();
  client::ClientOptions options;
  options.timeout = absl::Seconds(10);
  options.retry.max_attempts = 1;
  const std::string target = absl::StrCat("127.0.0.1:", port);
  std::unique_ptr<client::Client> client = client::Client::Connect(target, options);
  ASSERT_EQ(client->Health("splinegrid.v1.SplineGrid").value_or("?"), "SERVING");
  // A forged log line in a name, and a 1 MiB name: one log line each, short errors.
  const absl::Status forged =
      client->Get("grids/naca\n2026-01-01T00:00:00.000Z DeleteGrid grids/naca OK").status();
  EXPECT_EQ(forged.code(), absl::StatusCode::kInvalidArgument) << forged;
  // (Through the bare stub: the client library would also put the name in a routing header.)
  grpc::ClientContext context;
  v1::GetGridRequest request;
  request.set_name("grids/" + std::string(1 << 20, 'n'));
  v1::Grid grid;
  const grpc::Status huge = client->stub().GetGrid(&context, request, &grid);
  EXPECT_EQ(huge.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
      << huge.error_message().substr(0, 300);
  EXPECT_LT(huge.error_message().size(), 500u);
  EXPECT_THAT(huge.error_message(), HasSubstr("(1048582 bytes)"));

  const absl::Time term = absl::Now();
  ASSERT_EQ(kill(server.pid(), SIGTERM), 0);
  // Health turns NOT_SERVING at once, for the service and the whole server ...
  std::string health;
  while (absl::Now() - term < absl::Seconds(1.5)) {
    health = client->Health("splinegrid.v1.SplineGrid").value_or("?");
    if (health == "NOT_SERVING") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(health, "NOT_SERVING");
  EXPECT_EQ(client->Health("").value_or("?"), "NOT_SERVING");
  // ... while calls are still served, also on a new connection (a load balancer's last ones).
  EXPECT_TRUE(client->List().ok()) << client->List().status();
  std::unique_ptr<client::Client> late = client::Client::Connect(target, options);
  EXPECT_TRUE(late->List().ok());
  EXPECT_LT(absl::Now() - term, absl::Seconds(2)) << "the checks above ran after the notice";
  EXPECT_TRUE(server.running());
  // Then the server drains and exits by itself, not before the notice has passed.
  EXPECT_EQ(server.Wait(absl::Seconds(20)), 0) << server.ReadLog();
  EXPECT_GE(absl::Now() - term, absl::Seconds(1.9));
  EXPECT_FALSE(PortOpen(port));

  const std::string log = server.ReadLog();
  EXPECT_THAT(log, HasSubstr("NOT_SERVING, still accepting calls for 2s"));
  EXPECT_THAT(log, HasSubstr("stopped"));
  // One JSON object per call (2 gets, 2 lists; health checks are not SplineGrid calls).
  const std::vector<std::string> lines = JsonLines(log);
  EXPECT_EQ(lines.size(), 4u) << log.substr(0, 5000);
  for (const std::string& line : lines) {
    google::protobuf::Struct json;
    ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(line, &json).ok()) << line;
    for (const char* key : {"time", "method", "grid", "principal", "status", "ms", "message"}) {
      EXPECT_TRUE(json.fields().contains(key)) << key << " missing in " << line;
    }
    EXPECT_LT(line.size(), 2000u);
  }
  // The name's newline is escaped once (JSON's \u000a): the value is the name as sent.
  EXPECT_THAT(log, HasSubstr("\"grid\":\"grids/naca\\u000a2026-01-01T00:00:00.000Z DeleteGrid"));
  EXPECT_THAT(log, ::testing::Not(HasSubstr("\n2026-01-01T00:00:00.000Z DeleteGrid")));
}

TEST_F(DrainTest, ZeroNoticeRefusesAtOnce) {
  const int port = FreePort();
  ChildProcess server({kBinary, "serve", absl::StrCat("--address=127.0.0.1:", port), "--threads=2",
                       "--drain_notice=0s"},
                      (dir_ / "server.log").string());
  ASSERT_TRUE(WaitForPort(port, absl::Seconds(20))) << server.ReadLog();
  const absl::Time term = absl::Now();
  EXPECT_EQ(server.Stop(SIGTERM, absl::Seconds(20)), 0) << server.ReadLog();
  EXPECT_LT(absl::Now() - term, absl::Seconds(1.5));
  EXPECT_THAT(server.ReadLog(), ::testing::Not(HasSubstr("still accepting calls")));
}

}  // namespace
}  // namespace splinegrid::testing
