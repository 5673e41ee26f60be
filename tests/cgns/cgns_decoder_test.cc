// The CGNS decoder child's limits through the real server, with fake decoders (shell scripts
// given by --cgns_decoder) that misbehave as a decoder on a hostile file might: hang, write
// without end, print garbage, print a long message naming the upload. Each run records its pid
// and the upload's path, so the tests can check that the child was reaped and the temporary
// file removed. Also: the child's memory limit held against the budget while it runs, the
// serve flags' range checks.
#include <signal.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <thread>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "client/client.h"
#include "core/io/file_util.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/cgns/cgns_test_util.h"
#include "tests/store/server_process.h"

namespace splinegrid {
namespace {

using ::splinegrid::testing::ChildProcess;
using ::splinegrid::testing::TempDir;
using ::testing::HasSubstr;
using ::testing::Not;

const std::string kBinary = SPLINEGRID_BINARY_DIR "/splinegrid";
// What the server receives as the CGNS file: the fake decoders never read it.
const std::string kUpload = "fake CGNS bytes";

// A fake decoder: records its pid and argument in `dir`, then does what the file `mode` says.
std::string WriteFakeDecoder(const TempDir& dir) {
  const std::string path = dir.File("fake-decode");
  std::ofstream(path) << "#!/bin/sh\n"
                      << "D='" << dir.File("") << "'\n"
                      << R"(echo "$1" > "$D/upload"
echo $$ > "$D/pid.new" && mv "$D/pid.new" "$D/pid"
case $(cat "$D/mode") in
  hang) sleep 30 & echo $! > "$D/grandchild"; wait ;;
  endless) exec cat /dev/zero ;;
  garbage) printf 'not a CgnsDecoded message \377\377\377\377'; exit 0 ;;
  long) i=0
        while [ $i -lt 100 ]; do printf '%s: bad node %s in zone %s. ' "$1" $i $i; i=$((i+1)); done
        exit 2 ;;
  packed) printf 'xxxxxxxxxxxxxx'
        i=0
        while [ $i -lt 80 ]; do printf '%s' "$1"; i=$((i+1)); done
        exit 2 ;;
esac
exit 3
)";
  EXPECT_EQ(chmod(path.c_str(), 0755), 0);
  return path;
}

// The process `pid`'s state letter from /proc (R, S, Z, ...), or 0 when there is none.
char ProcessState(int pid) {
  std::ifstream stat(absl::StrCat("/proc/", pid, "/stat"));
  std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
  const size_t paren = text.rfind(')');
  return paren == std::string::npos || paren + 2 >= text.size() ? 0 : text[paren + 2];
}

// The number in `path` (written by the fake decoder), or -1.
int ReadPid(const std::string& path) {
  absl::StatusOr<std::string> text = ReadFileToString(path);
  int pid = -1;
  if (!text.ok() || !absl::SimpleAtoi(absl::StripAsciiWhitespace(*text), &pid)) return -1;
  return pid;
}

// A server on a free port whose decoder is the fake one, with `extra` flags.
class FakeDecoderServer {
 public:
  FakeDecoderServer(const TempDir& dir, std::vector<std::string> extra,
                    absl::Duration client_timeout = absl::Seconds(20))
      : dir_(dir), port_(testing::FreePort()) {
    std::vector<std::string> argv = {kBinary,
                                     "serve",
                                     absl::StrCat("--address=127.0.0.1:", port_),
                                     "--drain_notice=0s",
                                     "--shutdown_grace=0s",
                                     "--threads=3",
                                     absl::StrCat("--cgns_decoder=", WriteFakeDecoder(dir))};
    argv.insert(argv.end(), extra.begin(), extra.end());
    process_ = std::make_unique<ChildProcess>(argv, dir.File("server.log"));
    ready_ = testing::WaitForPort(port_, absl::Seconds(20));
    client::ClientOptions options;
    options.timeout = client_timeout;
    client_ = client::Client::Connect(absl::StrCat("127.0.0.1:", port_), options);
  }

  bool ready() const { return ready_; }
  std::string log() const { return process_->ReadLog(); }
  void Mode(const std::string& mode) const { std::ofstream(dir_.File("mode")) << mode << "\n"; }
  absl::StatusOr<v1::Grid> Import() { return client_->ImportCgns(kUpload, "", "fake.cgns"); }
  int pid() const { return ReadPid(dir_.File("pid")); }
  std::string upload() const {
    absl::StatusOr<std::string> text = ReadFileToString(dir_.File("upload"));
    return text.ok() ? std::string(absl::StripAsciiWhitespace(*text)) : "";
  }
  // The child was reaped (no zombie) and the temporary upload removed.
  void ExpectCleanedUp() const {
    const int child = pid();
    ASSERT_GT(child, 0);
    EXPECT_EQ(ProcessState(child), 0) << "decoder pid " << child << " is still there";
    ASSERT_FALSE(upload().empty());
    EXPECT_FALSE(std::filesystem::exists(upload())) << upload();
  }

