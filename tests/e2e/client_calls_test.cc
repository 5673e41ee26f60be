// The C++ client's calls against a fake SplineGrid server on a loopback port: retries of calls
// that broke off (UNAVAILABLE, a balancer's RST_STREAM; unary, streams from their start, within
// the deadline, across a server that starts late), the routing header, and export/import of
// archives (framing, a damaged file cancels the upload, nothing is left of a failed export).
#include <atomic>
#include <chrono>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/synchronization/notification.h"
#include "client/client.h"
#include "core/io/file_util.h"
#include "core/io/record_file.h"
#include "gmock/gmock.h"
#include "grpcpp/grpcpp.h"
#include "gtest/gtest.h"

namespace splinegrid::testing {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

// Fails the first failures[method] calls of a method with UNAVAILABLE, records the routing
// header of every call and keeps what ImportArchive received.
class FakeSplineGrid final : public v1::SplineGrid::Service {
 public:
  std::map<std::string, int> failures;
  std::vector<v1::ArchiveRecord> archive;  // what ExportGrid sends
  // EvaluateGrid of grids/reset: reset (as a balancer does) after the first message, this often.
  std::atomic<int> resets_{2};

  int calls(const std::string& method) {
    std::lock_guard<std::mutex> lock(mu_);
    return static_cast<int>(routing_[method].size());
  }
  std::vector<std::string> routing(const std::string& method) {
    std::lock_guard<std::mutex> lock(mu_);
    return routing_[method];
  }
  // The last ImportArchive: "complete" or "cancelled", the new id, the records.
  std::string import_outcome() {
    std::lock_guard<std::mutex> lock(mu_);
    return import_outcome_;
  }
  std::pair<std::string, std::vector<std::string>> imported() {
    std::lock_guard<std::mutex> lock(mu_);
    return imported_;
  }

  grpc::Status GetGrid(grpc::ServerContext* context, const v1::GetGridRequest* request,
                       v1::Grid* grid) override {
    if (auto failed = Enter("GetGrid", context)) return *failed;
    if (request->name() == "grids/stale") return grpc::Status(grpc::StatusCode::ABORTED, "stale");
    grid->set_name(request->name());
    grid->set_latest_revision(3);
    return grpc::Status::OK;
  }

  grpc::Status ListGrids(grpc::ServerContext* context, const v1::ListGridsRequest*,
                         v1::ListGridsResponse* response) override {
    if (auto failed = Enter("ListGrids", context)) return *failed;
    response->add_grids()->set_name("grids/a");
    return grpc::Status::OK;
  }

  grpc::Status ImportGrid(grpc::ServerContext* context,
                          grpc::ServerReader<v1::ImportGridRequest>* reader,
                          v1::Grid* grid) override {
    if (auto failed = Enter("ImportGrid", context)) return *failed;
    v1::ImportGridRequest request;
    std::string id = "picked";
    while (reader->Read(&request)) {
      if (request.has_header() && !request.header().grid_id().empty()) {
        id = request.header().grid_id();
      }
    }
    grid->set_name("grids/" + id);
    return grpc::Status::OK;
  }

