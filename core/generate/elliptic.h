// Elliptic smoothing of planar O-grids, solved coarse to fine with a B-spline of the coarse
// grid as the initial guess of the fine one (the QUADFLOW use of splines for grid generation).
//
// The grid x(xi, eta) (xi = i along the loops, periodic; eta = j from the wall) solves the
// Thompson-Thames-Mastin equations
//   alpha (x_xixi + phi x_xi) - 2 beta x_xieta + gamma (x_etaeta + psi x_eta) = 0,
//   alpha = |x_eta|^2,  beta = x_xi . x_eta,  gamma = |x_xi|^2
// (J. F. Thompson, F. C. Thames, C. W. Mastin, J. Comput. Phys. 15, 1974), with control
// functions in the form of P. D. Thomas and J. F. Middlecoff (AIAA J. 18(6), 1980), computed from
// an algebraic grid (cove_completion.h: the transfinite grid, from an offset layer past coves):
//  - phi from the point distributions of the two loops that bound the smoothed region (the
//    innermost free layer and the outer loop), blended linearly in eta, so the points slide
//    along the layers from the one distribution towards the other;
//  - psi at every point such that the algebraic grid satisfies the component of the discrete
//    equations normal to its layer, so every layer keeps its distance from the wall and with it
//    the boundary layer's growth. (With psi = 0, Winslow, the layers would spread evenly; with
//    psi from the layer distribution alone, -(x_eta . x_etaeta) / |x_eta|^2, the layers'
//    curvature pulls them in and a 1e-5 first layer shrinks a hundredfold.)
// The layers near the wall are held as the algebraic grid has them (orthogonalised there, with
// the requested heights; its offset layers, if any), and so are the wall and the outer loop.
//
// Discretisation: central differences on the unit index grid, except that x_xixi + phi x_xi
// (and likewise in eta) is exponentially fitted (D. N. de G. Allen and R. V. Southwell 1955,
// A. M. Il'in 1969): B(phi) x_{i-1} + B(-phi) x_{i+1} - (B(phi) + B(-phi)) x_i with
// B(z) = z / (e^z - 1). That is exact for geometric point distributions on every level, so the
// coarse and fine levels solve the same problem, and its weights are positive for any phi (no
// clipping of the controls). Phi from a loop is then ln(|x_i - x_{i-1}| / |x_{i+1} - x_i|).
// Solver: alternating line relaxation, every line of constant i solved at once (tridiagonal in
// j: the flat cells near the wall couple strongly in j) then every line of constant j (cyclic
// tridiagonal in i: the long far-field cells couple in i), each relaxed by omega, until no point
// moves by more than `tolerance` times its smallest neighbouring spacing in a sweep. Should the
// largest move stop falling (over-relaxation can keep the points by a sharp trailing edge
// jumping) or stop being finite, the iteration starts again from the initial grid with omega
// lowered (elliptic.cc kStallSweeps).
//
// Coarse to fine: the coarse grid takes every second point and layer of the algebraic grid; it
// is smoothed from there, interpolated by a B-spline surface (tensor_fit.h) and
// evaluated at refinement level 1 of its point distribution, which gives as many points as the
// fine grid; with the fine held layers and outer loop put back, that is the fine level's initial
// guess. The fine level is then solved by multigrid cycles (below): the relaxation alone loses
// a far-field mode at about 0.99 a sweep, the same from either start, so the guess alone saved
// only 2x at the default tolerance.
//
// Multigrid cycles: the full approximation scheme (A. Brandt, Math. Comp. 31(138), 1977;
// U. Trottenberg, C. W. Oosterlee, A. Schueller, "Multigrid", 2001, sec. 5.3.4) for the
// nonlinear equations N(x) = 0 on two levels: a fine sweep; the coarse level (every second
// point and layer) takes
//   N_c(x_c) = N_c(I x) + 16 R (-N(x))
// from x_c = I x (I: injection, the coarse point (I, J) is the fine (2 I, 2 J); R: full
// weighting; 16 because N is in index units: on half the points the metric terms and the
// differences of a smooth grid are 4 times as large each) and is relaxed; its correction
// x_c - I x, interpolated bilinearly in index space, is added to the fine free points; a fine
// sweep. The smooth far-field error the relaxation hardly reduces is what the coarse level
// removes. The control functions of each level are those of the algebraic grid at its points.
// (Three to five levels diverged or stalled on the coarser ones.)
#ifndef SPLINEGRID_CORE_GENERATE_ELLIPTIC_H_
#define SPLINEGRID_CORE_GENERATE_ELLIPTIC_H_

#include <vector>

