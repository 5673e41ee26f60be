#include "client/client.h"

#include <cstring>

#include "absl/strings/str_cat.h"
#include "third_party/grpc_health/health.grpc.pb.h"

namespace splinegrid::client {
namespace {

constexpr int64_t kUploadChunkBytes = 1 << 20;

Extents ExtentsOf(const v1::Extents& e) { return {e.i(), e.j(), e.k()}; }

}  // namespace

absl::Status FromGrpc(const grpc::Status& status) {
  if (status.ok()) return absl::OkStatus();
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()), status.error_message());
}

std::string GridName(const std::string& name_or_id) {
  return name_or_id.rfind("grids/", 0) == 0 ? name_or_id : absl::StrCat("grids/", name_or_id);
}

Client::Client(std::shared_ptr<grpc::Channel> channel, ClientOptions options)
    : channel_(std::move(channel)), stub_(v1::SplineGrid::NewStub(channel_)), options_(options) {}

std::unique_ptr<Client> Client::Connect(const std::string& target, ClientOptions options) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(8 << 20);
  return std::make_unique<Client>(
      grpc::CreateCustomChannel(target, grpc::InsecureChannelCredentials(), args), options);
}

std::unique_ptr<grpc::ClientContext> Client::NewContext() const {
  auto context = std::make_unique<grpc::ClientContext>();
  context->set_deadline(std::chrono::system_clock::now() +
                        absl::ToChronoNanoseconds(options_.timeout));
  return context;
}

absl::StatusOr<v1::Grid> Client::ImportPlot3d(const std::string& bytes, const std::string& grid_id,
                                              const std::string& display_name, bool planar_view,
                                              const ProgressFn& progress) {
  auto context = NewContext();
  v1::Grid grid;
  auto writer = stub_->ImportGrid(context.get(), &grid);
  v1::ImportGridRequest request;
  v1::ImportHeader* header = request.mutable_header();
  header->set_grid_id(grid_id);
  header->set_display_name(display_name);
  header->mutable_plot3d()->set_total_bytes(static_cast<int64_t>(bytes.size()));
  header->mutable_plot3d()->set_planar_view(planar_view);
  bool open = writer->Write(request);
  for (int64_t at = 0; open && at < static_cast<int64_t>(bytes.size()); at += kUploadChunkBytes) {
    request.Clear();
    request.set_plot3d_chunk(bytes.substr(at, kUploadChunkBytes));
    open = writer->Write(request);
    if (progress) progress(std::min<int64_t>(at + kUploadChunkBytes, bytes.size()), bytes.size());
  }
  writer->WritesDone();
  const grpc::Status status = writer->Finish();
  if (!status.ok()) return FromGrpc(status);
  return grid;
}

