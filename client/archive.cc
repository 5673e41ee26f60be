// Client::ExportGrid and Client::ImportArchive: a grid's archive records (ExportGrid's stream,
// ImportArchive's input) to and from a record file (core/io/record_file.h), one serialised
// ArchiveRecord per record.
#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <system_error>

#include "absl/strings/str_cat.h"
#include "client/client.h"
#include "core/io/record_file.h"
#include "core/util/status_macros.h"

namespace splinegrid::client {
namespace {

// Checks the shape of an archive as its records pass: a header first and only there, then as
// many source chunks and revisions as the header announces. `fault` builds the error (DATA_LOSS
// for a stream from the server, INVALID_ARGUMENT for a file) from a description.
class ArchiveShape {
 public:
  using Fault = std::function<absl::Status(const std::string& what)>;
  explicit ArchiveShape(Fault fault) : fault_(std::move(fault)) {}

  absl::Status Add(const v1::ArchiveRecord& record) {
    ++records_;
    if (records_ == 1) {
      if (!record.has_header()) {
        return fault_("the first record is not an archive header (is this an archive?)");
      }
      header_ = record.header();
      return absl::OkStatus();
    }
    switch (record.record_case()) {
      case v1::ArchiveRecord::kHeader:
        return fault_(absl::StrCat("record ", records_ - 1, " is a second header"));
      case v1::ArchiveRecord::kSource:
        ++source_chunks_;
        return absl::OkStatus();
      case v1::ArchiveRecord::kRevision:
        ++revisions_;
        return absl::OkStatus();
      default:  // a kind of record this client does not know: the server decides
        return absl::OkStatus();
    }
  }

  // After the last record: the counts match the header (revisions only when it counts them,
  // as an export's does).
  absl::Status Complete() const {
    if (records_ == 0) return fault_("no records (an archive starts with its header)");
    const bool revisions_short =
        header_.num_revisions() > 0 && revisions_ != header_.num_revisions();
    if (source_chunks_ != header_.num_source_chunks() || revisions_short) {
      return fault_(absl::StrCat("truncated or incomplete: the header announces ",
                                 header_.num_source_chunks(), " source chunks and ",
                                 header_.num_revisions(), " revisions, there are ", source_chunks_,
                                 " and ", revisions_));
    }
    return absl::OkStatus();
  }

  ArchiveSummary Summary(int64_t bytes) const {
    return ArchiveSummary{header_, source_chunks_, revisions_, bytes};
  }

 private:
  Fault fault_;
  int64_t records_ = 0;
  v1::ArchiveHeader header_;
  int64_t source_chunks_ = 0;
  int64_t revisions_ = 0;
};

// The next record of `reader` as an ArchiveRecord; nullopt at the end of the file. Errors are
// INVALID_ARGUMENT naming the file, the record and its byte offset.
absl::StatusOr<std::optional<v1::ArchiveRecord>> NextArchiveRecord(RecordReader& reader,
                                                                   const std::string& path,
                                                                   int64_t index,
                                                                   std::string* payload) {
  const int64_t offset = reader.offset();
  SG_ASSIGN_OR_RETURN(const bool more, reader.Next(payload));
  if (!more) return std::nullopt;
  v1::ArchiveRecord record;
  if (!record.ParseFromString(*payload)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "'", path, "': record ", index, " at byte offset ", offset, " is not an archive record"));
  }
  return record;
}

// Makes a rename into `directory` durable (best effort: some file systems refuse).
void SyncDirectory(const std::filesystem::path& directory) {
  const int fd = open(directory.empty() ? "." : directory.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return;
  (void)fsync(fd);
  close(fd);
}

}  // namespace

