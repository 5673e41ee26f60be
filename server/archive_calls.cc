// ExportGrid and ImportArchive: a grid with its source points and revisions as archive records
// (store/grid_archive.h), so a user can move grids between servers and keep them with a case.
#include <deque>
#include <optional>

#include "absl/cleanup/cleanup.h"
#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"
#include "server/grid_encoding.h"
#include "server/happens_before.h"
#include "server/ops/archive.h"
#include "server/service.h"
#include "server/store/grid_archive.h"
#include "server/upload_reactor.h"

namespace splinegrid::server {
namespace {

// Streams the records of one snapshot (ops::ExportSnapshot). They are built on the pool before
// the first write, charged to the budget, and written one at a time as the client takes them.
class ExportReactor : public grpc::ServerWriteReactor<v1::ExportGridResponse> {
 public:
  ExportReactor(ServiceState* state, grpc::CallbackServerContext* context,
                const v1::ExportGridRequest* request)
      : state_(state),
        context_(context),
        request_(request),
        log_("ExportGrid", request->name(), state->options) {
    absl::StatusOr<AdmittedStream> admitted = AdmitStream(*state_, context, Role::kRead, &log_);
    if (!admitted.ok()) {
      End(admitted.status());
      return;
    }
    caller_ = std::move(admitted->caller);
    stream_ = std::move(admitted->slot);
    if (absl::Status status =
            state_->pool.TrySubmit(caller_.principal, WorkKind::kLong, [this] { Prepare(); });
        !status.ok()) {
      End(status);
    }
  }

  void OnWriteDone(bool ok) override {
    SG_HAPPENS_AFTER(this);
    if (!ok) {
      End(WhyCallEnded(*state_, context_));
      return;
    }
    records_.pop_front();
    WriteNext();
  }

  void OnDone() override {
    SG_HAPPENS_AFTER(this);
    delete this;
  }

 private:
  void Prepare() {
    SG_HAPPENS_AFTER(this);
    const absl::Status status = [&]() -> absl::Status {
      SG_ASSIGN_OR_RETURN(const std::string id, ParseGridName(request_->name(), "name"));
      SG_ASSIGN_OR_RETURN(
          memory_,
          ops::ExportSnapshot(
              state_->Ops(), id, [&](const StoredGrid& grid) -> absl::StatusOr<int64_t> {
                int64_t bytes = 0;
                SG_RETURN_IF_ERROR(ForEachRecord(grid, [&](const v1::ArchiveRecord& record) {
                  records_.emplace_back();
                  *records_.back().mutable_record() = record;
                  bytes += static_cast<int64_t>(record.ByteSizeLong());
                  return absl::OkStatus();
                }));
                return bytes;
              }));
      return absl::OkStatus();
    }();
    if (!status.ok()) {
      End(status);
      return;
    }
    WriteNext();
  }

  void WriteNext() {
    if (records_.empty()) {
      stream_.Release();  // the call is over for its principal once its status goes out
      log_.Finish(absl::OkStatus());
      SG_HAPPENS_BEFORE(this);
      Finish(grpc::Status::OK);
      return;
    }
    SG_HAPPENS_BEFORE(this);
    StartWrite(&records_.front());
  }

  void End(const absl::Status& status) {
    stream_.Release();  // the call is over for its principal once its status goes out
    log_.Finish(status);
    SG_HAPPENS_BEFORE(this);
    Finish(ToGrpcStatus(status));
  }

  ServiceState* state_;
  grpc::CallbackServerContext* context_;
  const v1::ExportGridRequest* request_;
  CallLog log_;
  Caller caller_;
  // This call's place among its principal's open streams.
  StreamSlot stream_;
  MemoryReservation memory_;
  std::deque<v1::ExportGridResponse> records_;
};

// Assembles the records as they arrive (memory charged as data comes, not as the header
// announces), then stores the grid on the pool (ops::StoreArchived): nothing is stored unless
// the whole archive arrived and checks out.
class ImportArchiveReactor : public UploadReactor<v1::ImportArchiveRequest> {
 public:
  ImportArchiveReactor(ServiceState* state, grpc::CallbackServerContext* context,
                       v1::Grid* response)
      : UploadReactor(state, context, "ImportArchive"), response_(response) {
    Start();
  }

 private:
  absl::Status Accept(const v1::ImportArchiveRequest& message) override {
    if (!assembler_) {
      const std::string& id = message.grid_id();
      SG_RETURN_IF_ERROR(CheckRequestedGridId(id, "grid_id"));
      assembler_.emplace(&state_->budget, id);
    } else if (!message.grid_id().empty()) {
      return absl::InvalidArgumentError("grid_id is set after the first message");
    }
    SG_RETURN_IF_ERROR(assembler_->Add(message.record()), "record ", records_, ": ");
    ++records_;
    return absl::OkStatus();
  }

  absl::Status Complete() override {
    if (!assembler_) return absl::InvalidArgumentError("the archive is empty: no records came");
    // The assembled records are released before the call ends, stored or not.
    absl::Cleanup release = [this] { assembler_.reset(); };
    SG_ASSIGN_OR_RETURN(std::shared_ptr<StoredGrid> grid,
                        assembler_->Finish(/*check_counts=*/true, Cancel()));
    log_.set_grid(absl::StrCat("grids/", grid->id));
    // An admin restores a grid for its owner (the archive's); anyone else imports a copy of
    // their own.
    std::string owner = caller_.role == Role::kAdmin ? grid->owner : caller_.owner();
    SG_RETURN_IF_ERROR(ops::StoreArchived(state_->Ops(), grid, assembler_->stated_connectivity(),
                                          std::move(owner)));
    // The reply shows what was stored: the store kept the newest --keep_revisions deformed
    // revisions of the archive (GridStore::Create), as this does.
    return EncodeGrid(*WithinRetention(grid, state_->options.max_deform_revisions), 0,
                      v1::GRID_VIEW_BASIC, {}, response_);
  }

  v1::Grid* response_;
  std::optional<GridAssembler> assembler_;
  int64_t records_ = 0;
};

}  // namespace

grpc::ServerWriteReactor<v1::ExportGridResponse>* SplineGridService::ExportGrid(
    grpc::CallbackServerContext* context, const v1::ExportGridRequest* request) {
  return new ExportReactor(state_, context, request);
}

grpc::ServerReadReactor<Decoded<v1::ImportArchiveRequest>>* SplineGridService::ImportArchiveStream(
    grpc::CallbackServerContext* context, v1::Grid* response) {
  return new ImportArchiveReactor(state_, context, response);
}

}  // namespace splinegrid::server