 private:
  const TempDir& dir_;
  int port_;
  bool ready_ = false;
  std::unique_ptr<ChildProcess> process_;
  std::unique_ptr<client::Client> client_;
};

TEST(CgnsDecoderTest, AHangingDecoderIsKilledAtTheWallTimeLimitAndHoldsItsMemoryMeanwhile) {
  TempDir dir("cgns-decoder");
  FakeDecoderServer server(dir, {"--cgns_decoder_timeout_seconds=1", "--memory_budget_mb=256",
                                 "--cgns_decoder_memory_mb=160"});
  ASSERT_TRUE(server.ready()) << server.log();
  server.Mode("hang");
  const absl::Time start = absl::Now();
  absl::StatusOr<v1::Grid> hung = absl::UnknownError("not run");
  std::thread first([&] { hung = server.Import(); });
  // Once the first decoder runs, its 160 MiB are held: a second one does not fit in 256.
  while (server.pid() < 0 && absl::Now() - start < absl::Seconds(5)) {
    absl::SleepFor(absl::Milliseconds(10));
  }
  const int first_pid = server.pid();
  absl::StatusOr<v1::Grid> second = server.Import();
  EXPECT_EQ(second.status().code(), absl::StatusCode::kResourceExhausted) << second.status();
  EXPECT_THAT(second.status().message(), HasSubstr("--cgns_decoder_memory_mb = 160"));
  first.join();
  const absl::Duration took = absl::Now() - start;
  EXPECT_EQ(server.pid(), first_pid);  // the second never started a decoder
  EXPECT_EQ(hung.status().code(), absl::StatusCode::kInvalidArgument) << hung.status();
  EXPECT_THAT(hung.status().message(), HasSubstr("wall-time limit of 1s"));
  EXPECT_THAT(hung.status().message(), HasSubstr("killed"));
  EXPECT_GE(took, absl::Seconds(1));
  EXPECT_LT(took, absl::Seconds(3));
  server.ExpectCleanedUp();
  // The grandchild (the decoder's own `sleep`) died with it: its process group was killed.
  // Reparented to PID 1 it may linger as a zombie when PID 1 does not reap; it is not running.
  const int grandchild = ReadPid(dir.File("grandchild"));
  ASSERT_GT(grandchild, 0);
  const absl::Time wait_until = absl::Now() + absl::Seconds(1);
  while (ProcessState(grandchild) != 0 && ProcessState(grandchild) != 'Z' &&
         absl::Now() < wait_until) {
    absl::SleepFor(absl::Milliseconds(10));
  }
  EXPECT_THAT(ProcessState(grandchild), ::testing::AnyOf(0, 'Z'));
  // Released with the child: the next decode gets its memory (and fails on its output instead).
  server.Mode("garbage");
  absl::StatusOr<v1::Grid> third = server.Import();
  EXPECT_EQ(third.status().code(), absl::StatusCode::kInvalidArgument) << third.status();
}

TEST(CgnsDecoderTest, EndlessOutputIsRefusedByTheBudgetAndTheDecoderKilled) {
  TempDir dir("cgns-decoder");
  FakeDecoderServer server(dir, {"--memory_budget_mb=192", "--cgns_decoder_memory_mb=64"});
  ASSERT_TRUE(server.ready()) << server.log();
  server.Mode("endless");
  const absl::Time start = absl::Now();
  absl::StatusOr<v1::Grid> imported = server.Import();
  EXPECT_EQ(imported.status().code(), absl::StatusCode::kResourceExhausted) << imported.status();
  EXPECT_THAT(imported.status().message(), HasSubstr("the decoded CGNS file"));
  EXPECT_LT(absl::Now() - start, absl::Seconds(3));
  server.ExpectCleanedUp();
}

TEST(CgnsDecoderTest, GarbageWithExitZeroIsInvalidArgument) {
  TempDir dir("cgns-decoder");
  FakeDecoderServer server(dir, {});
  ASSERT_TRUE(server.ready()) << server.log();
  server.Mode("garbage");
  absl::StatusOr<v1::Grid> imported = server.Import();
  EXPECT_EQ(imported.status().code(), absl::StatusCode::kInvalidArgument) << imported.status();
  EXPECT_THAT(imported.status().message(), HasSubstr("not a CgnsDecoded message"));
  server.ExpectCleanedUp();
}

