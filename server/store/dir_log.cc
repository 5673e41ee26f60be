#include "server/store/dir_log.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <system_error>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/io/file_util.h"
#include "core/io/record_file.h"
#include "core/util/status_macros.h"
#include "server/store/grid_archive.h"
#include "server/store/revision_codec.h"

namespace splinegrid::server {
namespace {

namespace fs = std::filesystem;

constexpr char kGridFile[] = "grid.records";
// Markers of grids set aside as damaged at a start: damaged/{id}, a record file holding why.
constexpr char kDamagedDir[] = "damaged";

absl::Status ErrnoStatus(const std::string& what) { return ErrnoToStatusWithMessage(errno, what); }

absl::Status FsStatus(const std::error_code& error, const std::string& what) {
  if (error.category() == std::generic_category() || error.category() == std::system_category()) {
    return ErrnoToStatusWithMessage(error.value(), what);
  }
  return absl::InternalError(absl::StrCat(what, ": ", error.message()));
}

// fsync of a directory: makes the renames and unlinks in it durable.
absl::Status SyncDirectory(const fs::path& dir) {
  const int fd = open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return ErrnoStatus(absl::StrCat("cannot open ", dir.string()));
  const int synced = fsync(fd);
  const int error = errno;
  close(fd);
  if (synced != 0) {
    return ErrnoToStatusWithMessage(error, absl::StrCat("cannot fsync ", dir.string()));
  }
  return absl::OkStatus();
}

std::string RevisionFile(int64_t number) { return absl::StrFormat("r%012d.records", number); }

// The revision number of a file name "r{number}{suffix}", or -1.
int64_t NumberOf(const std::string& name, std::string_view suffix) {
  if (name.size() <= 1 + suffix.size() || name[0] != 'r' || !name.ends_with(suffix)) return -1;
  int64_t number = 0;
  if (!absl::SimpleAtoi(name.substr(1, name.size() - 1 - suffix.size()), &number)) return -1;
  return number > 0 ? number : -1;
}
int64_t RevisionNumberOf(const std::string& name) { return NumberOf(name, ".records"); }

// The marker left in a grid's directory for a revision file that was set aside as damaged
// ("r{number}.damaged", holding why), and the number of such a name (or -1).
std::string DamagedMarker(int64_t number) { return absl::StrFormat("r%012d.damaged", number); }
int64_t DamagedNumberOf(const std::string& name) { return NumberOf(name, ".damaged"); }

// Writes `payloads` as the record file `dir/name` through a temporary file: durable and
// atomic. The directory itself is not synced (the caller does, once per change).
absl::Status WriteRecordFile(const fs::path& dir, const std::string& name,
                             const std::vector<std::string>& payloads) {
  const fs::path tmp = dir / (name + ".tmp");
  absl::Status written = [&]() -> absl::Status {
    SG_ASSIGN_OR_RETURN(RecordWriter writer, RecordWriter::Create(tmp.string()));
    for (const std::string& payload : payloads) SG_RETURN_IF_ERROR(writer.Append(payload));
    SG_RETURN_IF_ERROR(writer.Close(/*sync=*/true));
    if (std::rename(tmp.c_str(), (dir / name).c_str()) != 0) {
      return ErrnoStatus(absl::StrCat("cannot rename ", tmp.string()));
    }
    return absl::OkStatus();
  }();
  if (!written.ok()) std::remove(tmp.c_str());  // a full disk gets its space back at once
  return written;
}

std::string Serialize(const v1::ArchiveRecord& record) { return record.SerializeAsString(); }

class DirLog final : public DurableLog {
 public:
  DirLog(fs::path root, int lock_fd) : root_(std::move(root)), lock_fd_(lock_fd) {}
  ~DirLog() override { close(lock_fd_); }

  absl::Status WriteGrid(const StoredGrid& grid) override {
    const fs::path staging = root_ / "grids" / absl::StrCat(".", grid.id, ".new");
    const absl::Status written = WriteStaged(grid, staging);
    if (!written.ok()) {
      std::error_code error;
      fs::remove_all(staging, error);  // a full disk gets its space back at once
    }
    return written;
  }

  absl::Status WriteRevision(const std::string& id, const GridRevision& revision) override {
    const fs::path dir = root_ / "grids" / id;
    SG_RETURN_IF_ERROR(WriteRevisionFile(dir, revision));
    return SyncDirectory(dir);
  }