  grpc::Status EvaluateGrid(grpc::ServerContext* context, const v1::EvaluateGridRequest* request,
                            grpc::ServerWriter<v1::EvaluateGridResponse>* writer) override {
    if (auto failed = Enter("EvaluateGrid", context)) return *failed;
    v1::EvaluateGridResponse message;
    v1::EvaluationHeader* header = message.mutable_header();
    header->set_revision(2);
    header->set_spatial_dim(2);
    v1::EvaluatedBlock* block = header->add_blocks();
    // grids/huge: a header announcing 10^12 points (16 TB of values), then nothing.
    const bool huge = request->name() == "grids/huge";
    block->mutable_extents()->set_i(huge ? 1000000 : 2);
    block->mutable_extents()->set_j(huge ? 1000000 : 1);
    block->mutable_extents()->set_k(1);
    header->set_total_points(huge ? 1e12 : 2);
    writer->Write(message);
    if (huge) return grpc::Status::OK;
    if (request->name() == "grids/broken") {
      return grpc::Status(grpc::StatusCode::UNAVAILABLE, "broken off");
    }
    if (request->name() == "grids/reset" && resets_.fetch_sub(1) > 0) {
      return grpc::Status(grpc::StatusCode::INTERNAL, "Received RST_STREAM with error code 2");
    }
    if (request->name() == "grids/bug") {
      return grpc::Status(grpc::StatusCode::INTERNAL, "a server bug");
    }
    message.Clear();
    v1::EvaluationChunk* chunk = message.mutable_chunk();
    chunk->set_field(v1::FIELD_POINTS);
    for (double v : {0.0, 0.0, 1.0, 0.0}) chunk->add_values(v);
    writer->Write(message);
    return grpc::Status::OK;
  }

  grpc::Status WatchGrid(grpc::ServerContext* context, const v1::WatchGridRequest* request,
                         grpc::ServerWriter<v1::WatchGridResponse>* writer) override {
    if (auto failed = Enter("WatchGrid", context)) return *failed;
    if (request->name() == "grids/missing") {
      return grpc::Status(grpc::StatusCode::NOT_FOUND, "grids/missing not found");
    }
    for (int revision : {1, 2}) {
      v1::WatchGridResponse message;
      message.mutable_revision()->set_revision(revision);
      writer->Write(message);
    }
    return grpc::Status::OK;
  }

  grpc::Status ExportGrid(grpc::ServerContext* context, const v1::ExportGridRequest*,
                          grpc::ServerWriter<v1::ExportGridResponse>* writer) override {
    if (auto failed = Enter("ExportGrid", context)) return *failed;
    for (const v1::ArchiveRecord& record : archive) {
      v1::ExportGridResponse message;
      *message.mutable_record() = record;
      writer->Write(message);
    }
    return grpc::Status::OK;
  }

  grpc::Status ImportArchive(grpc::ServerContext* context,
                             grpc::ServerReader<v1::ImportArchiveRequest>* reader,
                             v1::Grid* grid) override {
    if (auto failed = Enter("ImportArchive", context)) return *failed;
    v1::ImportArchiveRequest request;
    std::optional<std::string> id;
    std::vector<std::string> records;
    while (reader->Read(&request)) {
      if (!id) id = request.grid_id();
      records.push_back(request.record().SerializeAsString());
    }
    // A cancellation ends the reads like a half-close: it shows in the context (soon).
    bool cancelled = context->IsCancelled();
    for (int i = 0; i < 20 && !cancelled; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      cancelled = context->IsCancelled();
    }
    std::lock_guard<std::mutex> lock(mu_);
    if (cancelled) {
      import_outcome_ = "cancelled";
      return grpc::Status::CANCELLED;
    }
    import_outcome_ = "complete";
    imported_ = {id.value_or(""), records};
    v1::ArchiveRecord first;
    first.ParseFromString(records.at(0));
    grid->set_name("grids/" + (id->empty() ? first.header().id() : *id));
    return grpc::Status::OK;
  }

 private:
  std::optional<grpc::Status> Enter(const std::string& method, grpc::ServerContext* context) {
    std::lock_guard<std::mutex> lock(mu_);
    const auto& metadata = context->client_metadata();
    const auto it = metadata.find(client::kGridRoutingHeader);
    routing_[method].push_back(
        it == metadata.end() ? "(none)" : std::string(it->second.data(), it->second.size()));
    if (failures[method] > 0) {
      --failures[method];
      return grpc::Status(grpc::StatusCode::UNAVAILABLE, "no upstream");
    }
    return std::nullopt;
  }

