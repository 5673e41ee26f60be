#include "core/grid/connectivity_edit.h"

#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

// `range` of a block whose `direction` (extent n) is reversed.
void ReverseRange(FaceRange& range, int direction, int n) {
  if (range.face.normal == direction) range.face.upper = !range.face.upper;
  const int begin = n - 1 - range.end[direction], end = n - 1 - range.begin[direction];
  range.begin[direction] = begin;
  range.end[direction] = end;
}

}  // namespace

Connectivity Extruded(const Connectivity& surface, int layers) {
  Connectivity out = surface;
  for (BoundaryMatch& match : out.matches) {
    match.a.begin[2] = match.b.begin[2] = 0;
    match.a.end[2] = match.b.end[2] = layers;
    match.b_direction[2] = 2;
    match.reversed[2] = false;
  }
  return out;
}

void ReverseBlockDirection(Connectivity& connectivity, int block, int direction,
                           const Extents& extents) {
  const int n = extents[direction];
  for (BoundaryMatch& match : connectivity.matches) {
    // a's index along `direction` now runs the other way: so does the match along it.
    if (match.a.face.block == block) {
      ReverseRange(match.a, direction, n);
      if (match.b_direction[direction] >= 0) match.reversed[direction] = !match.reversed[direction];
    }
    // b's index along `direction` now runs the other way: the a-direction mapped onto it turns.
    if (match.b.face.block == block) {
      ReverseRange(match.b, direction, n);
      for (int d = 0; d < 3; ++d) {
        if (match.b_direction[d] == direction) match.reversed[d] = !match.reversed[d];
      }
    }
  }
}

absl::Status CheckMatchFits(const MultiBlockGrid& grid, const BoundaryMatch& match,
                            const std::string& what) {
  const int num_blocks = static_cast<int>(grid.blocks.size());
  for (const FaceRange* range : {&match.a, &match.b}) {
    const int b = range->face.block;
    bool inside = b >= 0 && b < num_blocks && range->face.normal >= 0 && range->face.normal < 3;
    for (int d = 0; inside && d < 3; ++d) {
      inside = range->begin[d] >= 0 && range->begin[d] <= range->end[d] &&
               range->end[d] < grid.blocks[b].extent(d);
    }
    if (!inside) {
      return absl::InvalidArgumentError(
          absl::StrCat("connectivity: the match ", match.Describe(), " does not fit ", what));
    }
  }
  return absl::OkStatus();
}

absl::Status CheckConnectivity(const MultiBlockGrid& grid, const Connectivity& connectivity,
                               double tolerance) {
  for (const BoundaryMatch& match : connectivity.matches) {
    SG_RETURN_IF_ERROR(CheckMatchFits(grid, match, "the grid"));
    const StructuredBlock& a = grid.blocks[match.a.face.block];
    const StructuredBlock& b = grid.blocks[match.b.face.block];
    const int dim = a.spatial_dim();
    absl::Status status;
    ForEachMatchedPoint(match, [&](const Extents& x, const Extents& y) {
      if (!status.ok()) return;
      double gap2 = 0.0;
      for (int c = 0; c < dim; ++c) {
        const double d = a.Point(x[0], x[1], x[2])[c] - b.Point(y[0], y[1], y[2])[c];
        gap2 += d * d;
      }
      if (!(std::sqrt(gap2) <= tolerance)) {
        status = absl::InvalidArgumentError(absl::StrCat(
            "connectivity: the match ", match.Describe(), " has points ", std::sqrt(gap2),
            " apart at (", x[0], ", ", x[1], ", ", x[2], ") of block ", match.a.face.block));
      }
    });
    SG_RETURN_IF_ERROR(status);
  }
  return absl::OkStatus();
}

}  // namespace splinegrid
