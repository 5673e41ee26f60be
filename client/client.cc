#include "client/client.h"

#include <algorithm>
#include <cstring>
#include <map>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/io/file_util.h"
#include "core/util/status_macros.h"
#include "third_party/grpc_health/health.grpc.pb.h"

namespace splinegrid::client {
namespace {

constexpr int64_t kUploadChunkBytes = 1 << 20;

Extents ExtentsOf(const v1::Extents& e) { return {e.i(), e.j(), e.k()}; }

// Reassembles an EvaluateGrid stream (a header, then chunks of every announced block's fields).
class EvaluationAssembler {
 public:
  EvaluationAssembler(const ProgressFn& progress, int64_t max_bytes)
      : progress_(progress), max_bytes_(max_bytes) {}

  // Takes the next message; DATA_LOSS when it does not fit what the header announced,
  // RESOURCE_EXHAUSTED for a header announcing more than max_bytes (nothing allocated).
  absl::Status Add(const v1::EvaluateGridResponse& message) {
    if (message.has_header()) {
      const v1::EvaluationHeader& h = message.header();
      SG_RETURN_IF_ERROR(CheckSize(h));
      result_.revision = h.revision();
      const int s = h.spatial_dim();
      for (const v1::EvaluatedBlock& eb : h.blocks()) {
        if (eb.block() >= static_cast<int>(slot_.size())) slot_.resize(eb.block() + 1, -1);
        slot_[eb.block()] = static_cast<int>(result_.blocks.size());
        EvaluatedBlock block{eb.block(), StructuredBlock(ExtentsOf(eb.extents()), s), {}, {}, {}};
        if (h.derivatives()) {
          block.du.resize(block.points.coords().size());
          block.dv.resize(block.points.coords().size());
          block.dw.resize(block.points.coords().size());
        }
        total_values_ +=
            static_cast<int64_t>(block.points.coords().size()) * (h.derivatives() ? 4 : 1);
        result_.blocks.push_back(std::move(block));
      }
      return absl::OkStatus();
    }
    const v1::EvaluationChunk& chunk = message.chunk();
    if (chunk.block() < 0 || chunk.block() >= static_cast<int>(slot_.size()) ||
        slot_[chunk.block()] < 0) {
      return absl::DataLossError(absl::StrCat("chunk for unannounced block ", chunk.block()));
    }
    EvaluatedBlock& block = result_.blocks[slot_[chunk.block()]];
    double* target = nullptr;
    switch (chunk.field()) {
      case v1::FIELD_POINTS:
        target = block.points.coords().data();
        break;
      case v1::FIELD_DU:
        target = block.du.data();
        break;
      case v1::FIELD_DV:
        target = block.dv.data();
        break;
      case v1::FIELD_DW:
        target = block.dw.data();
        break;
      default:
        break;
    }
    const int64_t n = chunk.values_size() + chunk.float_values_size();
    if (!target || chunk.offset() < 0 ||
        chunk.offset() + n > static_cast<int64_t>(block.points.coords().size())) {
      return absl::DataLossError("a chunk does not fit its block");
    }
    if (chunk.values_size() > 0) {
      std::memcpy(target + chunk.offset(), chunk.values().data(), n * sizeof(double));
    } else {
      // One widening copy of the packed floats (vectorised), not an accessor call per value.
      const float* floats = chunk.float_values().data();
      std::copy(floats, floats + n, target + chunk.offset());
    }
    received_ += n;
    if (progress_) progress_(received_ * 8, total_values_ * 8);
    return absl::OkStatus();
  }