  std::mutex mu_;
  std::map<std::string, std::vector<std::string>> routing_;
  std::string import_outcome_;
  std::pair<std::string, std::vector<std::string>> imported_;
};

client::RetryPolicy Fast() {
  client::RetryPolicy retry;
  retry.max_attempts = 4;
  retry.initial_backoff = absl::Milliseconds(10);
  retry.max_backoff = absl::Milliseconds(20);
  return retry;
}

// A fake server on 127.0.0.1:`port` (0: any free port).
std::unique_ptr<grpc::Server> Serve(FakeSplineGrid* service, int* port) {
  grpc::ServerBuilder builder;
  builder.AddListeningPort(absl::StrCat("127.0.0.1:", *port), grpc::InsecureServerCredentials(),
                           port);
  builder.RegisterService(service);
  return builder.BuildAndStart();
}

class ClientCallsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    server_ = Serve(&fake_, &port_);
    ASSERT_NE(server_, nullptr);
    dir_ = std::filesystem::temp_directory_path() /
           absl::StrCat("splinegrid-client-", getpid(), "-",
                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    server_->Shutdown();
    std::filesystem::remove_all(dir_);
  }

  std::unique_ptr<client::Client> Connect(client::RetryPolicy retry = Fast(),
                                          absl::Duration timeout = absl::Seconds(20)) {
    client::ClientOptions options;
    options.retry = retry;
    options.timeout = timeout;
    return client::Client::Connect(absl::StrCat("127.0.0.1:", port_), options);
  }

  FakeSplineGrid fake_;
  int port_ = 0;
  std::unique_ptr<grpc::Server> server_;
  std::filesystem::path dir_;
};

TEST_F(ClientCallsTest, UnaryCallsRetryUnavailableAndNameTheirGrid) {
  fake_.failures["GetGrid"] = 2;
  auto client = Connect();
  const absl::StatusOr<v1::Grid> grid = client->Get("grids/naca");
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_EQ(grid->latest_revision(), 3);
  EXPECT_THAT(fake_.routing("GetGrid"), ElementsAre("naca", "naca", "naca"));
  ASSERT_TRUE(client->List().ok());
  EXPECT_THAT(fake_.routing("ListGrids"), ElementsAre("(none)"));
}

TEST_F(ClientCallsTest, RetriesStopAfterMaxAttemptsWithTheLastError) {
  fake_.failures["GetGrid"] = 10;
  const absl::StatusOr<v1::Grid> grid = Connect()->Get("naca");
  EXPECT_TRUE(absl::IsUnavailable(grid.status())) << grid.status();
  EXPECT_THAT(grid.status().message(),
              HasSubstr("no upstream [attempt 4; each earlier one ended UNAVAILABLE or was "
                        "reset, and was made again]"));
  EXPECT_EQ(fake_.calls("GetGrid"), 4);
}

TEST_F(ClientCallsTest, OtherErrorsAndDisabledRetriesMakeOneAttempt) {
  EXPECT_TRUE(absl::IsAborted(Connect()->Get("stale").status()));
  EXPECT_EQ(fake_.calls("GetGrid"), 1);
  fake_.failures["GetGrid"] = 1;
  client::RetryPolicy off;
  off.max_attempts = 1;
  const absl::Status status = Connect(off)->Get("naca").status();
  EXPECT_TRUE(absl::IsUnavailable(status));
  EXPECT_EQ(status.message(), "no upstream");
  EXPECT_EQ(fake_.calls("GetGrid"), 2);
}

TEST_F(ClientCallsTest, AWaitPastTheDeadlineIsNotTaken) {
  fake_.failures["GetGrid"] = 10;
  client::RetryPolicy slow;
  slow.initial_backoff = slow.max_backoff = absl::Seconds(5);
  const absl::Time start = absl::Now();
  EXPECT_TRUE(absl::IsUnavailable(Connect(slow, absl::Seconds(1))->Get("naca").status()));
  EXPECT_LT(absl::Now() - start, absl::Seconds(1));
  EXPECT_EQ(fake_.calls("GetGrid"), 1);
}