#include "absl/status/statusor.h"
#include "core/grid/structured_grid.h"
#include "core/util/cancellation.h"

namespace splinegrid {

// Per grid point (point order).
struct ControlFunctions {
  std::vector<double> phi, psi;
};

// The control functions of the file comment from the algebraic grid `grid` (ni x nj x 1,
// spatial_dim 2, i periodic: the first line repeated as the last), phi blended from layer
// `inner` (the innermost free layer's neighbour below) to the outer loop. About 0.15-0.17 us
// a point (a safeguarded Newton iteration per point; BM_TrackingControls): `cancel` is polled
// every layer. Errors: CANCELLED.
absl::StatusOr<ControlFunctions> TrackingControls(const StructuredBlock& grid, int inner,
                                                  const CancelCheck& cancel = {});

struct EllipticOptions {
  int max_sweeps = 20000;
  // Converged when no point moves by more than this fraction of its smallest neighbouring
  // spacing in a sweep.
  double tolerance = 1e-3;
  double relaxation = 1.3;  // omega, in (0, 2); lowered after a stall (file comment)
  CancelCheck cancel;

  absl::Status Validate() const;
};

struct EllipticResult {
  StructuredBlock grid;
  int sweeps = 0;
  // SmoothMultigrid: the levels, and the sweeps of the coarser levels in units of a fine sweep
  // (a sweep of level l counts 4^-l).
  int levels = 1;
  double coarse_work = 0.0;
  bool stalled = false;  // the cycles stopped helping, and relaxation alone went on
  // Starts from the initial grid after a stall or a move that was not finite, and the
  // relaxation factor omega at the end (the options' unless lowered: elliptic.cc).
  int restarts = 0;
  double relaxation = 0.0;
  bool converged = false;
  double seconds = 0.0;
};

// Smooths `initial` with `control` (same points), holding layers 0 .. held_layers - 1 and the
// outer loop. Not converging (within max_sweeps, or stalled at the smallest omega: file comment) is
// reported (converged = false), not an error; the grid is then the iterate nearest convergence.
// Errors: INVALID_ARGUMENT for bad options or a grid that is not a periodic planar O-grid of at
// least 5 x 3 points; FAILED_PRECONDITION if the iteration diverges; CANCELLED.
absl::StatusOr<EllipticResult> SmoothElliptic(const StructuredBlock& initial,
                                              const ControlFunctions& control, int held_layers,
                                              const EllipticOptions& options);

// Smooths `initial` by the multigrid cycles of the file comment: a coarse level of every second
// point and layer if both extents are odd (and it has at least 17 x 9 points; else relaxation
// alone), each level with the control functions
// of `algebraic` (the algebraic grid, same points) at its points, the held layers halved. As
// SmoothElliptic, converged when a fine sweep moves no point by more than the tolerance of its
// spacing; `sweeps` counts the fine sweeps, `coarse_work` the coarse ones (a quarter each).
// Errors as SmoothElliptic,
// and INVALID_ARGUMENT if `algebraic` is not an O-grid of the same points.
absl::StatusOr<EllipticResult> SmoothMultigrid(const StructuredBlock& initial,
                                               const StructuredBlock& algebraic, int held_layers,
                                               const EllipticOptions& options);

struct CoarseToFine {
  EllipticResult coarse;  // the coarse level from the algebraic grid's every second point
  EllipticResult fine;    // the fine level from the coarse grid's spline, two-level cycles
  // The fine level from the algebraic grid by relaxation alone (with `compare`): the baseline
  // of the work saved.
  EllipticResult fine_from_transfinite;
  int held_layers = 1;  // of the fine level
};

// The layers 0 .. LayersWithin - 1 of the stack `heights` (transfinite.h LayerHeights) lie
// within `distance` of the wall: d_j <= distance. At least 1, the wall.
int LayersWithin(const std::vector<double>& heights, double distance);

// The algebraic grid `algebraic` (cove_completion.h: an O-grid between the wall and an evenly
// spaced outer circle) smoothed coarse to fine, holding at least layers 0 .. held_layers - 1
// (one more if that makes the last held fine layer a coarse one); with `compare`, also smoothed
// from the algebraic grid by relaxation alone. Errors: INVALID_ARGUMENT unless `algebraic` is a
// periodic planar O-grid with an odd number of points around (the first repeated) and an even
// number of layers, and as SmoothElliptic.
absl::StatusOr<CoarseToFine> SmoothCoarseToFine(const StructuredBlock& algebraic, int held_layers,
                                                const EllipticOptions& options, bool compare);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GENERATE_ELLIPTIC_H_