  // RESOURCE_EXHAUSTED when the announced blocks would take more than max_bytes_ here.
  absl::Status CheckSize(const v1::EvaluationHeader& h) const {
    if (max_bytes_ <= 0) return absl::OkStatus();
    double values = 0;  // in double: hostile extents must not overflow the sum
    for (const v1::EvaluatedBlock& eb : h.blocks()) {
      values += std::max<double>(eb.extents().i(), 1) * std::max<double>(eb.extents().j(), 1) *
                std::max<double>(eb.extents().k(), 1) * std::max(h.spatial_dim(), 1) *
                (h.derivatives() ? 4 : 1);
    }
    const double bytes = values * sizeof(double);
    if (bytes <= static_cast<double>(max_bytes_)) return absl::OkStatus();
    constexpr double kGiB = double(int64_t{1} << 30);
    return absl::ResourceExhaustedError(absl::StrFormat(
        "the evaluation holds %.0f points (%.2f GiB of values) but this client may hold %.2f GiB "
        "(ClientOptions::max_evaluation_bytes; the CLI: three quarters of the memory available "
        "to it, divided by the copies of the values its output format holds while writing): "
        "ask for fewer points (--res, --box, a lower --level, or --block)",
        h.total_points(), bytes / kGiB, max_bytes_ / kGiB));
  }

  // The evaluation once the stream has ended OK; DATA_LOSS when values are missing.
  absl::StatusOr<EvaluatedGrid> Finish() && {
    if (received_ != total_values_) {
      return absl::DataLossError(
          absl::StrCat("received ", received_, " of ", total_values_, " values"));
    }
    return std::move(result_);
  }

 private:
  const ProgressFn& progress_;
  const int64_t max_bytes_;
  EvaluatedGrid result_;
  std::vector<int> slot_;  // block index -> position in result_.blocks
  int64_t total_values_ = 0, received_ = 0;
};

}  // namespace

bool BrokeOff(const grpc::Status& status) {
  return status.error_code() == grpc::StatusCode::UNAVAILABLE ||
         (status.error_code() == grpc::StatusCode::INTERNAL &&
          absl::StrContains(status.error_message(), "RST_STREAM"));
}

absl::Status FromGrpc(const grpc::Status& status) {
  if (status.ok()) return absl::OkStatus();
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()), status.error_message());
}

bool PauseBeforeRetry(grpc::Channel& channel, absl::Duration wait,
                      const std::function<bool()>& stop) {
  const absl::Time until = absl::Now() + wait;
  for (absl::Time now = absl::Now(); now < until; now = absl::Now()) {
    if (stop && stop()) return true;
    const absl::Time slice = std::min(until, now + absl::Milliseconds(100));
    const grpc_connectivity_state state = channel.GetState(/*try_to_connect=*/true);
    if (state == GRPC_CHANNEL_READY) {
      absl::SleepFor(slice - now);
    } else {
      channel.WaitForStateChange(state, absl::ToChronoTime(slice));
    }
  }
  return stop && stop();
}

std::string GridName(const std::string& name_or_id) {
  return name_or_id.rfind("grids/", 0) == 0 ? name_or_id : absl::StrCat("grids/", name_or_id);
}

std::string GridId(const std::string& name_or_id) {
  return name_or_id.rfind("grids/", 0) == 0 ? name_or_id.substr(6) : name_or_id;
}

Client::Client(std::shared_ptr<grpc::Channel> channel, ClientOptions options)
    : channel_(std::move(channel)), stub_(v1::SplineGrid::NewStub(channel_)), options_(options) {}

std::unique_ptr<Client> Client::Connect(const std::string& target, ClientOptions options) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(8 << 20);
  if (options.retry.max_attempts > 1) {
    // gRPC's own reconnect backoff starts at 1 s: a restarted server would be reached only
    // after the retries are spent. Reconnect at the pace of the retry policy instead.
    const auto ms = [](absl::Duration d) {
      return static_cast<int>(std::clamp<int64_t>(absl::ToInt64Milliseconds(d), 1, 1 << 30));
    };
    args.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, ms(options.retry.initial_backoff));
    args.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, ms(options.retry.max_backoff));
  }
  std::shared_ptr<grpc::ChannelCredentials> credentials = grpc::InsecureChannelCredentials();
  if (options.use_tls) {
    grpc::SslCredentialsOptions ssl;
    ssl.pem_root_certs = options.tls_root_certs;
    ssl.pem_cert_chain = options.tls_cert_chain;
    ssl.pem_private_key = options.tls_private_key;
    credentials = grpc::SslCredentials(ssl);
    if (!options.tls_server_name.empty()) {
      args.SetSslTargetNameOverride(options.tls_server_name);
    }
  }
  return std::make_unique<Client>(grpc::CreateCustomChannel(target, credentials, args), options);
}

