// Issue 12 (5, 6): client strings escaped and cut in logs and errors, the JSON call log,
// requests that do not decode, and why calls ended.
#include <string>
#include <vector>

#include "absl/strings/str_split.h"
#include "core/util/quote.h"
#include "google/protobuf/struct.pb.h"
#include "google/protobuf/util/json_util.h"
#include "grpcpp/generic/generic_stub.h"
#include "server/call_log.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::testing {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// The non-empty lines of `text`.
std::vector<std::string> Lines(const std::string& text) {
  return absl::StrSplit(text, '\n', absl::SkipEmpty());
}

TEST(QuoteClientStringTest, EscapesControlsQuotesAndBackslashes) {
  EXPECT_EQ(QuoteClientString("grids/wing"), "'grids/wing'");
  EXPECT_EQ(QuoteClientString("a\nb\tc\r"), "'a\\nb\\tc\\r'");
  EXPECT_EQ(QuoteClientString("it's \\ \x1b[31m"), "'it\\'s \\\\ \\x1b[31m'");
  EXPECT_EQ(QuoteClientString(std::string("a\0b", 3)), "'a\\x00b'");
  EXPECT_EQ(QuoteClientString("\xc3\xa9"), "'\\xc3\\xa9'");
}

TEST(QuoteClientStringTest, CutsLongStringsAndNotesTheLength) {
  const std::string quoted = QuoteClientString(std::string(1 << 20, 'a'));
  EXPECT_EQ(quoted, "'" + std::string(200, 'a') + "...' (1048576 bytes)");
  // Exactly at the limit: whole. An escape is never cut in half.
  EXPECT_EQ(QuoteClientString(std::string(200, 'b')), "'" + std::string(200, 'b') + "'");
  std::string escaped;
  for (int i = 0; i < 100; ++i) escaped += "\\n";
  EXPECT_EQ(QuoteClientString(std::string(150, '\n')), "'" + escaped + "...' (150 bytes)");
}

TEST(EscapeForLogTest, KeepsQuotesEscapesControlsAndCuts) {
  EXPECT_EQ(EscapeForLog("name = 'x'", 100), "name = 'x'");
  EXPECT_EQ(EscapeForLog("a\nb", 100), "a\\nb");
  EXPECT_EQ(EscapeForLog("abcdef", 3), "abc... (6 bytes)");
}

// The fields of one JSON log line, parsed by protobuf's JSON parser.
google::protobuf::Struct ParseJson(const std::string& line) {
  google::protobuf::Struct parsed;
  const auto status = google::protobuf::util::JsonStringToMessage(line, &parsed);
  EXPECT_TRUE(status.ok()) << status << "\n" << line;
  return parsed;
}

TEST(CallLogTest, TextLineIsOneLineWithTheClientStringsEscaped) {
  server::ServerOptions options;
  server::CallLog log("GetGrid", "grids/naca\n2026-01-01T00:00:00.000Z DeleteGrid grids/naca OK",
                      options);
  log.set_principal("alice");
  const std::string line = log.Line(absl::InvalidArgumentError("bad\nname"), absl::Now());
  ASSERT_EQ(Lines(line).size(), 1u) << line;
  EXPECT_EQ(line.back(), '\n');
  EXPECT_THAT(line, HasSubstr(" GetGrid 'grids/naca\\n2026"));
  EXPECT_THAT(line, HasSubstr(" INVALID_ARGUMENT "));
  EXPECT_THAT(line, HasSubstr(" by alice: bad\\nname\n"));
}

TEST(CallLogTest, JsonLineParsesWithEveryField) {
  server::ServerOptions options;
  options.log_format = server::LogFormat::kJson;
  server::CallLog log("GetGrid", "grids/\"q\"\n\\x", options);
  log.set_principal("bob");
  const std::string line = log.Line(absl::NotFoundError("no grid \"x\""), absl::Now());
  ASSERT_EQ(Lines(line).size(), 1u) << line;
  const google::protobuf::Struct json = ParseJson(line);
  const auto& f = json.fields();
  for (const char* key : {"time", "method", "grid", "principal", "status", "ms", "message"}) {
    EXPECT_TRUE(f.contains(key)) << key << " missing in " << line;
  }
  EXPECT_EQ(f.at("method").string_value(), "GetGrid");
  EXPECT_EQ(f.at("grid").string_value(), "grids/\"q\"\n\\x");
  EXPECT_EQ(f.at("principal").string_value(), "bob");
  EXPECT_EQ(f.at("status").string_value(), "NOT_FOUND");
  EXPECT_EQ(f.at("message").string_value(), "no grid \"x\"");
  EXPECT_GE(f.at("ms").number_value(), 0.0);
}