absl::StatusOr<ArchiveSummary> Client::ExportGrid(const std::string& name, const std::string& path,
                                                  const ProgressFn& progress) {
  v1::ExportGridRequest request;
  request.set_name(GridName(name));
  const std::string temp = absl::StrCat(path, ".partial-", getpid());
  const auto data_loss = [&](const std::string& what) {
    return absl::DataLossError(absl::StrCat("the export of ", request.name(), ": ", what));
  };
  // Every attempt writes the file from its start (a retried export repeats the stream).
  std::optional<RecordWriter> writer;
  std::optional<ArchiveShape> shape;
  int64_t bytes = 0;
  absl::Status local;  // a write failure or a malformed stream (the call is cancelled)
  absl::Status status = Call(GridId(request.name()), [&](grpc::ClientContext* context) {
    writer.reset();
    shape.emplace(data_loss);
    bytes = static_cast<int64_t>(kRecordFileMagic.size());
    absl::StatusOr<RecordWriter> created = RecordWriter::Create(temp);
    local = created.status();
    if (!local.ok()) return grpc::Status::OK;  // `local` says why
    writer.emplace(*std::move(created));
    auto reader = stub_->ExportGrid(context, request);
    v1::ExportGridResponse message;
    std::string payload;
    while (local.ok() && reader->Read(&message)) {
      local = shape->Add(message.record());
      if (local.ok()) {
        message.record().SerializeToString(&payload);
        local = writer->Append(payload);
        bytes += 8 + static_cast<int64_t>(payload.size());
        if (progress) progress(bytes, 0);
      }
      if (!local.ok()) context->TryCancel();
    }
    return reader->Finish();
  });
  if (status.ok()) status = local;
  if (status.ok()) status = shape->Complete();
  if (writer.has_value()) {
    const absl::Status closed = writer->Close(/*sync=*/status.ok());
    if (status.ok()) status = closed;
  }
  if (status.ok()) {
    std::error_code error;
    std::filesystem::rename(temp, path, error);
    if (error) {
      status = absl::InternalError(
          absl::StrCat("cannot rename '", temp, "' onto '", path, "': ", error.message()));
    }
  }
  if (!status.ok()) {
    std::remove(temp.c_str());
    return status;
  }
  SyncDirectory(std::filesystem::path(path).parent_path());
  return shape->Summary(bytes);
}

absl::StatusOr<v1::Grid> Client::ImportArchive(const std::string& path, const std::string& new_id,
                                               const ProgressFn& progress) {
  const auto fault = [&](const std::string& what) {
    return absl::InvalidArgumentError(absl::StrCat("'", path, "': ", what));
  };
  // The header first: a file that is not an archive is refused before any call, and the
  // archive's id routes the call when no new one is given.
  std::string payload;
  std::string grid_id = GridId(new_id);
  {
    SG_ASSIGN_OR_RETURN(RecordReader reader, RecordReader::Open(path));
    SG_ASSIGN_OR_RETURN(const std::optional<v1::ArchiveRecord> first,
                        NextArchiveRecord(reader, path, 0, &payload));
    ArchiveShape shape(fault);
    if (!first.has_value()) return shape.Complete();
    SG_RETURN_IF_ERROR(shape.Add(*first));
    if (grid_id.empty()) grid_id = first->header().id();
  }
  std::error_code size_error;
  const int64_t file_bytes = static_cast<int64_t>(std::filesystem::file_size(path, size_error));

  v1::Grid grid;
  absl::Status local;  // a damaged file (the call is cancelled: nothing is stored)
  const absl::Status status = Call(grid_id, [&](grpc::ClientContext* context) {
    auto writer = stub_->ImportArchive(context, &grid);
    v1::ImportArchiveRequest request;
    request.set_grid_id(GridId(new_id));
    ArchiveShape shape(fault);
    absl::StatusOr<RecordReader> reader = RecordReader::Open(path);
    local = reader.status();
    bool open = true;
    for (int64_t index = 0; local.ok() && open; ++index) {
      absl::StatusOr<std::optional<v1::ArchiveRecord>> record =
          NextArchiveRecord(*reader, path, index, &payload);
      if (!record.ok()) {
        local = record.status();
      } else if (!record->has_value()) {
        local = shape.Complete();
        break;
      } else {
        local = shape.Add(**record);
        *request.mutable_record() = std::move(**record);
        if (local.ok()) open = writer->Write(request);
        request.clear_grid_id();  // the first message only
        if (progress) progress(reader->offset(), file_bytes);
      }
    }
    if (!local.ok()) {
      context->TryCancel();
    } else {
      writer->WritesDone();
    }
    return writer->Finish();
  });
  SG_RETURN_IF_ERROR(local);
  SG_RETURN_IF_ERROR(status);
  return grid;
}

}  // namespace splinegrid::client