absl::Status LoadTlsFiles(const std::string& ca_file, const std::string& cert_file,
                          const std::string& key_file, ClientOptions* options) {
  if (cert_file.empty() != key_file.empty()) {
    return absl::InvalidArgumentError(
        "a client certificate needs both --tls_cert and --tls_key (or neither)");
  }
  const auto read = [](const std::string& path, const char* flag,
                       std::string* pem) -> absl::Status {
    if (path.empty()) return absl::OkStatus();
    SG_ASSIGN_OR_RETURN(*pem, ReadFileToString(path), "--", flag, ": ");
    return absl::OkStatus();
  };
  SG_RETURN_IF_ERROR(read(ca_file, "tls_ca", &options->tls_root_certs));
  SG_RETURN_IF_ERROR(read(cert_file, "tls_cert", &options->tls_cert_chain));
  SG_RETURN_IF_ERROR(read(key_file, "tls_key", &options->tls_private_key));
  if (!ca_file.empty() || !cert_file.empty()) options->use_tls = true;
  return absl::OkStatus();
}

std::unique_ptr<grpc::ClientContext> Client::NewContext(absl::Time deadline,
                                                        const std::string& grid,
                                                        const std::string& token) {
  auto context = std::make_unique<grpc::ClientContext>();
  if (deadline != absl::InfiniteFuture()) context->set_deadline(absl::ToChronoTime(deadline));
  // Only what can be a grid id (1-63 characters; 128 leaves room for "grids/"): a long or
  // binary name goes without the routing header, so that the server, not the metadata limit,
  // answers it (INVALID_ARGUMENT naming the field).
  if (!grid.empty() && grid.size() <= 128 &&
      std::all_of(grid.begin(), grid.end(), [](char c) { return c >= 0x20 && c < 0x7F; })) {
    context->AddMetadata(kGridRoutingHeader, grid);
  }
  if (!token.empty() &&
      std::all_of(token.begin(), token.end(), [](char c) { return c > 0x20 && c < 0x7F; })) {
    context->AddMetadata("authorization", absl::StrCat("Bearer ", token));
  }
  return context;
}

absl::Status Client::Call(const std::string& grid, const Attempt& attempt) const {
  const absl::Time deadline = absl::Now() + options_.timeout;
  Backoff backoff(options_.retry);
  for (int attempts = 1;; ++attempts) {
    auto context = NewContext(deadline, grid, options_.token);
    const grpc::Status status = attempt(context.get());
    std::optional<absl::Duration> wait;
    if (BrokeOff(status)) wait = backoff.Next(deadline);
    if (!wait) {
      absl::Status result = FromGrpc(status);
      if (!result.ok() && attempts > 1) {
        result = absl::Status(
            result.code(),
            absl::StrCat(result.message(), " [attempt ", attempts,
                         "; each earlier one ended UNAVAILABLE or was reset, and was made again]"));
      }
      // gRPC's own words when the client's deadline fires first; the server's say more.
      if (result.code() == absl::StatusCode::kDeadlineExceeded &&
          result.message() == "Deadline Exceeded") {
        result = absl::Status(
            result.code(),
            absl::StrCat(
                "the call's deadline passed before its answer came (the client's timeout, ",
                absl::FormatDuration(options_.timeout),
                ": ClientOptions.timeout, CLI --timeout, C timeout_seconds)"));
      }
      // A TLS server closes a plaintext connection at once, and a server that asks for client
      // certificates a TLS connection without one; a plaintext server answers a TLS handshake
      // with bytes that are no TLS record (OpenSSL: "wrong version number"). Say what that
      // usually means.
      if (options_.use_tls && absl::IsUnavailable(result) &&
          absl::StrContains(result.message(), "wrong version number")) {
        result = absl::Status(
            result.code(),
            absl::StrCat(result.message(),
                         " (the server answered the TLS handshake in plaintext: it does not use "
                         "TLS; connect without --tls_ca, ClientOptions.use_tls = false)"));
      }
      if (absl::IsUnavailable(result) && absl::StrContains(result.message(), "Socket closed")) {
        const char* hint =
            !options_.use_tls
                ? "if it uses TLS, give its CA: --tls_ca, ClientOptions.tls_root_certs"
            : options_.tls_cert_chain.empty()
                ? "if it asks for client certificates (mTLS), give yours: --tls_cert and "
                  "--tls_key, ClientOptions.tls_cert_chain and tls_private_key"
                : nullptr;
        if (hint != nullptr) {
          result = absl::Status(
              result.code(),
              absl::StrCat(result.message(), " (the server closed the connection: ", hint, ")"));
        }
      }
      return result;
    }
    PauseBeforeRetry(*channel_, *wait);
  }
}

