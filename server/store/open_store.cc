#include "server/store/open_store.h"

#include "absl/strings/str_cat.h"
#include "server/store/dir_log.h"
#include "server/store/memory_store.h"
#include "server/store/redis_connection.h"
#include "server/store/redis_store.h"

namespace splinegrid::server {

absl::StatusOr<std::unique_ptr<GridStore>> OpenStore(const ServerOptions& options,
                                                     MemoryBudget* budget) {
  const std::string& spec = options.store;
  if (!options.redis_password_file.empty() && !spec.starts_with("redis://")) {
    return absl::InvalidArgumentError(
        absl::StrCat("--redis_password_file is for a redis:// store, and --store = '",
                     RedactRedisSpec(spec).substr(0, 200), "' is none"));
  }
  if (spec == "memory") return std::make_unique<MemoryStore>(options.max_deform_revisions);
  if (spec.starts_with("dir:")) {
    const std::string path = spec.substr(4);
    if (path.empty()) return absl::InvalidArgumentError("--store=dir: needs a path (dir:PATH)");
    absl::StatusOr<std::unique_ptr<MemoryStore>> store =
        OpenDirStore(path, options.max_deform_revisions, budget);
    if (!store.ok()) return store.status();
    return std::unique_ptr<GridStore>(*std::move(store));
  }
  if (spec.starts_with("redis://")) return OpenRedisStore(spec, options, budget);
  return absl::InvalidArgumentError(
      absl::StrCat("--store = '", RedactRedisSpec(spec).substr(0, 200),
                   "' is not a store: give memory, dir:PATH or redis://HOST:PORT[/DB]"));
}

}  // namespace splinegrid::server
