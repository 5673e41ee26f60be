// Grids by transfinite interpolation between a wall loop and an outer loop.
//
// The O-grid X(i, j), i along both loops (the same number of points, the first repeated as the
// last), j = 0 the wall and j = layers the outer loop, is Gordon's line interpolation in the
// layer direction with the layer heights d_j = sum_{k<j} h_k of offset_march.h (first_height,
// growth r so that they add up to `distance` D), t_j = d_j / D:
//  - straight lines, X = W_i + t_j (O_i - W_i) (orthogonalize = false), or
//  - orthogonalised: the straight line bent towards the wall normal n_i near the wall,
//      X = W_i + t (O_i - W_i) + t (1 - t)^m (D n_i - (O_i - W_i)),
//    which leaves the wall along n_i at the requested heights, X = W_i + d_j n_i + O(t^2), and
//    straightens out within about orthogonal_reach: the bump t (1 - t)^m peaks at
//    1 / (e (m + 1)) and m is chosen so that D times that is orthogonal_reach (the lines bend
//    off straight by at most that much, so neighbouring lines in a concave region cannot cross
//    unless it is tighter than the reach). Straight lines from a sharp trailing edge's
//    neighbours graze the surface towards the edge and fold the first cells; the bent lines
//    clear it first.
// The outer loop: a circle about the wall's centroid, `distance` beyond the wall's farthest
// point, its points at the angles of the wall points' arc length (the wall's clustering,
// carried out), starting in the direction of the wall's first point (the trailing edge), so
// that the straight lines from the trailing edge fan out instead of crossing.
#ifndef SPLINEGRID_CORE_GENERATE_TRANSFINITE_H_
#define SPLINEGRID_CORE_GENERATE_TRANSFINITE_H_

#include <array>
#include <vector>

#include "absl/status/statusor.h"
#include "core/generate/wall_loop.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

struct CompletionOptions {
  int layers = 128;
  double first_height = 1e-5;
  double distance = 50.0;
  bool orthogonalize = true;
  double orthogonal_reach = 0.2;  // in the wall's unit

  absl::Status Validate() const;
};

// How the outer circle's points are spaced: at the angles of the wall points' arc length (the
// wall's clustering carried out), or evenly (for elliptic smoothing, elliptic.h: the clustering
// at a trailing edge would leave far-field cells a thousandth as wide as they are long).
enum class OuterSpacing { kFollowWall, kEven };

// The circle of the file comment: about the wall's centroid, `distance` beyond its farthest
// point.
struct Circle {
  std::array<double, 2> center = {0.0, 0.0};
  double radius = 0.0;
};
Circle EnclosingCircle(const std::vector<std::array<double, 2>>& wall, double distance);

// As many points on `circle` as `loop` has (closed, first repeated as last), running the same
// way round from the direction of its first point, spaced as `spacing` says (kFollowWall: at
// the angles of the loop's arc length).
std::vector<std::array<double, 2>> PointsOnCircle(const Circle& circle,
                                                  const std::vector<std::array<double, 2>>& loop,
                                                  OuterSpacing spacing);

// PointsOnCircle(EnclosingCircle(wall, distance), wall, spacing).
std::vector<std::array<double, 2>> OuterCircle(const WallLoop& wall, double distance,
                                               OuterSpacing spacing = OuterSpacing::kFollowWall);

// The heights d_0 = 0 < d_1 < ... < d_layers = distance of the layers: first_height, growing by
// the ratio r (sampling.h GeometricRatio).
std::vector<double> LayerHeights(const CompletionOptions& options);

// Rows from .. heights.size() - 1 of `grid` (at least that many rows, inner.size() points per
// row): the lines of the file comment from inner[i] to outer[i] (closed loops of the same
// points), leaving inner[i] along directions[i] (unit) with orthogonalize, at
// t_j = (d_j - d_from) / (d_last - d_from) of `heights`; row `from` is `inner`.
void InterpolateLines(const std::vector<std::array<double, 2>>& inner,
                      const std::vector<std::array<double, 2>>& directions,
                      const std::vector<std::array<double, 2>>& outer,
                      const std::vector<double>& heights, const CompletionOptions& options,
                      int from, StructuredBlock& grid);

// The O-grid between `wall` and `outer` (same point count, both closed, outer enclosing wall):
// points x (layers + 1), spatial_dim 2, with i running as in offset_march.h (clockwise, cell
// areas positive). Errors: INVALID_ARGUMENT for bad options or loops.
absl::StatusOr<StructuredBlock> TransfiniteGrid(const WallLoop& wall,
                                                const std::vector<std::array<double, 2>>& outer,
                                                const CompletionOptions& options);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GENERATE_TRANSFINITE_H_