absl::StatusOr<v1::Grid> Client::ImportPlot3d(const std::string& bytes, const std::string& grid_id,
                                              const std::string& display_name, bool planar_view,
                                              const ProgressFn& progress) {
  v1::Plot3dSource options;
  options.set_planar_view(planar_view);
  return ImportPlot3d(bytes, grid_id, display_name, options, progress);
}

absl::StatusOr<v1::Grid> Client::ImportPlot3d(const std::string& bytes, const std::string& grid_id,
                                              const std::string& display_name,
                                              const v1::Plot3dSource& options,
                                              const ProgressFn& progress) {
  v1::ImportHeader header;
  header.set_grid_id(grid_id);
  header.set_display_name(display_name);
  *header.mutable_plot3d() = options;
  header.mutable_plot3d()->set_total_bytes(static_cast<int64_t>(bytes.size()));
  return UploadFile(
      header, bytes,
      [](v1::ImportGridRequest& request, std::string chunk) {
        request.set_plot3d_chunk(std::move(chunk));
      },
      progress);
}

absl::StatusOr<v1::Grid> Client::ImportCgns(const std::string& bytes, const std::string& grid_id,
                                            const std::string& display_name,
                                            const ProgressFn& progress) {
  v1::ImportHeader header;
  header.set_grid_id(grid_id);
  header.set_display_name(display_name);
  header.mutable_cgns()->set_total_bytes(static_cast<int64_t>(bytes.size()));
  return UploadFile(
      header, bytes,
      [](v1::ImportGridRequest& request, std::string chunk) {
        request.set_cgns_chunk(std::move(chunk));
      },
      progress);
}

absl::StatusOr<v1::Grid> Client::UploadFile(const v1::ImportHeader& header,
                                            const std::string& bytes, const ChunkSetter& set_chunk,
                                            const ProgressFn& progress) {
  v1::ImportGridRequest head;
  *head.mutable_header() = header;
  const int64_t size = static_cast<int64_t>(bytes.size());
  v1::Grid grid;
  SG_RETURN_IF_ERROR(Call(GridId(header.grid_id()), [&](grpc::ClientContext* context) {
    auto writer = stub_->ImportGrid(context, &grid);
    bool open = writer->Write(head);
    v1::ImportGridRequest request;
    for (int64_t at = 0; open && at < size; at += kUploadChunkBytes) {
      set_chunk(request, bytes.substr(at, kUploadChunkBytes));
      open = writer->Write(request);
      if (progress) progress(std::min<int64_t>(at + kUploadChunkBytes, size), size);
    }
    writer->WritesDone();
    return writer->Finish();
  }));
  return grid;
}