TEST_F(ClientCallsTest, UploadsAreSentAgainWholeAndRouteByTheRequestedId) {
  fake_.failures["ImportGrid"] = 1;
  auto client = Connect();
  const absl::StatusOr<v1::Grid> grid =
      client->ImportPlot3d("1\n2 1\n0 1\n0 0\n", "new", "", false);
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_EQ(grid->name(), "grids/new");
  ASSERT_TRUE(client->ImportPlot3d("1\n2 1\n0 1\n0 0\n", "", "", false).ok());
  EXPECT_THAT(fake_.routing("ImportGrid"), ElementsAre("new", "new", "(none)"));
}

TEST_F(ClientCallsTest, ABrokenStreamIsAskedForAgainFromItsStart) {
  fake_.failures["EvaluateGrid"] = 2;
  auto client = Connect();
  v1::EvaluateGridRequest request;
  request.set_name("naca");
  const absl::StatusOr<client::EvaluatedGrid> grid = client->Evaluate(request);
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_EQ(grid->revision, 2);
  EXPECT_EQ(fake_.calls("EvaluateGrid"), 3);
  // Reset by a balancer after the first message, twice: the third attempt is whole.
  request.set_name("reset");
  const absl::StatusOr<client::EvaluatedGrid> reset = client->Evaluate(request);
  ASSERT_TRUE(reset.ok()) << reset.status();
  EXPECT_EQ(reset->blocks.at(0).points.num_points(), 2);
  EXPECT_EQ(fake_.calls("EvaluateGrid"), 6);
  // Broken off after the first message every time: the retries give up.
  request.set_name("broken");
  const absl::Status broken = client->Evaluate(request).status();
  EXPECT_TRUE(absl::IsUnavailable(broken)) << broken;
  EXPECT_EQ(broken.message(),
            "broken off [attempt 4; each earlier one ended UNAVAILABLE or was reset, and was made "
            "again]");
  // Any other INTERNAL is an answer, not a break.
  request.set_name("bug");
  const absl::Status bug = client->Evaluate(request).status();
  EXPECT_TRUE(absl::IsInternal(bug)) << bug;
  EXPECT_EQ(bug.message(), "a server bug");
  EXPECT_EQ(fake_.calls("EvaluateGrid"), 11);
}

// An evaluation larger than the client may hold is refused at its header, before anything is
// allocated (16 TB here); one within the limit is assembled.
TEST_F(ClientCallsTest, AnEvaluationLargerThanTheClientMayHoldIsRefusedAtItsHeader) {
  client::ClientOptions options;
  options.retry = Fast();
  options.max_evaluation_bytes = int64_t{1} << 30;
  auto client = client::Client::Connect(absl::StrCat("127.0.0.1:", port_), options);
  v1::EvaluateGridRequest request;
  request.set_name("huge");
  const absl::Status huge = client->Evaluate(request).status();
  EXPECT_EQ(huge.code(), absl::StatusCode::kResourceExhausted) << huge;
  EXPECT_THAT(huge.message(), HasSubstr("the evaluation holds 1000000000000 points (14901.16 GiB "
                                        "of values) but this client may hold 1.00 GiB"));
  EXPECT_EQ(fake_.calls("EvaluateGrid"), 1);  // not retried
  request.set_name("naca");
  const absl::StatusOr<client::EvaluatedGrid> small = client->Evaluate(request);
  ASSERT_TRUE(small.ok()) << small.status();
  EXPECT_EQ(small->blocks.at(0).points.num_points(), 2);
}

// The retry is not a resumption: no call ever found the grid, so NOT_FOUND is no deletion.
TEST_F(ClientCallsTest, AWatchOfAnUnknownGridIsNotFoundAlsoAfterARetry) {
  fake_.failures["WatchGrid"] = 1;
  const absl::Status status =
      Connect()->Watch("missing", 0, [](const v1::WatchGridResponse&) { return true; });
  EXPECT_TRUE(absl::IsNotFound(status)) << status;
  EXPECT_EQ(fake_.calls("WatchGrid"), 2);
}

