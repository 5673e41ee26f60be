// Validity of a fitted grid: no folded cells and no cell far from its original size, at the
// original resolution and at refinement levels 1..max_level.
//
// Every cell of the original block (named by its lower corner (i, j, k)) is compared with the
// fitted cells inside it. At level l the fitted block is evaluated at the refined point
// distribution (PointDistribution::Refined, (m - 1) 2^l + 1 points per active direction); its
// sub-cell (I, J, K) lies in the original ("parent") cell (I >> l, J >> l, K >> l) and takes
// the share s = prod_d du_sub / du_parent of the parent's parameter intervals. Its intended size
// is that share of the parent, so
//   ratio = measure(fitted sub-cell) / (s * measure(parent cell)),
// the fitted mapping's mean Jacobian over the sub-cell relative to the original cell's. At level
// 0, s = 1 and this is the plain size ratio. The refined distribution follows the original
// grid's stretching (point_distribution.h), so s is not 2^(-l D): in a wall layer stretched by 2
// per cell the first of four sub-cells gets 0.19 of its parent's height, not 0.25, and a
// refinement that keeps the stretching is not mistaken for a size jump. A perfect fit gives 1;
// ratio <= 0 is a fold (the Jacobian lost the original cell's sign); ratio outside [1 / r, r],
// r = max_size_ratio, is a size jump.
//
// Signed cell measures, corners in binary order: corner a + 2b (+ 4c) is grid point
// (i + a, j + b, k + c) counted in the block's active directions, fastest first:
//  - planar blocks (spatial_dim 2): shoelace area of the quadrilateral x0 x1 x3 x2,
//      A = 0.5 (x3 - x0) x (x2 - x1)              (half the cross product of the diagonals);
//  - surfaces in 3D: the area vector a = 0.5 (x3 - x0) x (x2 - x1); the ratio is
//      a_fitted . a_original / |a_original|^2      (times 2^(2l)),
//    so a fold or a flipped normal is negative and a same-size, same-orientation cell gives 1;
//  - volumes: the volume of the trilinear hexahedron, the integral of det J over the cell, in
//    closed form: the six tetrahedra around the diagonal x0-x7 (J. Grandy, "Efficient computation
//    of volume of hexahedral cells", LLNL UCRL-ID-128886, 1997),
//      V6 = (x7 - x0) . ((x1 - x0) x (x3 - x5) + (x4 - x0) x (x5 - x6)
//                        + (x2 - x0) x (x6 - x3)) / 6,
//    is exact only for planar faces: it splits every face along its diagonal through x0 or x7.
//    A bilinear face encloses the mean of its two triangulations, which differ by the
//    tetrahedron of its corners, so
//      V = V6 + 1/12 sum_faces (b - a) . ((c - a) x (d - a)),
//    faces a b c d in outward cyclic order with a-c the diagonal V6 used: (0 2 3 1), (4 5 7 6),
//    (0 4 6 2), (1 3 7 5), (0 1 5 4), (2 6 7 3). Tested against exact Gauss quadrature of det J.
// Curves and points have no cells: their result is empty and ok().
//
// Skipped cells (counted in cells_skipped, never failed): original cells whose measure is ~0,
// |measure| <= 1e-12 * the block's median |measure| (a cell collapsed to a line or point), and
// cells with a collapsed edge, one edge no longer than 1e-9 * the cell's longest edge (polar
// axes, wing tips, degenerate tip patches). The latter have a nonzero measure, but their Jacobian
// vanishes on the collapsed edge, so even a perfect refinement does not split them evenly: the
// sub-cells at the apex of a triangle get ratio 2^-l, a false size failure at level 2.
//
// Cost O(cells * 2^(l D)) per level for the measures plus the evaluation, O(k) per refined
// point (sum factorisation, GridEvaluator). The levels are evaluated one after another, each in
// chunks of i (when i is active) and, within a chunk, row by row along the slowest active
// direction (grid lines for surfaces, k-planes for volumes), two rows held at a time. Memory:
// the reference measures (one or three doubles and a state byte per original cell), the
// evaluator's u-contracted net (at most options.evaluator_budget doubles, unless two points of
// it exceed that), and two rows of a chunk.
#ifndef SPLINEGRID_CORE_FIT_REPORT_GRID_QUALITY_H_
#define SPLINEGRID_CORE_FIT_REPORT_GRID_QUALITY_H_

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/bspline/evaluation.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/grid/structured_grid.h"
#include "core/util/cancellation.h"

namespace splinegrid {

struct CellQualityOptions {
  // Highest refinement level checked; levels 0..max_level are all checked. At most
  // kMaxRefinementLevel (sampling.h); the cost grows as 2^(max_level D).
  int max_level = 2;
  // Largest accepted size change (dimensionless, >= 1): a cell passes when its ratio lies in
  // [1 / max_size_ratio, max_size_ratio].
  double max_size_ratio = 2.0;
  // Most original cells listed in CellQuality::bad_cells (>= 0); the count is always exact.
  int max_reported_cells = 1000;
  // Memory knob, in doubles: when i is active the refined grid is evaluated in chunks of i
  // whose GridEvaluator net, spatial_dim * (chunk points) * n_v * n_w, fits this budget (at least
  // two points per chunk). The result does not depend on it. Default 32 MB.
  int64_t evaluator_budget = int64_t{1} << 22;
  // Polled before every row (grid line or plane) of every chunk and level; fired: CANCELLED.
  CancelCheck cancel;

