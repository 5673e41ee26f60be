// splinegrid.h: evaluating a block into the caller's array.
#include <algorithm>
#include <cstdint>

#include "absl/strings/str_cat.h"
#include "capi/client_state.h"
#include "capi/splinegrid.h"
#include "client/client.h"
#include "core/util/status_macros.h"

extern "C" {

sg_status sg_evaluate(sg_client* c, const char* grid, int64_t revision, int32_t block,
                      int32_t level, double* points, int64_t capacity, int32_t extents[3],
                      int64_t* revision_out) {
  namespace client = splinegrid::client;
  if (c == nullptr) return SG_INVALID_ARGUMENT;
  return splinegrid::capi::Guard(c->state.get(), [&]() -> absl::Status {
    SG_RETURN_IF_ERROR(splinegrid::capi::RequireString(grid, "grid"));
    if (revision < 0) {
      return absl::InvalidArgumentError(absl::StrCat("revision: ", revision, " (0: the latest)"));
    }
    if (block < 0) return absl::InvalidArgumentError(absl::StrCat("block: ", block));
    if (points == nullptr) return absl::InvalidArgumentError("points: NULL");
    SG_ASSIGN_OR_RETURN(client::Client * connected, c->state->Connected());
    splinegrid::v1::EvaluateGridRequest request;
    request.set_name(client::GridName(grid));
    request.set_revision(revision);
    request.add_blocks(block);
    request.set_refinement_level(level);  // the server checks the range
    SG_ASSIGN_OR_RETURN(const client::EvaluatedGrid evaluated, connected->Evaluate(request));
    if (evaluated.blocks.size() != 1) {
      return absl::InternalError(
          absl::StrCat("the server answered ", evaluated.blocks.size(), " blocks for 1"));
    }
    const splinegrid::StructuredBlock& got = evaluated.blocks.front().points;
    const int64_t needed = static_cast<int64_t>(got.coords().size());
    if (capacity < needed) {
      return absl::InvalidArgumentError(
          absl::StrCat("points: capacity ", capacity, " values, block ", block, " at level ", level,
                       " needs ", needed, " (", got.extent(0), " x ", got.extent(1), " x ",
                       got.extent(2), " x ", got.spatial_dim(), ")"));
    }
    std::copy(got.coords().begin(), got.coords().end(), points);
    if (extents != nullptr) {
      for (int d = 0; d < 3; ++d) extents[d] = got.extent(d);
    }
    if (revision_out != nullptr) *revision_out = evaluated.revision;
    return absl::OkStatus();
  });
}

}  // extern "C"
