// What the operations (server/ops) work on: the grid store, the memory budget and the deformers
// kept between calls. The operations are the service's orchestration without protobuf or gRPC:
// resolve revisions, reserve memory, run the kernel, build revisions and publish them. The
// handlers (server/*_call.cc) only convert requests and responses (proto/convert) and call them.
#ifndef SPLINEGRID_SERVER_OPS_OPS_CONTEXT_H_
#define SPLINEGRID_SERVER_OPS_OPS_CONTEXT_H_

#include <functional>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "server/deformer_cache.h"
#include "server/grid_store.h"
#include "server/memory_budget.h"

namespace splinegrid::server::ops {

// Decides from a grid's owner whether the caller may change it: OK, or the error to return.
// Arguments: the owner (StoredGrid::owner), the grid's name ("grids/ID") and the action
// ("fitting", "fairing", "deforming").
using ChangeCheck = std::function<absl::Status(const std::string& owner, const std::string& name,
                                               absl::string_view action)>;

struct OpsContext {
  GridStore& store;
  MemoryBudget& budget;
  DeformerCache& deformers;
  ChangeCheck may_change = {};  // empty: every caller may change every grid

  // The check for grid `id` owned by `owner` (OK without a check).
  absl::Status MayChange(const std::string& owner, const std::string& id,
                         absl::string_view action) const {
    return may_change ? may_change(owner, "grids/" + id, action) : absl::OkStatus();
  }
};

}  // namespace splinegrid::server::ops

#endif  // SPLINEGRID_SERVER_OPS_OPS_CONTEXT_H_
