// What the operations (server/ops) work on: the grid store, the memory budget and the deformers
// kept between calls. The operations are the service's orchestration without protobuf or gRPC:
// resolve revisions, reserve memory, run the kernel, build revisions and publish them. The
// handlers (server/*_call.cc) only convert requests and responses (proto/convert) and call them.
#ifndef SPLINEGRID_SERVER_OPS_OPS_CONTEXT_H_
#define SPLINEGRID_SERVER_OPS_OPS_CONTEXT_H_

#include "server/deformer_cache.h"
#include "server/grid_store.h"
#include "server/memory_budget.h"

namespace splinegrid::server::ops {

struct OpsContext {
  GridStore& store;
  MemoryBudget& budget;
  DeformerCache& deformers;
};

}  // namespace splinegrid::server::ops

#endif  // SPLINEGRID_SERVER_OPS_OPS_CONTEXT_H_
