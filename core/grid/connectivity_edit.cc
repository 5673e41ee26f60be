#include "core/grid/connectivity_edit.h"

#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"

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

absl::Status CheckConnectivity(const MultiBlockGrid& grid, const Connectivity& connectivity,
                               double tolerance) {
  const int num_blocks = static_cast<int>(grid.blocks.size());
  for (const BoundaryMatch& match : connectivity.matches) {
    for (const FaceRange* range : {&match.a, &match.b}) {
      const int b = range->face.block;
      bool inside = b >= 0 && b < num_blocks && range->face.normal >= 0 && range->face.normal < 3;
      for (int d = 0; inside && d < 3; ++d) {
        inside = range->begin[d] >= 0 && range->begin[d] <= range->end[d] &&
                 range->end[d] < grid.blocks[b].extent(d);
      }
      if (!inside) {
        return absl::InvalidArgumentError(
            absl::StrCat("connectivity: the match ", match.Describe(), " does not fit the grid"));
      }
    }
    const StructuredBlock& a = grid.blocks[match.a.face.block];
    const StructuredBlock& b = grid.blocks[match.b.face.block];
    const int dim = a.spatial_dim();
    for (int k = match.a.begin[2]; k <= match.a.end[2]; ++k) {
      for (int j = match.a.begin[1]; j <= match.a.end[1]; ++j) {
        for (int i = match.a.begin[0]; i <= match.a.end[0]; ++i) {
          const Extents y = match.MapToB({i, j, k});
          double gap2 = 0.0;
          for (int c = 0; c < dim; ++c) {
            const double d = a.Point(i, j, k)[c] - b.Point(y[0], y[1], y[2])[c];
            gap2 += d * d;
          }
          if (!(std::sqrt(gap2) <= tolerance)) {
            return absl::InvalidArgumentError(absl::StrCat(
                "connectivity: the match ", match.Describe(), " has points ", std::sqrt(gap2),
                " apart at (", i, ", ", j, ", ", k, ") of block ", match.a.face.block));
          }
        }
      }
    }
  }
  return absl::OkStatus();
}

}  // namespace splinegrid