  // OK, or INVALID_ARGUMENT naming the field and value.
  absl::Status Validate() const;
};

struct CellQuality {
  // Fitted (sub-)cells checked and skipped, summed over all levels.
  int64_t cells_checked = 0;
  int64_t cells_skipped = 0;
  // Checked cells with ratio <= 0 (folded or, on surfaces, normal flipped).
  int64_t folded = 0;
  // Checked cells with 0 < ratio < 1 / max_size_ratio or ratio > max_size_ratio.
  int64_t out_of_size = 0;
  // Smallest ratio over all checked cells: the worst Jacobian ratio, negative for a fold.
  double min_ratio = std::numeric_limits<double>::infinity();
  // Largest |ratio| over all checked cells.
  double max_ratio = 0.0;
  // Original-grid cell (lower corner; 0 in inactive directions) and level of min_ratio.
  Extents worst_cell = {0, 0, 0};
  int worst_level = 0;
  // Distinct original cells that failed at any level, and the first max_reported_cells of them
  // in index order (i fastest).
  int64_t num_bad_cells = 0;
  std::vector<Extents> bad_cells;
  // Checked cells with ratio <= 0 at each level 0..max_level (they sum to `folded`).
  std::vector<int64_t> folded_by_level;
  // Distinct original cells with a folded sub-cell at some level (a subset of the bad cells),
  // and the first max_reported_cells of them in index order.
  int64_t num_folded_cells = 0;
  std::vector<Extents> folded_cells;

  // No folded and no out-of-size cell.
  bool ok() const { return folded == 0 && out_of_size == 0; }
  // Whether the check measured anything: some cell was checked, or the block has no cells at all
  // (curves, points). A block whose every cell was skipped as collapsed was not measured, so
  // ok() says nothing about it.
  bool measured() const { return cells_checked > 0 || cells_skipped == 0; }
};

// Checks the cells of `fitted` (a fit of `original`: its distribution has original's extents)
// at levels 0..options.max_level, as described in the file comment.
// Errors: INVALID_ARGUMENT for bad options, extents or spatial_dim that differ (both named),
// non-finite original points, or three active directions with spatial_dim 2; OUT_OF_RANGE when
// a level has more than 2^30 points in a direction; CANCELLED.
absl::StatusOr<CellQuality> CheckCellQuality(const FittedBlock& fitted,
                                             const StructuredBlock& original,
                                             const CellQualityOptions& options = {});

// The cells of an original block as CheckCellQuality compares fits with them: their signed
// measures and which are skipped as collapsed. Built once, it checks any number of fits of the
// same grid (a deformation gate checks every time step against one reference); building costs
// about one check at level 0, and it holds about 8 bytes per cell (24 for surfaces in 3D).
class CellReference {
 public:
  // INVALID_ARGUMENT for non-finite points or three active directions with spatial_dim 2.
  static absl::StatusOr<CellReference> Build(const StructuredBlock& original);

  const Extents& extents() const;
  int spatial_dim() const;
  int64_t num_cells() const;
  // The bytes it holds.
  int64_t bytes() const;

  struct Cells;  // defined in grid_quality.cc

 private:
  explicit CellReference(std::shared_ptr<const Cells> cells) : cells_(std::move(cells)) {}
  friend absl::StatusOr<CellQuality> CheckCellQuality(const FittedBlock& fitted,
                                                      const CellReference& reference,
                                                      const CellQualityOptions& options);
  std::shared_ptr<const Cells> cells_;
};

// CheckCellQuality against a prebuilt reference (the same result).
absl::StatusOr<CellQuality> CheckCellQuality(const FittedBlock& fitted,
                                             const CellReference& reference,
                                             const CellQualityOptions& options);

// One sentence on the folds of block `block`'s `quality` (empty when nothing folded): the
// folded sub-cells per level, the original cells they lie in, the worst cell with its level and
// Jacobian ratio and the first `max_listed` folded cells, e.g. "block 0: 268 folded sub-cells at
// level 1 and 1010 at level 2 in 657 cells; the worst at cell (3, 40, 0), level 2, Jacobian ratio
// -0.8; first cells (2, 39, 0), ...".
std::string DescribeFolds(int block, const CellQuality& quality, int max_listed = 8);

// The cell measures of the file comment, for single cells (corners in binary order; z ignored
// for the planar area). Planar signed area, positive when x0 x1 x3 x2 runs counter-clockwise.
double PlanarCellArea(const std::array<Point3, 4>& corners);
// Area vector 0.5 (x3 - x0) x (x2 - x1); its length is the area of a planar cell.
Point3 CellAreaVector(const std::array<Point3, 4>& corners);
// Signed volume of the trilinear hexahedron (V above), positive for a right-handed cell.
double HexahedronVolume(const std::array<Point3, 8>& corners);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_REPORT_GRID_QUALITY_H_