absl::StatusOr<v1::Grid> Client::ImportPoints(const MultiBlockGrid& source,
                                              const std::string& grid_id,
                                              const std::string& display_name,
                                              const ProgressFn& progress) {
  if (source.blocks.empty()) return absl::InvalidArgumentError("the grid has no blocks");
  v1::ImportGridRequest head;
  v1::ImportHeader* header = head.mutable_header();
  header->set_grid_id(grid_id);
  header->set_display_name(display_name);
  header->mutable_points()->set_spatial_dim(source.blocks.front().spatial_dim());
  int64_t total = 0;
  for (const StructuredBlock& block : source.blocks) {
    v1::Extents* e = header->mutable_points()->add_blocks();
    e->set_i(block.extent(0));
    e->set_j(block.extent(1));
    e->set_k(block.extent(2));
    total += static_cast<int64_t>(block.coords().size() * sizeof(double));
  }
  v1::Grid grid;
  SG_RETURN_IF_ERROR(Call(GridId(grid_id), [&](grpc::ClientContext* context) {
    auto writer = stub_->ImportGrid(context, &grid);
    bool open = writer->Write(head);
    int64_t done = 0;
    constexpr int64_t kValues = kUploadChunkBytes / sizeof(double);
    v1::ImportGridRequest request;
    for (size_t b = 0; open && b < source.blocks.size(); ++b) {
      const std::span<const double> coords = source.blocks[b].coords();
      for (int64_t at = 0; open && at < static_cast<int64_t>(coords.size()); at += kValues) {
        v1::PointChunk* chunk = request.mutable_points();
        chunk->set_block(static_cast<int>(b));
        const int64_t n = std::min<int64_t>(kValues, coords.size() - at);
        chunk->mutable_coordinates()->Assign(coords.begin() + at, coords.begin() + at + n);
        open = writer->Write(request);
        done += n * static_cast<int64_t>(sizeof(double));
        if (progress) progress(done, total);
      }
    }
    writer->WritesDone();
    return writer->Finish();
  }));
  return grid;
}

absl::StatusOr<v1::FitGridResponse> Client::Fit(const std::string& name, const v1::FitSpec& spec) {
  v1::FitGridRequest request;
  request.set_name(GridName(name));
  *request.mutable_spec() = spec;
  return Unary(&v1::SplineGrid::Stub::FitGrid, request);
}

absl::StatusOr<v1::FitGridResponse> Client::Fair(const std::string& name, int64_t revision,
                                                 const v1::Fairing* fairing, bool allow_folds) {
  v1::FairGridRequest request;
  request.set_allow_folds(allow_folds);
  request.set_name(GridName(name));
  request.set_revision(revision);
  if (fairing != nullptr) *request.mutable_fairing() = *fairing;
  return Unary(&v1::SplineGrid::Stub::FairGrid, request);
}

absl::StatusOr<v1::DeformGridResponse> Client::Deform(v1::DeformGridRequest request) {
  request.set_name(GridName(request.name()));
  return Unary(&v1::SplineGrid::Stub::DeformGrid, request);
}

absl::StatusOr<v1::GenerateGridResponse> Client::Generate(const v1::GenerateGridRequest& request) {
  return Unary(&v1::SplineGrid::Stub::GenerateGrid, request);
}

void WatchCancel::Cancel() {
  std::lock_guard<std::mutex> lock(mu_);
  cancelled_ = true;
  if (context_ != nullptr) context_->TryCancel();
}

bool WatchCancel::cancelled() const {
  std::lock_guard<std::mutex> lock(mu_);
  return cancelled_;
}

void WatchCancel::Attach(grpc::ClientContext* context) {
  std::lock_guard<std::mutex> lock(mu_);
  context_ = context;
  if (context_ != nullptr && cancelled_) context_->TryCancel();
}

RevisionStream::RevisionStream(std::function<Call(int64_t)> open, int64_t after_revision,
                               const RetryPolicy& retry, std::shared_ptr<grpc::Channel> channel,
                               std::shared_ptr<WatchCancel> cancel)
    : open_(std::move(open)),
      retry_(retry),
      backoff_(retry),
      channel_(std::move(channel)),
      cancel_(std::move(cancel)),
      after_(after_revision) {
  Open();
}

RevisionStream::~RevisionStream() { (void)Finish(); }

void RevisionStream::Open() {
  cancel_->Attach(nullptr);  // before the previous attempt's context goes
  call_ = open_(after_);
  cancel_->Attach(call_.context.get());
}

bool RevisionStream::SameCreation() {
  const std::multimap<grpc::string_ref, grpc::string_ref>& metadata =
      call_.context->GetServerInitialMetadata();
  const auto value = [&](const char* key) -> std::optional<std::string> {
    const auto it = metadata.find(key);
    if (it == metadata.end()) return std::nullopt;
    return std::string(it->second.data(), it->second.size());
  };
  if (after_ == -1) {
    int64_t begins_after = 0;
    if (const std::optional<std::string> after = value(kWatchAfterHeader);
        after.has_value() && absl::SimpleAtoi(*after, &begins_after) && begins_after >= 0) {
      after_ = begins_after;
    }
  }
  const std::optional<std::string> incarnation = value(kIncarnationHeader);
  if (!incarnation.has_value() || incarnation->empty()) return true;
  if (incarnation_.empty()) incarnation_ = *incarnation;
  return *incarnation == incarnation_;
}