  void DropRevisions(const std::string& id, const std::vector<int64_t>& numbers) override {
    const fs::path dir = root_ / "grids" / id;
    for (int64_t number : numbers) {
      std::error_code error;
      fs::remove(dir / RevisionFile(number), error);
    }
  }

  absl::Status Probe() override {
    const fs::path grids = root_ / "grids";
    // A name starting with '.': a start removes it if this does not finish.
    SG_RETURN_IF_ERROR(WriteRecordFile(grids, ".probe", {"probe"}));
    if (std::remove((grids / ".probe").c_str()) != 0) {
      return ErrnoStatus(absl::StrCat("cannot remove ", (grids / ".probe").string()));
    }
    return SyncDirectory(grids);
  }

  absl::Status DeleteGrid(const std::string& id) override {
    const fs::path trash = root_ / "trash" / absl::StrCat(id, "-", absl::ToUnixNanos(absl::Now()));
    if (std::rename((root_ / "grids" / id).c_str(), trash.c_str()) != 0) {
      return ErrnoStatus(absl::StrCat("cannot move grids/", id, " to the trash"));
    }
    SG_RETURN_IF_ERROR(SyncDirectory(root_ / "grids"));
    std::error_code error;
    fs::remove_all(trash, error);  // a start empties the trash if this did not finish
    return absl::OkStatus();
  }

  absl::Status ForgetDamagedGrid(const std::string& id) override {
    const fs::path marker = root_ / kDamagedDir / id;
    if (std::remove(marker.c_str()) != 0 && errno != ENOENT) {
      return ErrnoStatus(absl::StrCat("cannot remove ", kDamagedDir, "/", id));
    }
    return SyncDirectory(root_ / kDamagedDir);
  }

 private:
  // WriteGrid through `staging` (grids/.{id}.new), renamed to grids/{id} when complete.
  absl::Status WriteStaged(const StoredGrid& grid, const fs::path& staging) {
    const fs::path grids = root_ / "grids";
    std::error_code error;
    fs::remove_all(staging, error);
    if (!fs::create_directory(staging, error)) {
      return FsStatus(error, absl::StrCat("cannot create ", staging.string()));
    }
    std::vector<std::string> payloads;
    v1::ArchiveRecord record;
    *record.mutable_header() = EncodeGridHeader(grid, 0);
    payloads.push_back(Serialize(record));
    SG_RETURN_IF_ERROR(ForEachSourceChunk(grid.source->grid(), kSourceChunkValues,
                                          [&](const v1::SourceChunk& chunk) {
                                            v1::ArchiveRecord r;
                                            *r.mutable_source() = chunk;
                                            payloads.push_back(Serialize(r));
                                            return absl::OkStatus();
                                          }));
    SG_RETURN_IF_ERROR(WriteRecordFile(staging, kGridFile, payloads));
    for (const auto& revision : grid.revisions) {
      SG_RETURN_IF_ERROR(WriteRevisionFile(staging, *revision));
    }
    SG_RETURN_IF_ERROR(SyncDirectory(staging));
    if (std::rename(staging.c_str(), (grids / grid.id).c_str()) != 0) {
      return ErrnoStatus(absl::StrCat("cannot rename ", staging.string(), " to ", grid.id));
    }
    return SyncDirectory(grids);
  }

  static absl::Status WriteRevisionFile(const fs::path& dir, const GridRevision& revision) {
    v1::ArchiveRecord record;
    EncodeRevision(revision, record.mutable_revision());
    return WriteRecordFile(dir, RevisionFile(revision.number), {Serialize(record)});
  }

