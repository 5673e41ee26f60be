#include "core/bspline/tensor_spline.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace splinegrid {

absl::StatusOr<TensorSpline> TensorSpline::Create(std::array<KnotVector, 3> knots, int spatial_dim,
                                                  std::vector<double> control) {
  if (spatial_dim != 2 && spatial_dim != 3) {
    return absl::InvalidArgumentError(
        absl::StrCat("spatial_dim = ", spatial_dim, "; must be 2 or 3"));
  }
  const int64_t points =
      int64_t{knots[0].num_controls()} * knots[1].num_controls() * knots[2].num_controls();
  if (static_cast<int64_t>(control.size()) != spatial_dim * points) {
    return absl::InvalidArgumentError(absl::StrCat(
        "control: ", control.size(), " coordinates given; the knot vectors define ",
        knots[0].num_controls(), " x ", knots[1].num_controls(), " x ", knots[2].num_controls(),
        " control points of ", spatial_dim, " coordinates = ", spatial_dim * points));
  }
  for (size_t i = 0; i < control.size(); ++i) {
    if (!std::isfinite(control[i])) {
      return absl::InvalidArgumentError(
          absl::StrCat("control[", i, "] = ", control[i], " is not finite"));
    }
  }
  return TensorSpline(std::move(knots), spatial_dim, std::move(control));
}

Extents TensorSpline::control_extents() const {
  return {knots_[0].num_controls(), knots_[1].num_controls(), knots_[2].num_controls()};
}

}  // namespace splinegrid