// A JSON field's value is the string the client got, escaped once: a status message that quotes
// a name (with its C escapes) reads in the log as it read to the client, not with its
// backslashes doubled; UTF-8 is kept, a byte of invalid UTF-8 is U+FFFD, a long message is cut
// at a character.
TEST(CallLogTest, JsonValuesAreTheStringsTheClientGot) {
  server::ServerOptions options;
  options.log_format = server::LogFormat::kJson;
  server::CallLog log("GetGrid", "grids/caf\xc3\xa9\xff", options);
  const std::string message = "grid_id " + QuoteClientString("a\nb") + " is not a valid id";
  const google::protobuf::Struct json =
      ParseJson(log.Line(absl::InvalidArgumentError(message), absl::Now()));
  EXPECT_EQ(json.fields().at("message").string_value(), "grid_id 'a\\nb' is not a valid id");
  EXPECT_EQ(json.fields().at("grid").string_value(), "grids/caf\xc3\xa9\xef\xbf\xbd");
  const std::string long_message = std::string(999, 'x') + "\xc3\xa9" + std::string(100, 'y');
  const google::protobuf::Struct long_json =
      ParseJson(log.Line(absl::InternalError(long_message), absl::Now()));
  EXPECT_EQ(long_json.fields().at("message").string_value(),
            std::string(999, 'x') + "\xc3\xa9... (1101 bytes)");
}

class LogHygieneTest : public ServiceTest {
 protected:
  void SetUp() override {
    options_.log_calls = true;
    ServiceTest::SetUp();
  }

  // The status of `method` called with `messages` as raw bytes (generic stub, any call kind),
  // and the responses read.
  grpc::Status CallWithBytes(const std::string& method, const std::vector<std::string>& messages) {
    grpc::GenericStub stub(server_->InProcessChannel());
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    grpc::CompletionQueue cq;
    auto await = [&cq](void* tag) {
      void* got = nullptr;
      bool ok = false;
      EXPECT_TRUE(cq.Next(&got, &ok));
      EXPECT_EQ(got, tag);
      return ok;
    };
    int tag = 0;
    std::unique_ptr<grpc::GenericClientAsyncReaderWriter> call =
        stub.PrepareCall(&context, "/splinegrid.v1.SplineGrid/" + method, &cq);
    call->StartCall(&tag);
    bool ok = await(&tag);
    for (const std::string& bytes : messages) {
      if (!ok) break;
      grpc::Slice slice(bytes);
      grpc::ByteBuffer buffer(&slice, 1);
      call->Write(buffer, &tag);
      ok = await(&tag);
    }
    if (ok) {
      call->WritesDone(&tag);
      await(&tag);
    }
    for (grpc::ByteBuffer response;;) {
      call->Read(&response, &tag);
      if (!await(&tag)) break;
    }
    grpc::Status status;
    call->Finish(&status, &tag);
    await(&tag);
    return status;
  }
};

// Bytes that are no protobuf message: a field tag with the invalid wire type 7.
const std::string kGarbage = "\x0f\xff\xff\xff";

TEST_F(LogHygieneTest, UndecodableUnaryRequestIsInvalidArgument) {
  ::testing::internal::CaptureStderr();
  const grpc::Status status = CallWithBytes("GetGrid", {kGarbage});
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("does not decode as splinegrid.v1.GetGridRequest"));
  EXPECT_THAT(log, HasSubstr(" GetGrid - INVALID_ARGUMENT "));
  // A request that decodes still reaches its handler.
  v1::GetGridRequest request;
  request.set_name("grids/absent");
  EXPECT_EQ(CallWithBytes("GetGrid", {request.SerializeAsString()}).error_code(),
            grpc::StatusCode::NOT_FOUND);
}

TEST_F(LogHygieneTest, UndecodableServerStreamRequestIsInvalidArgument) {
  for (const char* method : {"EvaluateGrid", "WatchGrid", "ExportGrid"}) {
    const grpc::Status status = CallWithBytes(method, {kGarbage});
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << method;
    EXPECT_THAT(status.error_message(), HasSubstr("does not decode as splinegrid.v1.")) << method;
  }
}

