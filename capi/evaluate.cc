// splinegrid.h: evaluating a block into the caller's array.
#include <algorithm>
#include <cstdint>

#include "absl/strings/str_cat.h"
#include "capi/client_state.h"
#include "capi/splinegrid.h"
#include "client/client.h"
#include "core/util/status_macros.h"

namespace {

namespace client = splinegrid::client;

// OK when an array of `rank` dimensions `shape` (rank 0: a flat buffer of `capacity` values) can
// hold `got` as points(spatial_dim, ni, nj, nk) with the trailing directions merged into its
// last dimension; INVALID_ARGUMENT naming both shapes otherwise.
absl::Status CheckFits(const splinegrid::StructuredBlock& got, int32_t block, int32_t level,
                       int32_t rank, const int64_t* shape, int64_t capacity) {
  const int64_t needed = static_cast<int64_t>(got.coords().size());
  const std::string wanted =
      absl::StrCat("block ", block, " at level ", level, " needs ", needed, " (", got.spatial_dim(),
                   " x ", got.extent(0), " x ", got.extent(1), " x ", got.extent(2), ")");
  if (rank <= 1) {
    const int64_t size = rank == 1 ? shape[0] : capacity;
    if (size < needed) {
      return absl::InvalidArgumentError(
          absl::StrCat("points: capacity ", size, " values, ", wanted));
    }
    return absl::OkStatus();
  }
  // The array's dimensions against (spatial_dim, ni, nj, nk), the last one taking the rest.
  const int64_t want[4] = {got.spatial_dim(), got.extent(0), got.extent(1), got.extent(2)};
  bool fits = true;
  int64_t rest = 1;
  for (int d = 0; d < 4; ++d) {
    if (d < rank - 1) {
      fits = fits && shape[d] == want[d];
    } else {
      rest *= want[d];
    }
  }
  fits = fits && shape[rank - 1] == rest;
  if (!fits) {
    std::string given;
    for (int d = 0; d < rank; ++d) absl::StrAppend(&given, d == 0 ? "" : ", ", shape[d]);
    return absl::InvalidArgumentError(absl::StrCat(
        "points: shape (", given, ") does not fit ", wanted,
        ": give points(spatial_dim, ni, nj, nk), the directions after its last dimension merged "
        "into it, or a rank-1 array of at least that size"));
  }
  return absl::OkStatus();
}

absl::Status Evaluate(sg_client* c, const char* grid, int64_t revision, int32_t block,
                      int32_t level, double* points, int32_t rank, const int64_t* shape,
                      int64_t capacity, int32_t extents[3], int64_t* revision_out) {
  SG_RETURN_IF_ERROR(splinegrid::capi::RequireString(grid, "grid"));
  if (revision < 0) {
    return absl::InvalidArgumentError(absl::StrCat("revision: ", revision, " (0: the latest)"));
  }
  if (block < 0) return absl::InvalidArgumentError(absl::StrCat("block: ", block));
  if (points == nullptr) return absl::InvalidArgumentError("points: NULL");
  if (rank > 0 && shape == nullptr) return absl::InvalidArgumentError("shape: NULL");
  if (rank < 0 || rank > 4) {
    return absl::InvalidArgumentError(absl::StrCat("rank: ", rank, " (1 to 4)"));
  }
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
  SG_RETURN_IF_ERROR(CheckFits(got, block, level, rank, shape, capacity));
  std::copy(got.coords().begin(), got.coords().end(), points);
  if (extents != nullptr) {
    for (int d = 0; d < 3; ++d) extents[d] = got.extent(d);
  }
  if (revision_out != nullptr) *revision_out = evaluated.revision;
  return absl::OkStatus();
}

}  // namespace

extern "C" {

sg_status sg_evaluate(sg_client* c, const char* grid, int64_t revision, int32_t block,
                      int32_t level, double* points, int64_t capacity, int32_t extents[3],
                      int64_t* revision_out) {
  if (c == nullptr) return SG_INVALID_ARGUMENT;
  return splinegrid::capi::Guard(c->state.get(), [&]() -> absl::Status {
    return Evaluate(c, grid, revision, block, level, points, /*rank=*/0, nullptr, capacity, extents,
                    revision_out);
  });
}

sg_status sg_evaluate_shaped(sg_client* c, const char* grid, int64_t revision, int32_t block,
                             int32_t level, double* points, int32_t rank, const int64_t* shape,
                             int32_t extents[3], int64_t* revision_out) {
  if (c == nullptr) return SG_INVALID_ARGUMENT;
  return splinegrid::capi::Guard(c->state.get(), [&]() -> absl::Status {
    if (rank < 1) return absl::InvalidArgumentError(absl::StrCat("rank: ", rank, " (1 to 4)"));
    return Evaluate(c, grid, revision, block, level, points, rank, shape, 0, extents, revision_out);
  });
}

}  // extern "C"