TEST_F(ClientCallsTest, AWatchIsOpenedAgainBeforeItsFirstRevision) {
  fake_.failures["WatchGrid"] = 2;
  std::vector<int64_t> seen;
  const absl::Status status = Connect()->Watch("naca", 0, [&](const v1::WatchGridResponse& m) {
    seen.push_back(m.revision().revision());
    return true;
  });
  EXPECT_TRUE(status.ok()) << status;
  EXPECT_THAT(seen, ElementsAre(1, 2));
  EXPECT_THAT(fake_.routing("WatchGrid"), ElementsAre("naca", "naca", "naca"));
}

TEST_F(ClientCallsTest, ACallReachesAServerThatStartsLate) {
  // The channel's reconnect backoff follows the retry policy: a server that comes up while the
  // call is retrying is reached (gRPC's own first reconnect wait is 1 s).
  int port = 0;
  {
    FakeSplineGrid probe;
    auto reserved = Serve(&probe, &port);  // a free port, released again
    reserved->Shutdown();
  }
  client::ClientOptions options;
  options.retry.max_attempts = 8;
  auto client = client::Client::Connect(absl::StrCat("127.0.0.1:", port), options);
  FakeSplineGrid late;
  std::unique_ptr<grpc::Server> server;
  std::thread starter([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    server = Serve(&late, &port);
  });
  const absl::Time start = absl::Now();
  const absl::StatusOr<std::vector<v1::Grid>> grids = client->List();
  starter.join();
  ASSERT_TRUE(grids.ok()) << grids.status();
  EXPECT_GE(absl::Now() - start, absl::Milliseconds(250));
  ASSERT_NE(server, nullptr);
  server->Shutdown();
}

std::vector<v1::ArchiveRecord> Archive(int chunks, int revisions) {
  std::vector<v1::ArchiveRecord> records(1);
  v1::ArchiveHeader* header = records[0].mutable_header();
  header->set_format_version(1);
  header->set_id("naca");
  header->set_num_source_chunks(chunks);
  header->set_num_revisions(revisions);
  for (int c = 0; c < chunks; ++c) {
    v1::SourceChunk* chunk = records.emplace_back().mutable_source();
    chunk->set_first(1000 * c);
    for (int v = 0; v < 1000; ++v) chunk->add_coords(c);
  }
  for (int r = 0; r < revisions; ++r) records.emplace_back().mutable_revision();
  return records;
}

std::vector<std::string> ReadPayloads(const std::string& path) {
  std::vector<std::string> payloads;
  RecordReader reader = RecordReader::Open(path).value();
  std::string payload;
  while (reader.Next(&payload).value()) payloads.push_back(payload);
  return payloads;
}

TEST_F(ClientCallsTest, ExportWritesTheRecordsFramedAndImportStreamsThemBack) {
  fake_.archive = Archive(2, 1);
  fake_.failures["ExportGrid"] = 1;
  const std::string path = (dir_ / "naca.sgrid").string();
  auto client = Connect();
  const absl::StatusOr<client::ArchiveSummary> summary = client->ExportGrid("naca", path);
  ASSERT_TRUE(summary.ok()) << summary.status();
  EXPECT_EQ(summary->header.id(), "naca");
  EXPECT_EQ(summary->source_chunks, 2);
  EXPECT_EQ(summary->revisions, 1);
  EXPECT_EQ(summary->bytes, static_cast<int64_t>(std::filesystem::file_size(path)));
  std::vector<std::string> expected;
  for (const v1::ArchiveRecord& record : fake_.archive) {
    expected.push_back(record.SerializeAsString());
  }
  EXPECT_EQ(ReadPayloads(path), expected);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir_), {}), 1);  // no temporary

  absl::StatusOr<v1::Grid> grid = client->ImportArchive(path, "");
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_EQ(grid->name(), "grids/naca");
  EXPECT_EQ(fake_.imported(), std::make_pair(std::string(), expected));
  grid = client->ImportArchive(path, "grids/copy");
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_EQ(grid->name(), "grids/copy");
  EXPECT_EQ(fake_.imported(), std::make_pair(std::string("copy"), expected));
  EXPECT_THAT(fake_.routing("ImportArchive"), ElementsAre("naca", "copy"));
  EXPECT_THAT(fake_.routing("ExportGrid"), ElementsAre("naca", "naca"));
}

