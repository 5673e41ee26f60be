// `serve --store`: which GridStore backend holds the grids.
//   memory                  in this process (the default; nothing to install, lost on exit)
//   dir:PATH                in this process and in PATH, durable (dir_log.h)
//   redis://[USER[:PASSWORD]@]HOST:PORT[/DB]  in Redis, shared by any number of replicas
//                           (redis_store.h; the password also from --redis_password_file)
#ifndef SPLINEGRID_SERVER_STORE_OPEN_STORE_H_
#define SPLINEGRID_SERVER_STORE_OPEN_STORE_H_

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "server/grid_store.h"
#include "server/memory_budget.h"
#include "server/server_options.h"

namespace splinegrid::server {

// Opens the store `options.store` names, loading what it holds. INVALID_ARGUMENT for a spec
// that is none of the above; UNAVAILABLE when Redis cannot be reached; other errors as the
// backend reports them.
absl::StatusOr<std::unique_ptr<GridStore>> OpenStore(const ServerOptions& options,
                                                     MemoryBudget* budget);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_STORE_OPEN_STORE_H_
