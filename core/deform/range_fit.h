// Least squares for the controls of one spline direction that carry a range of its parameters.
//
// For samples u_0 < ... < u_{S-1} filling a parameter range [u_0, u_{S-1}] (the points of a
// boundary range at some refinement level), the B-splines that are nonzero at the samples are
// those whose supports overlap the range: a contiguous block of controls [first, last]. RangeFit
// factors min || B x - y || over them once (banded QR, banded_qr.h) and then maps any number of
// sample columns y to control columns x, in O(samples order) each. The first (last) control is
// pinned to the first (last) sample when its B-spline is 1 there, at a clamped end or a break
// (a knot of multiplicity order - 1): the fit then passes through that end exactly, as the
// fitted grid does.
#ifndef SPLINEGRID_CORE_DEFORM_RANGE_FIT_H_
#define SPLINEGRID_CORE_DEFORM_RANGE_FIT_H_

#include <cstdint>
#include <span>
#include <vector>

#include "absl/status/statusor.h"
#include "core/bspline/basis.h"
#include "core/bspline/knot_vector.h"
#include "core/fit/solve/banded_qr.h"

namespace splinegrid {

class RangeFit {
 public:
  // Errors: INVALID_ARGUMENT for fewer than 2 or unsorted samples; FAILED_PRECONDITION when the
  // samples do not determine every control of the block (too few inside some support).
  static absl::StatusOr<RangeFit> Create(const KnotVector& knots, std::span<const double> samples);

  int first() const { return first_; }
  int last() const { return last_; }
  int num_controls() const { return last_ - first_ + 1; }
  int num_samples() const { return basis_.num_samples(); }

  // `in`: num_samples() rows of `width` values (row r at in + r width); `out`: num_controls()
  // rows of `width` values, the least-squares controls of every column.
  void Apply(const double* in, int64_t width, double* out) const;

 private:
  RangeFit() = default;

  int first_ = 0, last_ = 0;
  bool pin_first_ = false, pin_last_ = false;
  SampledBasis basis_;
  BandedQR qr_{1, 1};      // over the free controls, rows in sample order
  std::vector<int> rows_;  // the samples whose rows were added to qr_, in order
};

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_DEFORM_RANGE_FIT_H_