TEST_F(ClientCallsTest, AnIncompleteExportLeavesTheOldFileAndNoTemporary) {
  fake_.archive = Archive(2, 1);
  fake_.archive.pop_back();  // the header announces a revision that does not come
  const std::string path = (dir_ / "naca.sgrid").string();
  ASSERT_TRUE(WriteFileAtomically(path, "old").ok());
  const absl::Status status = Connect()->ExportGrid("naca", path).status();
  EXPECT_TRUE(absl::IsDataLoss(status)) << status;
  EXPECT_THAT(status.message(), HasSubstr("the export of grids/naca: truncated or incomplete"));
  EXPECT_EQ(ReadFileToString(path).value(), "old");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir_), {}), 1);
  // An unknown grid: nothing at all.
  fake_.failures["ExportGrid"] = 10;
  const std::string other = (dir_ / "other.sgrid").string();
  EXPECT_TRUE(absl::IsUnavailable(Connect()->ExportGrid("naca", other).status()));
  EXPECT_FALSE(std::filesystem::exists(other));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir_), {}), 1);
}

TEST_F(ClientCallsTest, ADamagedArchiveIsRefusedBeforeOrWhileSending) {
  const std::string path = (dir_ / "naca.sgrid").string();
  std::string whole(kRecordFileMagic);
  const std::vector<v1::ArchiveRecord> records = Archive(40, 1);
  int64_t boundary = 0;  // after the header and one chunk
  for (size_t r = 0; r < records.size(); ++r) {
    whole += FrameRecord(records[r].SerializeAsString());
    if (r == 1) boundary = static_cast<int64_t>(whole.size());
  }
  auto client = Connect();
  // Not an archive at all, or not starting with a header: refused before any call.
  ASSERT_TRUE(WriteFileAtomically(path, "1\n2 1\n0 1\n0 0\n").ok());
  absl::Status status = client->ImportArchive(path, "").status();
  EXPECT_TRUE(absl::IsInvalidArgument(status));
  EXPECT_THAT(status.message(), HasSubstr("is not a record file"));
  ASSERT_TRUE(WriteFileAtomically(path, absl::StrCat(std::string(kRecordFileMagic),
                                                     FrameRecord(records[1].SerializeAsString())))
                  .ok());
  status = client->ImportArchive(path, "").status();
  EXPECT_THAT(status.message(), HasSubstr("the first record is not an archive header"));
  EXPECT_EQ(fake_.calls("ImportArchive"), 0);
  // Cut in half: the records before the cut go out, then the call is cancelled.
  ASSERT_TRUE(WriteFileAtomically(path, whole.substr(0, whole.size() / 2)).ok());
  status = client->ImportArchive(path, "").status();
  EXPECT_TRUE(absl::IsInvalidArgument(status)) << status;
  EXPECT_THAT(status.message(), HasSubstr("truncated record"));
  for (int i = 0; i < 50 && fake_.import_outcome().empty(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_NE(fake_.import_outcome(), "complete");  // cancelled (or never started)
  // Cut at a record boundary: complete records, fewer than the header announces.
  ASSERT_TRUE(WriteFileAtomically(path, whole.substr(0, boundary)).ok());
  status = client->ImportArchive(path, "").status();
  EXPECT_TRUE(absl::IsInvalidArgument(status)) << status;
  EXPECT_THAT(status.message(), HasSubstr("truncated or incomplete: the header announces 40 "
                                          "source chunks and 1 revisions, there are 1 and 0"));
  EXPECT_TRUE(fake_.imported().second.empty());
}

}  // namespace
}  // namespace splinegrid::testing