TEST_F(LogHygieneTest, UndecodableClientStreamMessageIsInvalidArgument) {
  v1::ImportGridRequest header;
  header.mutable_header()->set_grid_id("streamed");
  header.mutable_header()->mutable_plot3d()->set_total_bytes(1000);
  const grpc::Status status = CallWithBytes("ImportGrid", {header.SerializeAsString(), kGarbage});
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
  EXPECT_THAT(status.error_message(),
              HasSubstr("does not decode as splinegrid.v1.ImportGridRequest"));
  const grpc::Status archive = CallWithBytes("ImportArchive", {kGarbage});
  EXPECT_EQ(archive.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(archive.error_message(),
              HasSubstr("does not decode as splinegrid.v1.ImportArchiveRequest"));
  // Nothing was stored.
  EXPECT_EQ(client_->Get("streamed").status().code(), absl::StatusCode::kNotFound);
}

TEST_F(LogHygieneTest, NameWithANewlineCannotForgeALogLine) {
  const std::string forged = "grids/naca\n2026-01-01T00:00:00.000Z DeleteGrid grids/naca OK 1.0 ms";
  ::testing::internal::CaptureStderr();
  const absl::Status get = client_->Get(forged).status();
  const absl::Status remove = client_->Delete(forged);
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(get.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(get.message(), HasSubstr("'grids/naca\\n2026-01-01"));
  EXPECT_THAT(get.message(), Not(HasSubstr("\n")));
  EXPECT_EQ(remove.code(), absl::StatusCode::kInvalidArgument);
  const std::vector<std::string> lines = Lines(log);
  ASSERT_EQ(lines.size(), 2u) << log;  // one line per call
  EXPECT_THAT(lines[0], HasSubstr(" GetGrid 'grids/naca\\n2026"));
  EXPECT_THAT(lines[1], HasSubstr(" DeleteGrid 'grids/naca\\n2026"));
  for (const std::string& line : lines) EXPECT_THAT(line, HasSubstr(" INVALID_ARGUMENT "));
}

TEST_F(LogHygieneTest, OneMebibyteNameGivesAShortInvalidArgument) {
  const std::string huge = "grids/" + std::string(1 << 20, 'x');
  ::testing::internal::CaptureStderr();
  const absl::Status get = client_->Get(huge).status();
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(get.code(), absl::StatusCode::kInvalidArgument) << get.message().substr(0, 300);
  EXPECT_LT(get.message().size(), 500u);
  EXPECT_THAT(get.message(), HasSubstr("(1048582 bytes)"));
  const std::vector<std::string> lines = Lines(log);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_LT(lines[0].size(), 1500u);
}

TEST_F(LogHygieneTest, LongPageTokenIsCutInTheMessage) {
  v1::ListGridsRequest request;
  request.set_page_token(std::string(100000, '!') + "\n");
  grpc::ClientContext context;
  v1::ListGridsResponse response;
  const grpc::Status status =
      v1::SplineGrid::NewStub(server_->InProcessChannel())->ListGrids(&context, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_LT(status.error_message().size(), 500u);
  EXPECT_THAT(status.error_message(), HasSubstr("(100001 bytes)"));
}

TEST_F(LogHygieneTest, ClientCancelAndDeadlineAreToldApart) {
  ImportShared("grids/n0012_113-33.p2dfmt", "wing");
  // A watch that the client cancels, then one whose deadline passes.
  auto stub = v1::SplineGrid::NewStub(server_->InProcessChannel());
  ::testing::internal::CaptureStderr();
  {
    grpc::ClientContext context;
    v1::WatchGridRequest request;
    request.set_name("grids/wing");
    request.set_after_revision(-1);
    auto reader = stub->WatchGrid(&context, request);
    reader->WaitForInitialMetadata();
    context.TryCancel();
    v1::WatchGridResponse response;
    while (reader->Read(&response)) {
    }
    EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::CANCELLED);
  }
  {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(300));
    v1::WatchGridRequest request;
    request.set_name("grids/wing");
    request.set_after_revision(-1);
    auto reader = stub->WatchGrid(&context, request);
    v1::WatchGridResponse response;
    while (reader->Read(&response)) {
    }
    EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  }
  // The server logs each call when its reactor finishes, maybe just after the client saw it.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_THAT(log, HasSubstr("WatchGrid grids/wing CANCELLED"));
  EXPECT_THAT(log, HasSubstr("the client cancelled"));
  EXPECT_THAT(log, HasSubstr("WatchGrid grids/wing DEADLINE_EXCEEDED"));
  EXPECT_THAT(log, Not(HasSubstr("went away")));
}

TEST_F(LogHygieneTest, ShutdownEndsCallsAsUnavailable) {
  ImportShared("grids/n0012_113-33.p2dfmt", "wing");
  auto stub = v1::SplineGrid::NewStub(server_->InProcessChannel());
  grpc::ClientContext context;
  v1::WatchGridRequest request;
  request.set_name("grids/wing");
  request.set_after_revision(-1);
  auto reader = stub->WatchGrid(&context, request);
  reader->WaitForInitialMetadata();
  ::testing::internal::CaptureStderr();
  server_->Shutdown();
  v1::WatchGridResponse response;
  while (reader->Read(&response)) {
  }
  const grpc::Status status = reader->Finish();
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAVAILABLE) << status.error_message();
  EXPECT_THAT(log, HasSubstr("WatchGrid grids/wing UNAVAILABLE"));
  EXPECT_THAT(log, HasSubstr("the server is shutting down"));
}

}  // namespace
}  // namespace splinegrid::testing
