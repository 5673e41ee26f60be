// The `dir:PATH` backend: a MemoryStore whose every change is on disk before the call that made
// it returns, and which a restart loads back.
//
// Layout under PATH (every file a record file, core/io/record_file.h):
//   grids/{id}/grid.records          the header and the source points (archive records)
//   grids/{id}/r{number}.records     one StoredRevision each (number zero-padded to 12 digits)
//   grids/{id}/r{number}.damaged     a revision file a start found damaged and set aside (why)
//   corrupt/                         what a start found damaged, moved aside (and logged)
// Each file is written as `name.tmp`, fsynced, renamed over `name` and its directory fsynced
// (rename is atomic, so a reader sees the old state or the new, never half). A new grid is
// written into `grids/.{id}.new` and renamed to `grids/{id}` as a whole; a deleted grid is
// renamed to `trash/` (fsynced) before its files are removed. A start removes leftover .tmp
// files, .new and trash directories: the changes they were part of were never acknowledged.
#ifndef SPLINEGRID_SERVER_STORE_DIR_LOG_H_
#define SPLINEGRID_SERVER_STORE_DIR_LOG_H_

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "server/memory_budget.h"
#include "server/store/memory_store.h"

namespace splinegrid::server {

// Opens (creating if needed) the store directory `path` and loads it: every grid and revision
// that reads back intact; a damaged grid or revision file is reported on stderr, moved to
// corrupt/ and skipped. Errors: the directory cannot be created, read or locked (another
// server uses it), or the budget cannot hold what it contains.
absl::StatusOr<std::unique_ptr<MemoryStore>> OpenDirStore(const std::string& path,
                                                          int max_deform_revisions,
                                                          MemoryBudget* budget);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_STORE_DIR_LOG_H_
