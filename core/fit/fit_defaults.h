// The defaults the fit's options share, stated once. GridFitOptions (grid_fit.h) is the one
// options struct of FitGrid; the lower-level fits a solver may call on their own (FitBlock,
// FitToTolerance, FitAirfoil) start from the same values.
#ifndef SPLINEGRID_CORE_FIT_FIT_DEFAULTS_H_
#define SPLINEGRID_CORE_FIT_FIT_DEFAULTS_H_

#include "core/bspline/parametrization.h"

namespace splinegrid {

// Spline order (degree + 1): cubic.
inline constexpr int kDefaultOrder = 4;
inline constexpr Parametrization kDefaultParametrization = Parametrization::kChordLength;
// Knot refinement rounds of a tolerance fit before it gives up (each round splits every span
// that needs it, so 60 rounds reach far below any grid's spacing).
inline constexpr int kDefaultMaxRefinementRounds = 60;

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_FIT_DEFAULTS_H_
