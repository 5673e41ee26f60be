// Parametrisation of structured point data: which parameter each grid index maps to.
//
// For a line of points Q_0 .. Q_{m-1} the parameters are u_0 = 0 < ... < u_{m-1} = 1 with
// increments proportional to 1 (uniform), |Q_{i+1} - Q_i| (chord length) or its square root
// (centripetal, Lee 1989). For a tensor grid every grid line of a direction gets its own
// parameters and the direction's parameters are their average (P&T A9.3, SurfMeshParams); lines of
// zero length (collapsed edges) do not take part.
#ifndef SPLINEGRID_CORE_BSPLINE_PARAMETRIZATION_H_
#define SPLINEGRID_CORE_BSPLINE_PARAMETRIZATION_H_

#include <array>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

enum class Parametrization {
  kUniform,      // u_i = i / (m - 1)
  kChordLength,  // increments proportional to the distance between neighbours
  kCentripetal,  // increments proportional to the square root of that distance
};

// "uniform", "chord_length" or "centripetal".
std::string_view ParametrizationName(Parametrization p);

// OK for the three values above; INVALID_ARGUMENT naming the value otherwise (a cast integer).
absl::Status ValidateParametrization(Parametrization p);

// Parameters of the three grid directions (i, j, k) of `block`, each averaged over all grid
// lines of that direction. Always strictly increasing from 0 to 1: increments that vanish on
// every line (repeated points) get a small share of a uniform increment, so the parameters stay
// usable for knot placement. A direction with one point gives {0}. Cost: one sweep over the
// points (three square roots each); memory: a third of the input for volumes.
std::array<std::vector<double>, 3> ParametrizeBlock(const StructuredBlock& block,
                                                    Parametrization parametrization);

// Parameters of direction d of `block` averaged over some of its grid lines only: the lines
// along d through the grid indices `lines` (each entry's index in direction d is ignored).
// Collapsed lines take no part; with none left, the average over all lines. Cost O(lines m_d).
std::vector<double> ParametrizeLines(const StructuredBlock& block, int d,
                                     const std::vector<Extents>& lines,
                                     Parametrization parametrization);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_BSPLINE_PARAMETRIZATION_H_