TEST(CgnsDecoderTest, ALongMessageIsCutAndDoesNotNameTheTemporaryFile) {
  TempDir dir("cgns-decoder");
  FakeDecoderServer server(dir, {});
  ASSERT_TRUE(server.ready()) << server.log();
  server.Mode("long");
  absl::StatusOr<v1::Grid> imported = server.Import();
  EXPECT_EQ(imported.status().code(), absl::StatusCode::kInvalidArgument) << imported.status();
  const std::string message(imported.status().message());
  EXPECT_THAT(message, HasSubstr("cgns: "));
  EXPECT_THAT(message, HasSubstr("the upload: bad node 0 in zone 0."));
  EXPECT_THAT(message, HasSubstr(" bytes)"));  // cut, with the length noted
  EXPECT_LT(message.size(), 2100u);
  ASSERT_FALSE(server.upload().empty());
  EXPECT_THAT(message, Not(HasSubstr(server.upload())));
  EXPECT_THAT(message, Not(HasSubstr("splinegrid-cgns-")));  // not even a part of its name
  server.ExpectCleanedUp();

  // The name back to back past the cut: replacing shortens the text, which must not pull a
  // part of a later name under the cut (the review's case: 14 characters, then the name 80 times).
  server.Mode("packed");
  imported = server.Import();
  EXPECT_EQ(imported.status().code(), absl::StatusCode::kInvalidArgument) << imported.status();
  EXPECT_THAT(imported.status().message(), HasSubstr("the uploadthe upload"));
  EXPECT_THAT(imported.status().message(), Not(HasSubstr("splinegrid-cgns-")));
  EXPECT_THAT(imported.status().message(), Not(HasSubstr("/tmp/")));
  server.ExpectCleanedUp();
}

TEST(CgnsDecoderTest, ACancelledImportKillsTheDecoder) {
  TempDir dir("cgns-decoder");
  // The client gives up after 0.5 s; the server's own limit is far away.
  FakeDecoderServer server(dir, {"--cgns_decoder_timeout_seconds=60"}, absl::Milliseconds(500));
  ASSERT_TRUE(server.ready()) << server.log();
  server.Mode("hang");
  absl::StatusOr<v1::Grid> imported = server.Import();
  EXPECT_EQ(imported.status().code(), absl::StatusCode::kDeadlineExceeded) << imported.status();
  // The server notices within its 100 ms poll, kills and reaps the child, removes the upload
  // and logs the call.
  const absl::Time wait_until = absl::Now() + absl::Seconds(2);
  while (absl::Now() < wait_until &&
         (server.pid() < 0 || ProcessState(server.pid()) != 0 ||
          std::filesystem::exists(server.upload()) ||
          server.log().find("cancelled while its CGNS file") == std::string::npos)) {
    absl::SleepFor(absl::Milliseconds(20));
  }
  server.ExpectCleanedUp();
  EXPECT_THAT(server.log(), HasSubstr("cancelled while its CGNS file was decoded"));
}

TEST(CgnsDecoderTest, ServeRefusesDecoderLimitsOutOfRange) {
  for (const auto& [flag, value] : std::vector<std::pair<std::string, std::string>>{
           {"cgns_decoder_memory_mb", "63"},
           {"cgns_decoder_memory_mb", "-1"},
           {"cgns_decoder_cpu_seconds", "0"},
           {"cgns_decoder_timeout_seconds", "86401"}}) {
    std::string out;
    const int code = testing::RunShell(
        absl::StrCat(kBinary, " serve --address=127.0.0.1:1 --", flag, "=", value), &out);
    EXPECT_EQ(code, 2) << out;
    EXPECT_THAT(out, HasSubstr(absl::StrCat("--", flag, " = ", value, " is outside"))) << out;
  }
}

TEST(CgnsDecoderTest, ADecoderLimitBeyondTheBudgetIsResourceExhaustedNamingTheFlag) {
  TempDir dir("cgns-decoder");
  FakeDecoderServer server(dir, {"--memory_budget_mb=128", "--cgns_decoder_memory_mb=512"});
  ASSERT_TRUE(server.ready()) << server.log();
  server.Mode("garbage");
  absl::StatusOr<v1::Grid> imported = server.Import();
  EXPECT_EQ(imported.status().code(), absl::StatusCode::kResourceExhausted) << imported.status();
  EXPECT_THAT(imported.status().message(),
              HasSubstr("the CGNS decoder's memory limit (serve --cgns_decoder_memory_mb = 512)"));
  EXPECT_EQ(server.pid(), -1);  // never started
}

}  // namespace
}  // namespace splinegrid
