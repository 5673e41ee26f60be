// Curvature reduction of an offset layer's concave parts, before the next step.
//
// A curve offset by h shrinks where it is concave (curvature -kappa, kappa > 0) by the factor
// 1 - h kappa and folds once h kappa >= 1. Offsets into a cove focus its normals on one point:
// at distance d from a concave arc of radius R the layer's radius is R - d, so the curvature
// grows layer after layer while the steps grow too, and smoothing the normals cannot stop it
// (the 30P30N slat's cove folded at layer 46 of 96, the main element's flap cove at its concave
// corner at layer 66). The cure of curvature-flow front tracking (J. A. Sethian, "Curvature and
// the evolution of fronts", Commun. Math. Phys. 101, 1985: speed 1 - eps kappa, the entropy
// condition) is to let concave parts advance faster than the rest. FillConcavities does that on
// the layer itself, where and as much as needed:
//
//   while some point has h_next kappa_i > max_turning (kappa_i: its turning angle over half its
//   two segments):
//     mark those points and kConcaveFillReach neighbours on both sides, and on every run [a, b]
//     of marked points, with x_{a-1} and x_{b+1} held, take one implicit Laplacian step
//       (1 + 2 tau) x_i - tau (x_{i-1} + x_{i+1}) = x_i,   tau = kConcaveFillTau.
//
// A Laplacian step moves a concave point forward, towards its neighbours' chord, and evens the
// spacing along the run, which spreads the points the cove had focused; a run grows by itself
// as its ends become the concave points. An implicit step is stable for any tau; one is worth
// 16 explicit (1, 2, 1) / 4 sweeps. Convex corners and the seam stay and bound the runs; concave
// corners are smoothed like any point, since their offsets would keep the corner and consume
// the points of both sides. Last, no point moves by more than max_move (the caller's next
// step): a grid line bends by at most 45 degrees per layer, and a concave corner is rounded over
// several layers instead of chamfered in one (chamfered in one layer, the 30P30N main element's
// corner kinked its grid lines, and the interpolating spline of that grid folded 81 sub-cells
// at levels 1-2).
//
// Measured on the three 30P30N elements (129 to 1025 wall points, 48 to 200 layers): at most
// 1450 rounds on one layer (the flap at 1025 points), runs of at most 57 points, every filled
// layer valid; the rounds grow about linearly with the points.
#ifndef SPLINEGRID_CORE_GENERATE_CONCAVE_FILL_H_
#define SPLINEGRID_CORE_GENERATE_CONCAVE_FILL_H_

#include <vector>

#include "core/generate/loop_geometry.h"

namespace splinegrid {

// tau of one implicit step (worth 16 explicit sweeps), and the neighbours smoothed with an
// offending point on each side (file comment).
inline constexpr double kConcaveFillTau = 4.0;
inline constexpr int kConcaveFillReach = 2;

struct ConcaveFill {
  int rounds = 0;     // implicit steps taken (0: the layer was within the bound)
  bool met = true;    // no point left beyond the bound (else the rounds ran out: 4 per point)
  int held_back = 0;  // points whose move was cut to max_move
};

// Smooths the closed loop `layer` (the first point repeated as the last; `orientation` the sign
// of its area, as LoopNormals) until no point has a concave curvature kappa with
// h_next kappa > max_turning, then cuts every point's move to max_move (file comment).
// `fixed[i]` points do not move; the seam (the first and last point) never does. At most 4
// rounds per point, O(points) each.
ConcaveFill FillConcavities(std::vector<Point2>& layer, const std::vector<bool>& fixed,
                            double orientation, double h_next, double max_turning, double max_move);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GENERATE_CONCAVE_FILL_H_