bool RevisionStream::Resume() {
  if (cancel_->cancelled() || !BrokeOff(*finished_)) return false;
  // A call that was up (its initial metadata arrived) gets the retries afresh.
  if (!call_.context->GetServerInitialMetadata().empty()) backoff_ = Backoff(retry_);
  const std::optional<absl::Duration> wait = backoff_.Next(absl::InfiniteFuture());
  if (!wait) return false;
  if (PauseBeforeRetry(*channel_, *wait, [&] { return cancel_->cancelled(); })) {
    finished_ = grpc::Status(grpc::StatusCode::CANCELLED, "cancelled");
    return false;
  }
  finished_.reset();
  ended_ = false;
  Open();
  return true;
}

bool RevisionStream::Next(v1::WatchGridResponse* message) {
  while (!ended_) {
    const bool read = call_.reader->Read(message);
    ended_ = !read;
    if (!SameCreation()) {
      // The watched grid was deleted while the call was resumed, and the id created again.
      if (read) {
        call_.context->TryCancel();
        v1::WatchGridResponse ignored;
        while (call_.reader->Read(&ignored)) {
        }
        ended_ = true;
      }
      (void)call_.reader->Finish();
      finished_ = grpc::Status::OK;
      return false;
    }
    if (read) {
      after_ = message->revision().revision();
      return true;
    }
    finished_ = call_.reader->Finish();
    // A call that finds no grid which an earlier call did find (only a resumed call can: the
    // server ends a found grid's watch OK): it was deleted meanwhile, which ends the watch.
    if (!incarnation_.empty() && finished_->error_code() == grpc::StatusCode::NOT_FOUND) {
      finished_ = grpc::Status::OK;
      return false;
    }
    if (!Resume()) break;
  }
  return false;
}

absl::Status RevisionStream::Finish() {
  if (status_.has_value()) return *status_;
  if (!ended_) {
    call_.context->TryCancel();
    v1::WatchGridResponse ignored;
    while (call_.reader->Read(&ignored)) {
    }
    ended_ = true;
  }
  if (!finished_) finished_ = call_.reader->Finish();
  cancel_->Attach(nullptr);
  status_ = FromGrpc(*finished_);
  if (finished_->error_code() == grpc::StatusCode::CANCELLED && cancel_->cancelled()) {
    status_ = absl::CancelledError("the watch was cancelled");
  }
  return *status_;
}

absl::StatusOr<v1::GetWallCurvatureResponse> Client::WallCurvature(const std::string& name,
                                                                   int64_t revision,
                                                                   int refinement_level,
                                                                   const std::vector<int>& blocks) {
  v1::GetWallCurvatureRequest request;
  request.set_name(GridName(name));
  request.set_revision(revision);
  request.set_refinement_level(refinement_level);
  for (int b : blocks) request.add_blocks(b);
  return Unary(&v1::SplineGrid::Stub::GetWallCurvature, request);
}

absl::StatusOr<v1::Grid> Client::Get(const std::string& name, int64_t revision, v1::GridView view,
                                     const std::vector<int>& blocks) {
  v1::GetGridRequest request;
  request.set_name(GridName(name));
  request.set_revision(revision);
  request.set_view(view);
  for (int b : blocks) request.add_blocks(b);
  return Unary(&v1::SplineGrid::Stub::GetGrid, request);
}

absl::StatusOr<v1::Grid> Client::Get(v1::GetGridRequest request) {
  request.set_name(GridName(request.name()));
  return Unary(&v1::SplineGrid::Stub::GetGrid, request);
}

absl::StatusOr<std::vector<v1::Grid>> Client::List() {
  std::vector<v1::Grid> grids;
  v1::ListGridsRequest request;
  request.set_page_size(500);
  for (;;) {
    absl::StatusOr<v1::ListGridsResponse> page = Unary(&v1::SplineGrid::Stub::ListGrids, request);
    if (!page.ok()) return page.status();
    for (v1::Grid& grid : *page->mutable_grids()) grids.push_back(std::move(grid));
    if (page->next_page_token().empty()) return grids;
    request.set_page_token(page->next_page_token());
  }
}