  const fs::path root_;
  const int lock_fd_;  // flock'ed: one server per directory
};

// The incarnation of a grid written before the store kept incarnations: the same at every start
// (a watch resumed across a restart still knows the grid), different for another creation of
// the id (another create_time). FNV-1a, 64 bits, of "id/create_time in ns".
std::string StableIncarnation(const StoredGrid& grid) {
  uint64_t hash = 14695981039346656037ull;
  for (const char c : absl::StrCat(grid.id, "/", absl::ToUnixNanos(grid.create_time))) {
    hash = (hash ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  }
  return absl::StrFormat("%016x", hash);
}

// Moves a damaged file or grid directory to corrupt/ and says so.
void SetAside(const fs::path& root, const fs::path& path, const absl::Status& why) {
  const fs::path target =
      root / "corrupt" /
      absl::StrCat(path.parent_path().filename().string(), "-", path.filename().string(), "-",
                   absl::ToUnixNanos(absl::Now()));
  std::error_code error;
  fs::rename(path, target, error);
  std::fprintf(stderr, "splinegrid: store: %s is damaged and was skipped (moved to %s): %s\n",
               path.string().c_str(), target.string().c_str(), std::string(why.message()).c_str());
}

// Reads one grid directory: its header and points (any fault: the whole grid is unusable), then
// each revision (a fault skips that revision only).
absl::StatusOr<std::shared_ptr<StoredGrid>> LoadGrid(const fs::path& root, const fs::path& dir,
                                                     int max_deform_revisions,
                                                     MemoryBudget* budget) {
  const std::string id = dir.filename().string();
  GridAssembler assembler(budget, id);
  {
    SG_ASSIGN_OR_RETURN(RecordReader reader, RecordReader::Open((dir / kGridFile).string()));
    std::string payload;
    for (;;) {
      SG_ASSIGN_OR_RETURN(const bool more, reader.Next(&payload));
      if (!more) break;
      v1::ArchiveRecord record;
      if (!record.ParseFromString(payload) ||
          record.record_case() == v1::ArchiveRecord::kRevision) {
        return absl::InvalidArgumentError(
            absl::StrCat("record at byte ", reader.offset(), " is not a header or source chunk"));
      }
      SG_RETURN_IF_ERROR(assembler.Add(record));
    }
    if (!assembler.has_source()) {
      return absl::InvalidArgumentError("the source points are incomplete");
    }
  }
  std::vector<std::pair<int64_t, fs::path>> files;
  std::vector<int64_t> damaged;  // set aside, at this start or an earlier one
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.ends_with(".tmp")) {
      fs::remove(entry.path());  // an unacknowledged write
    } else if (const int64_t number = RevisionNumberOf(name); number > 0) {
      files.emplace_back(number, entry.path());
    } else if (const int64_t marked = DamagedNumberOf(name); marked > 0) {
      damaged.push_back(marked);
    }
  }
  std::sort(files.begin(), files.end());
  for (const auto& file : files) {
    // Named, not a structured binding: clang 14 (.ci/tsan, .ci/fuzz) cannot capture those.
    const int64_t number = file.first;
    const fs::path& path = file.second;
    absl::Status loaded = [&]() -> absl::Status {
      SG_ASSIGN_OR_RETURN(RecordReader reader, RecordReader::Open(path.string()));
      std::string payload;
      SG_ASSIGN_OR_RETURN(const bool present, reader.Next(&payload));
      v1::ArchiveRecord record;
      if (!present || !record.ParseFromString(payload) || !record.has_revision()) {
        return absl::InvalidArgumentError("it holds no revision record");
      }
      if (record.revision().number() != number) {
        return absl::InvalidArgumentError(
            absl::StrCat("it holds revision ", record.revision().number(), ", not ", number));
      }
      return assembler.AddRevision(record.revision());
    }();
    if (loaded.code() == absl::StatusCode::kResourceExhausted) return loaded;
    if (!loaded.ok()) {
      // A marker in its place, so that asking for it says what happened, after later starts too.
      const absl::Status marked =
          WriteRecordFile(dir, DamagedMarker(number), {std::string(loaded.message())});
      if (!marked.ok()) {
        std::fprintf(stderr, "splinegrid: store: cannot mark %s as damaged: %s\n",
                     path.string().c_str(), std::string(marked.message()).c_str());
      }
      SetAside(root, path, loaded);
      damaged.push_back(number);
    }
  }
  SG_ASSIGN_OR_RETURN(std::shared_ptr<StoredGrid> grid, assembler.Finish(/*check_counts=*/false));
  if (grid->incarnation.empty()) grid->incarnation = StableIncarnation(*grid);
  std::sort(damaged.begin(), damaged.end());
  damaged.erase(std::unique(damaged.begin(), damaged.end()), damaged.end());
  grid->damaged_revisions = std::move(damaged);
  // Retention may not have finished removing files before a crash: apply it again.
  const std::vector<int64_t> dropped = DeformRevisionsBeyond(grid->revisions, max_deform_revisions);
  for (int64_t number : dropped) {
    std::error_code error;
    fs::remove(dir / RevisionFile(number), error);
  }
  std::erase_if(grid->revisions, [&](const std::shared_ptr<const GridRevision>& r) {
    return std::find(dropped.begin(), dropped.end(), r->number) != dropped.end();
  });
  return grid;
}

// The grids damaged at this start or an earlier one (id -> why), from the markers in damaged/;
// a marker of an id that was loaded (a stale one) is removed.
std::map<std::string, std::string> DamagedGrids(
    const fs::path& root, const std::vector<std::shared_ptr<const StoredGrid>>& loaded) {
  std::map<std::string, std::string> damaged;
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(root / kDamagedDir, error)) {
    const std::string id = entry.path().filename().string();
    if (id.ends_with(".tmp")) {
      fs::remove(entry.path(), error);  // a marker whose write did not finish
      continue;
    }
    const bool is_loaded =
        std::any_of(loaded.begin(), loaded.end(), [&](const auto& grid) { return grid->id == id; });
    if (is_loaded) {
      fs::remove(entry.path(), error);
      continue;
    }
    std::string why = "the reason was not readable";
    if (absl::StatusOr<RecordReader> reader = RecordReader::Open(entry.path().string());
        reader.ok()) {
      std::string payload;
      if (absl::StatusOr<bool> read = reader->Next(&payload); read.ok() && *read) {
        why = payload.substr(0, 1000);
      }
    }
    damaged.emplace(id, std::move(why));
  }
  return damaged;
}

}  // namespace

