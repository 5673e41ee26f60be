// The quality gate of a deformation: folded cells and the change of wall orthogonality.
//
// Cells are compared at refinement level `level` of the point distribution: the reference grid
// is evaluated there, and each deformed cell's signed measure (grid_quality.h: signed area,
// area vector along the reference normal, trilinear volume) is divided by the reference cell's.
// A ratio <= 0 is a folded cell (its Jacobian changed sign); the smallest ratio is the worst
// Jacobian ratio. Cells the quality check skips (collapsed edges) are not judged. Surface blocks
// in 3D are compared along the reference normals, so rotations beyond 90 degrees would read as
// folds; planar and volume blocks are judged by their signed measure, which rotation keeps.
//
// Orthogonality: at the samples of every wall line (wall_curvature.h, FindWallLines) at the
// same level, the angle between the wall tangent and the grid line leaving the wall (the other
// active direction of a planar block, the face's normal direction of a volume), in the
// reference and in the deformed grid; the largest change is reported. Surface blocks have no
// line leaving the wall and are skipped.
#ifndef SPLINEGRID_CORE_DEFORM_DEFORM_QUALITY_H_
#define SPLINEGRID_CORE_DEFORM_DEFORM_QUALITY_H_

#include <cstdint>
#include <limits>
#include <vector>

#include "absl/status/statusor.h"
#include "core/fit/report/grid_quality.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/grid/boundary_kinds.h"
#include "core/grid/point_distribution.h"
#include "core/util/cancellation.h"

namespace splinegrid {

struct DeformationCheck {
  int level = 0;
  int64_t cells_checked = 0;
  int64_t folded = 0;
  double min_jacobian_ratio = std::numeric_limits<double>::infinity();
  double max_jacobian_ratio = 0.0;
  int worst_block = 0;
  Extents worst_cell = {0, 0, 0};  // lower corner at `level`
  double max_orthogonality_change_degrees = 0.0;
  int64_t wall_samples = 0;

  bool ok() const { return folded == 0; }
};

// The check of deformations of one reference at one level, with what depends on the reference
// alone computed once: the reference grid at that level and its cells (grid_quality.h
// CellReference), the wall lines and their angles. A coupled simulation checks every step
// against the same reference; then each check only evaluates the deformed grid.
class DeformationGate {
 public:
  // Errors: INVALID_ARGUMENT for a level outside [0, kMaxRefinementLevel] or a reference the
  // cell check refuses (non-finite points); CANCELLED (`cancel` is polled per block and line).
  static absl::StatusOr<DeformationGate> Create(const std::vector<FittedBlock>& reference,
                                                const BoundaryKinds& kinds, int level,
                                                const CancelCheck& cancel = {});

  // Compares `deformed` (the reference's blocks moved: same blocks and distributions) with the
  // reference. Errors: INVALID_ARGUMENT for blocks that do not correspond; CANCELLED.
  absl::StatusOr<DeformationCheck> Check(const std::vector<FittedBlock>& deformed,
                                         const CancelCheck& cancel = {}) const;

  int level() const { return level_; }
  // The reference cells held, and the bytes of everything held (about 9-25 per cell).
  int64_t num_cells() const;
  int64_t bytes() const;

 private:
  // A block at the gate's level: its point distribution and reference cells.
  struct Block {
    PointDistribution at_level;
    CellReference cells;
  };
  // A sample of a wall line: where, the wall direction d, the direction e leaving the wall, and
  // the reference's angle between them.
  struct WallSample {
    int block = 0;
    Point3 uvw;
    int d = 0, e = 0;
    double before = 0.0;
  };

  DeformationGate() = default;

  int level_ = 0;
  std::vector<Block> blocks_;
  std::vector<WallSample> samples_;
};

// Compares `deformed` with `reference` (same blocks, same distributions) at `level`:
// DeformationGate::Create then Check. Errors: INVALID_ARGUMENT for blocks that do not
// correspond or a level outside [0, kMaxRefinementLevel]; CANCELLED.
absl::StatusOr<DeformationCheck> CheckDeformation(const std::vector<FittedBlock>& reference,
                                                  const std::vector<FittedBlock>& deformed,
                                                  const BoundaryKinds& kinds, int level,
                                                  const CancelCheck& cancel = {});

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_DEFORM_DEFORM_QUALITY_H_