absl::Status Client::Delete(const std::string& name) {
  v1::DeleteGridRequest request;
  request.set_name(GridName(name));
  return Unary(&v1::SplineGrid::Stub::DeleteGrid, request).status();
}

absl::StatusOr<EvaluatedGrid> Client::Evaluate(v1::EvaluateGridRequest request,
                                               const ProgressFn& progress) {
  request.set_name(GridName(request.name()));
  std::optional<EvaluationAssembler> assembler;
  absl::Status malformed;  // the stream did not fit together (the call was cancelled)
  const absl::Status status = Call(GridId(request.name()), [&](grpc::ClientContext* context) {
    assembler.emplace(progress, options_.max_evaluation_bytes);
    malformed = absl::OkStatus();
    auto reader = stub_->EvaluateGrid(context, request);
    v1::EvaluateGridResponse message;
    while (malformed.ok() && reader->Read(&message)) {
      malformed = assembler->Add(message);
      if (!malformed.ok()) context->TryCancel();
    }
    return reader->Finish();
  });
  SG_RETURN_IF_ERROR(malformed);
  SG_RETURN_IF_ERROR(status);
  return std::move(*assembler).Finish();
}

std::unique_ptr<RevisionStream> Client::Watch(const std::string& name, int64_t after_revision,
                                              std::shared_ptr<WatchCancel> cancel) {
  v1::WatchGridRequest request;
  request.set_name(GridName(name));
  request.set_after_revision(after_revision);
  if (cancel == nullptr) cancel = std::make_shared<WatchCancel>();
  // The stream may outlive this client: it keeps a stub of its own (sharing the channel).
  std::shared_ptr<v1::SplineGrid::Stub> stub = v1::SplineGrid::NewStub(channel_);
  auto open = [stub, request, token = options_.token](int64_t after) {
    RevisionStream::Call call;
    // No deadline: a watch lasts.
    call.context = NewContext(absl::InfiniteFuture(), GridId(request.name()), token);
    v1::WatchGridRequest resumed = request;
    resumed.set_after_revision(after);
    call.reader = stub->WatchGrid(call.context.get(), resumed);
    return call;
  };
  return std::make_unique<RevisionStream>(open, after_revision,
                                          options_.watch_retry.value_or(options_.retry), channel_,
                                          std::move(cancel));
}

absl::Status Client::Watch(const std::string& name, int64_t after_revision,
                           const std::function<bool(const v1::WatchGridResponse&)>& on_revision,
                           std::shared_ptr<WatchCancel> cancel) {
  std::unique_ptr<RevisionStream> stream = Watch(name, after_revision, std::move(cancel));
  v1::WatchGridResponse message;
  bool stopped = false;
  while (stream->Next(&message)) {
    if (!on_revision(message)) {
      stopped = true;
      stream->Cancel();
      break;
    }
  }
  const absl::Status status = stream->Finish();
  if (status.ok() || ((stopped || stream->cancel()->cancelled()) && absl::IsCancelled(status))) {
    return absl::OkStatus();
  }
  return status;
}

absl::StatusOr<v1::EvaluatePointsResponse> Client::EvaluatePoints(
    v1::EvaluatePointsRequest request) {
  request.set_name(GridName(request.name()));
  return Unary(&v1::SplineGrid::Stub::EvaluatePoints, request);
}

absl::StatusOr<std::string> Client::Health(const std::string& service) {
  auto stub = grpc::health::v1::Health::NewStub(channel_);
  // Not retried: a probe answers for now.
  auto context = NewContext(absl::Now() + options_.timeout, "", options_.token);
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(service);
  grpc::health::v1::HealthCheckResponse response;
  const grpc::Status status = stub->Check(context.get(), request, &response);
  if (!status.ok()) return FromGrpc(status);
  return grpc::health::v1::HealthCheckResponse::ServingStatus_Name(response.status());
}

}  // namespace splinegrid::client
