// Fits a half turn of a helix (201 points) with 16 cubic control points through the installed
// kernel, and checks the fit and a point evaluated between the data.
#include <cmath>
#include <cstdio>

#include "core/bspline/evaluation.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/grid/structured_grid.h"

int main() {
  constexpr int kPoints = 201;
  constexpr double kPi = 3.14159265358979323846;
  splinegrid::StructuredBlock helix({kPoints, 1, 1}, 3);
  for (int i = 0; i < kPoints; ++i) {
    const double t = kPi * i / (kPoints - 1);
    double* p = helix.Point(i, 0, 0);
    p[0] = std::cos(t);
    p[1] = std::sin(t);
    p[2] = 0.1 * t;
  }
  splinegrid::FitOptions options;
  options.control_counts = {16, 0, 0};
  const absl::StatusOr<splinegrid::FittedBlock> fit = splinegrid::FitBlock(helix, options);
  if (!fit.ok()) {
    std::fprintf(stderr, "fit: %s\n", fit.status().ToString().c_str());
    return 1;
  }
  const splinegrid::Point3 mid = splinegrid::EvaluatePoint(fit->spline, {0.5, 0.0, 0.0});
  const double radius = std::hypot(mid[0], mid[1]);
  std::printf(
      "fit_curve: %lld points -> %lld control points, max deviation %.3g, radius at "
      "u = 0.5: %.9f\n",
      static_cast<long long>(fit->summary.num_points),
      static_cast<long long>(fit->summary.num_control_points), fit->summary.deviation.max, radius);
  const bool ok = fit->summary.num_control_points == 16 && fit->summary.deviation.max < 1e-5 &&
                  std::abs(radius - 1.0) < 1e-5;
  return ok ? 0 : 1;
}