absl::StatusOr<std::unique_ptr<MemoryStore>> OpenDirStore(const std::string& path,
                                                          int max_deform_revisions,
                                                          MemoryBudget* budget) {
  const fs::path root(path);
  std::error_code error;
  for (const char* sub : {"grids", "corrupt", "trash", kDamagedDir}) {
    fs::create_directories(root / sub, error);
    if (error) return FsStatus(error, absl::StrCat("--store=dir:", path, ": cannot create ", sub));
  }
  const int lock_fd = open((root / "LOCK").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock_fd < 0) return ErrnoStatus(absl::StrCat("--store=dir:", path, ": cannot open LOCK"));
  if (flock(lock_fd, LOCK_EX | LOCK_NB) != 0) {
    close(lock_fd);
    return absl::FailedPreconditionError(absl::StrCat(
        "--store=dir:", path, " is in use by another process (its LOCK file is locked)"));
  }
  fs::remove_all(root / "trash", error);
  fs::create_directories(root / "trash", error);
  std::vector<std::shared_ptr<const StoredGrid>> loaded;
  for (const fs::directory_entry& entry : fs::directory_iterator(root / "grids", error)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with(".")) {  // a Create that did not finish
      fs::remove_all(entry.path(), error);
      continue;
    }
    absl::StatusOr<std::shared_ptr<StoredGrid>> grid =
        LoadGrid(root, entry.path(), max_deform_revisions, budget);
    if (grid.ok()) {
      loaded.push_back(*std::move(grid));
    } else if (grid.status().code() == absl::StatusCode::kResourceExhausted) {
      close(lock_fd);
      return absl::ResourceExhaustedError(absl::StrCat("--store=dir:", path, ": loading grids/",
                                                       name, ": ", grid.status().message()));
    } else {
      SetAside(root, entry.path(), grid.status());
      // A marker in its place, so that asking for the grid says what happened, after later
      // starts too (until it is deleted).
      const absl::Status marked =
          WriteRecordFile(root / kDamagedDir, name, {std::string(grid.status().message())});
      if (!marked.ok() || !SyncDirectory(root / kDamagedDir).ok()) {
        std::fprintf(stderr, "splinegrid: store: cannot mark grids/%s as damaged: %s\n",
                     name.c_str(), std::string(marked.message()).c_str());
      }
    }
  }
  if (error) {
    close(lock_fd);
    return FsStatus(error, absl::StrCat("--store=dir:", path, ": cannot list grids/"));
  }
  std::map<std::string, std::string> damaged = DamagedGrids(root, loaded);
  std::fprintf(
      stderr, "splinegrid: store dir:%s: %zu grids loaded%s\n", path.c_str(), loaded.size(),
      damaged.empty() ? "" : absl::StrCat(", ", damaged.size(), " reported damaged").c_str());
  return std::make_unique<MemoryStore>(max_deform_revisions,
                                       std::make_unique<DirLog>(root, lock_fd), std::move(loaded),
                                       std::move(damaged));
}

}  // namespace splinegrid::server