absl::StatusOr<v1::Grid> Client::ImportPoints(const MultiBlockGrid& source,
                                              const std::string& grid_id,
                                              const std::string& display_name,
                                              const ProgressFn& progress) {
  if (source.blocks.empty()) return absl::InvalidArgumentError("the grid has no blocks");
  auto context = NewContext();
  v1::Grid grid;
  auto writer = stub_->ImportGrid(context.get(), &grid);
  v1::ImportGridRequest request;
  v1::ImportHeader* header = request.mutable_header();
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
  bool open = writer->Write(request);
  int64_t done = 0;
  constexpr int64_t kValues = kUploadChunkBytes / sizeof(double);
  for (size_t b = 0; open && b < source.blocks.size(); ++b) {
    const std::span<const double> coords = source.blocks[b].coords();
    for (int64_t at = 0; open && at < static_cast<int64_t>(coords.size()); at += kValues) {
      request.Clear();
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
  const grpc::Status status = writer->Finish();
  if (!status.ok()) return FromGrpc(status);
  return grid;
}

absl::StatusOr<v1::FitGridResponse> Client::Fit(const std::string& name, const v1::FitSpec& spec) {
  v1::FitGridRequest request;
  request.set_name(GridName(name));
  *request.mutable_spec() = spec;
  return Unary(&v1::SplineGrid::Stub::FitGrid, request);
}

absl::StatusOr<v1::FitGridResponse> Client::Fair(const std::string& name, int64_t revision,
                                                 const v1::Fairing* fairing) {
  v1::FairGridRequest request;
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

RevisionStream::RevisionStream(std::unique_ptr<grpc::ClientContext> context,
                               std::unique_ptr<grpc::ClientReader<v1::WatchGridResponse>> reader,
                               std::shared_ptr<WatchCancel> cancel)
    : context_(std::move(context)), reader_(std::move(reader)), cancel_(std::move(cancel)) {
  cancel_->Attach(context_.get());
}

RevisionStream::~RevisionStream() { (void)Finish(); }

bool RevisionStream::Next(v1::WatchGridResponse* message) {
  if (ended_) return false;
  if (reader_->Read(message)) return true;
  ended_ = true;
  return false;
}

absl::Status RevisionStream::Finish() {
  if (status_.has_value()) return *status_;
  if (!ended_) {
    context_->TryCancel();
    v1::WatchGridResponse ignored;
    while (reader_->Read(&ignored)) {
    }
    ended_ = true;
  }
  const grpc::Status status = reader_->Finish();
  cancel_->Attach(nullptr);
  status_ = FromGrpc(status);
  if (status.error_code() == grpc::StatusCode::CANCELLED && cancel_->cancelled()) {
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
  auto context = NewContext();
  auto reader = stub_->EvaluateGrid(context.get(), request);
  v1::EvaluateGridResponse message;
  EvaluatedGrid result;
  std::vector<int> slot;  // block index -> position in result.blocks
  int64_t total_values = 0, received = 0;
  int s = 3;
  while (reader->Read(&message)) {
    if (message.has_header()) {
      const v1::EvaluationHeader& h = message.header();
      result.revision = h.revision();
      s = h.spatial_dim();
      for (const v1::EvaluatedBlock& eb : h.blocks()) {
        if (eb.block() >= static_cast<int>(slot.size())) slot.resize(eb.block() + 1, -1);
        slot[eb.block()] = static_cast<int>(result.blocks.size());
        EvaluatedBlock block{eb.block(), StructuredBlock(ExtentsOf(eb.extents()), s), {}, {}, {}};
        if (h.derivatives()) {
          block.du.resize(block.points.coords().size());
          block.dv.resize(block.points.coords().size());
          block.dw.resize(block.points.coords().size());
        }
        total_values +=
            static_cast<int64_t>(block.points.coords().size()) * (h.derivatives() ? 4 : 1);
        result.blocks.push_back(std::move(block));
      }
      continue;
    }
    const v1::EvaluationChunk& chunk = message.chunk();
    if (chunk.block() < 0 || chunk.block() >= static_cast<int>(slot.size()) ||
        slot[chunk.block()] < 0) {
      context->TryCancel();
      return absl::DataLossError(absl::StrCat("chunk for unannounced block ", chunk.block()));
    }
    EvaluatedBlock& block = result.blocks[slot[chunk.block()]];
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
      context->TryCancel();
      return absl::DataLossError("a chunk does not fit its block");
    }
    if (chunk.values_size() > 0) {
      std::memcpy(target + chunk.offset(), chunk.values().data(), n * sizeof(double));
    } else {
      for (int64_t x = 0; x < n; ++x) target[chunk.offset() + x] = chunk.float_values(x);
    }
    received += n;
    if (progress) progress(received * 8, total_values * 8);
  }
  const grpc::Status status = reader->Finish();
  if (!status.ok()) return FromGrpc(status);
  if (received != total_values) {
    return absl::DataLossError(
        absl::StrCat("received ", received, " of ", total_values, " values"));
  }
  return result;
}

std::unique_ptr<RevisionStream> Client::Watch(const std::string& name, int64_t after_revision,
                                              std::shared_ptr<WatchCancel> cancel) {
  auto context = std::make_unique<grpc::ClientContext>();  // no deadline: a watch lasts
  v1::WatchGridRequest request;
  request.set_name(GridName(name));
  request.set_after_revision(after_revision);
  auto reader = stub_->WatchGrid(context.get(), request);
  if (cancel == nullptr) cancel = std::make_shared<WatchCancel>();
  return std::make_unique<RevisionStream>(std::move(context), std::move(reader), std::move(cancel));
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
  auto context = NewContext();
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(service);
  grpc::health::v1::HealthCheckResponse response;
  const grpc::Status status = stub->Check(context.get(), request, &response);
  if (!status.ok()) return FromGrpc(status);
  return grpc::health::v1::HealthCheckResponse::ServingStatus_Name(response.status());
}

}  // namespace splinegrid::client
