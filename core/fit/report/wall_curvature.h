// Curvature along the walls of a fitted grid: how smooth the body surface is (fairing.h).
//
// A wall line is a maximal run of at least three consecutive wall points along a grid line of a
// block (BoundaryKinds): the wall faces of a planar block, every grid line of a surface block
// in 3D, the in-face lines of a volume block's wall faces. Runs are cut at the block's
// distribution breaks (feature points such as a sharp trailing edge): a kink is not a curvature
// extremum. Along a wall line the fitted spline's iso-parametric curve C(t) is sampled at
// refinement level `level` of the point distribution, and
//   planar blocks: kappa = (x' y'' - y' x'') / |C'|^3 (signed, positive turning left),
//   3D:            kappa = |C' x C''| / |C'|^3.
// Metrics over all samples of all wall lines:
//  - samples;
//  - extrema: interior samples where kappa turns from rising to falling or back (changes below
//    1e-9 of the line's largest |kappa| count as flat, so a straight line has none);
//  - sum of squared curvature differences of neighbouring samples, sum (kappa_{s+1} - kappa_s)^2,
//    which grows with every wiggle (the fairness measure of Farin & Sapidis, "Curvature and the
//    fairness of curves and surfaces", IEEE CG&A 9(2), 1989).
// Cost O(k^2) per sample plus the contraction of the control net onto each line.
#ifndef SPLINEGRID_CORE_FIT_REPORT_WALL_CURVATURE_H_
#define SPLINEGRID_CORE_FIT_REPORT_WALL_CURVATURE_H_

#include <cstdint>
#include <span>
#include <vector>

#include "core/bspline/evaluation.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/grid/boundary_kinds.h"

namespace splinegrid {

// Grid points start + t e_direction, t = 0 .. length - 1, of block `block`.
struct WallLine {
  int block = 0;
  int direction = 0;
  Extents start = {0, 0, 0};
  int length = 0;
};

struct CurvatureSample {
  double arc_length = 0.0;  // from the start of the wall line (chord sum of the samples)
  Point3 point = {0.0, 0.0, 0.0};
  double curvature = 0.0;
};

struct CurvatureMetrics {
  int64_t lines = 0;
  int64_t samples = 0;
  int64_t extrema = 0;
  double sum_squared_differences = 0.0;
  double max_abs_curvature = 0.0;
};

// The wall lines of `blocks` (fitted blocks of a grid with `kinds`), block by block, direction
// by direction, lines in point order.
std::vector<WallLine> FindWallLines(const std::vector<FittedBlock>& blocks,
                                    const BoundaryKinds& kinds);

// The curvature of `fitted` along `line` at refinement level `level` (0: the original points),
// (length - 1) 2^level + 1 samples. Precondition: level <= kMaxRefinementLevel (sampling.h).
std::vector<CurvatureSample> SampleWallCurvature(const FittedBlock& fitted, const WallLine& line,
                                                 int level);

// Adds the samples of one wall line to `metrics`.
void AccumulateCurvature(std::span<const CurvatureSample> samples, CurvatureMetrics& metrics);

// The metrics of every wall line of `blocks` at `level`.
CurvatureMetrics WallCurvatureMetrics(const std::vector<FittedBlock>& blocks,
                                      const BoundaryKinds& kinds, int level);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_REPORT_WALL_CURVATURE_H_
