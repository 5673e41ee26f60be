// Knot insertion (Boehm's algorithm): refine the knot vector of one direction without
// changing the mapping.
#ifndef SPLINEGRID_CORE_BSPLINE_KNOT_INSERTION_H_
#define SPLINEGRID_CORE_BSPLINE_KNOT_INSERTION_H_

#include "absl/status/statusor.h"
#include "core/bspline/tensor_spline.h"

namespace splinegrid {

// Inserts the knot u `times` times into direction `direction` (P&T A5.1, applied to every
// control line of that direction, A5.3). The result describes the same mapping exactly (up to
// rounding) with `times` more control points per line in that direction.
// Errors: INVALID_ARGUMENT if direction is not 0..2, u is not strictly inside the domain,
// times < 1, or the multiplicity of u would exceed order - 1.
absl::StatusOr<TensorSpline> InsertKnot(const TensorSpline& spline, int direction, double u,
                                        int times = 1);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_BSPLINE_KNOT_INSERTION_H_
