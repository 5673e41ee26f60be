#include "core/fit/solve/tensor_fit.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include "absl/strings/str_cat.h"
#include "core/bspline/evaluation.h"
#include "core/fit/solve/fairing.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

constexpr char kDirectionNames[] = "ijk";

// Control count and order of direction d for `points` data points.
struct DirectionShape {
  int controls;
  int order;
};

DirectionShape ShapeOf(const FitOptions& options, const Extents& points, int d) {
  if (points[d] == 1) return {1, 1};
  const int controls = options.control_counts[d] == 0 ? points[d] : options.control_counts[d];
  return {controls, std::min(options.order, controls)};
}

// out[p] = |a_p - b_p|^2 for points of S interleaved coordinates.
template <int S>
void SquaredDistances(const double* __restrict a, const double* __restrict b, int64_t count,
                      double* __restrict out) {
  for (int64_t p = 0; p < count; ++p) {
    double sq = 0.0;
    for (int c = 0; c < S; ++c) sq += (a[S * p + c] - b[S * p + c]) * (a[S * p + c] - b[S * p + c]);
    out[p] = sq;
  }
}

}  // namespace

absl::Status ValidateControlCounts(const Extents& counts, int order, const Extents& points,
                                   const std::string& field, const std::string& block) {
  for (int d = 0; d < 3; ++d) {
    const int n = counts[d], m = points[d];
    const std::string name = absl::StrCat(field, "[", d, "] = ", n);
    const std::string dir(1, kDirectionNames[d]);
    if (n < 0) return absl::InvalidArgumentError(absl::StrCat(name, " is negative"));
    if (m == 1) {
      if (n > 1) {
        return absl::InvalidArgumentError(absl::StrCat(name, " but ", block,
                                                       " has a single point in ", dir,
                                                       " (direction ", dir, "); use 0 or 1"));
      }
      continue;
    }
    if (n == 0) continue;
    if (n == 1) {
      return absl::InvalidArgumentError(absl::StrCat(name, " is below 2: ", block, " has ", m,
                                                     " points in ", dir,
                                                     ", and a direction of several points needs "
                                                     "at least 2 control points"));
    }
    if (n > m) {
      return absl::InvalidArgumentError(absl::StrCat(name, " exceeds the ", m, " points of ", block,
                                                     " in ", dir, "; give at most ", m,
                                                     " (0: as many as points)"));
    }
    // A direction of order k needs k controls, unless it has fewer points than k: then it
    // interpolates them at order m (the only fit there is; see FitOptions::order).
    const int least = std::min(std::max(order, 2), m);
    if (n < least) {
      return absl::InvalidArgumentError(absl::StrCat(
          name, " is below order = ", order, ": a B-spline of order k needs at least k control ",
          "points per direction; give at least ", least, " (", block, " has ", m, " points in ",
          dir, "), or order <= ", n));
    }
  }
  return absl::OkStatus();
}

absl::Status FitOptions::Validate(const Extents& points) const {
  if (order < 2 || order > kMaxOrder) {
    return absl::InvalidArgumentError(
        absl::StrCat("order = ", order, " is outside [2, ", kMaxOrder, "]"));
  }
  SG_RETURN_IF_ERROR(ValidateParametrization(parametrization));
  if (!(fairing >= 0.0) || !std::isfinite(fairing)) {
    return absl::InvalidArgumentError(
        absl::StrCat("fairing = ", fairing, " is not a finite number >= 0"));
  }
  for (int d = 0; d < 3; ++d) {
    if (breaks[d].empty()) continue;
    if (knot_placement != KnotPlacement::kAveraged) {
      return absl::InvalidArgumentError(absl::StrCat("breaks[", d, "] has ", breaks[d].size(),
                                                     " breaks; breaks need averaged knots"));
    }
    for (size_t q = 0; q < breaks[d].size(); ++q) {
      const int r = breaks[d][q];
      if (r < 1 || r > points[d] - 2 || (q > 0 && r <= breaks[d][q - 1])) {
        return absl::InvalidArgumentError(
            absl::StrCat("breaks[", d, "][", q, "] = ", r, " is not ascending inside [1, ",
                         points[d] - 2, "] (the block has ", points[d], " points in ",
                         std::string(1, kDirectionNames[d]), ")"));
      }
    }
  }
  return ValidateControlCounts(control_counts, order, points, "control_counts", "the block");
}

absl::StatusOr<TensorSpline> FitTensor(const StructuredBlock& block,
                                       const std::array<std::vector<double>, 3>& params,
                                       const std::array<KnotVector, 3>& knots, EndCondition ends,
                                       const CancelCheck& cancel, const DirectionPins& pins,
                                       double fairing) {
  const Extents& m = block.extents();
  std::vector<DirectionFit> fits;
  fits.reserve(3);
  for (int d = 0; d < 3; ++d) {
    if (static_cast<int>(params[d].size()) != m[d]) {
      return absl::InvalidArgumentError(absl::StrCat("direction ", d, ": ", params[d].size(),
                                                     " parameters for ", m[d], " points"));
    }
    const std::vector<PenaltyRow> penalties = JumpPenaltyRows(knots[d], params[d], fairing);
    SG_ASSIGN_OR_RETURN(DirectionFit fit,
                        DirectionFit::Create(knots[d], params[d], ends, pins[d], penalties),
                        "direction ", std::string(1, kDirectionNames[d]), ": ");
    fits.push_back(std::move(fit));
  }
  // Pass d fits direction d of a tensor whose already fitted directions hold control values:
  // shape (s * cur_0 .. cur_{d-1}, m_d, cur_{d+1} .. cur_2) -> n_d. The slowest direction goes
  // first: its lines are whole contiguous rows of the data, and it shrinks the data the most
  // before the strided passes.
  const int s = block.spatial_dim();
  Extents cur = m;
  std::unique_ptr<double[]> current;  // output of the previous pass (fully overwritten)
  std::vector<double> control;        // output of the last pass
  const double* in = block.coords().data();
  for (int d = 2; d >= 0; --d) {
    // A direction with one point and one control is the identity: no pass, no copy.
    if (m[d] == 1 && knots[d].num_controls() == 1 && d > 0) continue;
    int64_t a = s, b = 1;
    for (int e = 0; e < d; ++e) a *= cur[e];
    for (int e = d + 1; e < 3; ++e) b *= cur[e];
    cur[d] = knots[d].num_controls();
    const int64_t size = a * cur[d] * b;
    double* out;
    std::unique_ptr<double[]> next;
    if (d > 0) {
      next.reset(new double[size]);
      out = next.get();
    } else {
      control.resize(size);
      out = control.data();
    }
    SG_RETURN_IF_ERROR(fits[d].Apply(in, a, b, out, cancel));
    current = std::move(next);
    in = out;
  }
  std::array<KnotVector, 3> all = knots;
  return TensorSpline::Create(std::move(all), s, std::move(control));
}

absl::StatusOr<Deviation> MeasureDeviation(const TensorSpline& spline,
                                           const std::array<std::vector<double>, 3>& params,
                                           const StructuredBlock& block, const CancelCheck& cancel,
                                           std::span<const double> tolerance) {
  GridEvaluator evaluator(spline, params, /*first_derivatives=*/false);
  if (evaluator.extents() != block.extents() || spline.spatial_dim() != block.spatial_dim()) {
    return absl::InvalidArgumentError("spline parameters and data block differ in shape");
  }
  if (!tolerance.empty() && static_cast<int64_t>(tolerance.size()) != block.num_points()) {
    return absl::InvalidArgumentError("tolerance: one value per point is needed");
  }
  double max_ratio_squared = -1.0;
  const int s = block.spatial_dim();
  const int ni = block.extent(0), nj = block.extent(1);
  // Lines are evaluated in batches (about 32k points) and compared with the data; the squared
  // distances of a batch go to a buffer so that the sums vectorise.
  const int64_t batch = std::max<int64_t>(1, 32768 / ni);
  std::vector<double> fitted(batch * evaluator.line_size()), d2(batch * ni);
  Deviation dev;
  dev.num_points = block.num_points();
  double sum_squares = 0.0, max_squared = -1.0;
  for (int64_t l0 = 0; l0 < evaluator.num_lines(); l0 += batch) {
    SG_RETURN_IF_ERROR(PollCancel(cancel));
    const int64_t l1 = std::min(l0 + batch, evaluator.num_lines());
    const int64_t count = (l1 - l0) * ni;
    evaluator.EvaluateLines(l0, l1, fitted.data());
    const double* data = block.coords().data() + l0 * evaluator.line_size();
    if (s == 2) {
      SquaredDistances<2>(fitted.data(), data, count, d2.data());
    } else {
      SquaredDistances<3>(fitted.data(), data, count, d2.data());
    }
    // Eight independent partial sums and maxima: the reductions vectorise.
    double partial_sum[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    double partial_max[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    int64_t p = 0;
    for (; p + 8 <= count; p += 8) {
      for (int t = 0; t < 8; ++t) {
        partial_sum[t] += d2[p + t];
        partial_max[t] = partial_max[t] > d2[p + t] ? partial_max[t] : d2[p + t];
      }
    }
    for (; p < count; ++p) {
      partial_sum[0] += d2[p];
      partial_max[0] = std::max(partial_max[0], d2[p]);
    }
    double batch_max = 0.0;
    for (int t = 0; t < 8; ++t) {
      sum_squares += partial_sum[t];
      batch_max = std::max(batch_max, partial_max[t]);
    }
    auto index_of = [&](int64_t at) -> Extents {
      const int64_t line = l0 + at / ni;
      return {static_cast<int>(at % ni), static_cast<int>(line % nj), static_cast<int>(line / nj)};
    };
    if (batch_max > max_squared) {
      max_squared = batch_max;
      dev.max_at = index_of(std::find(d2.begin(), d2.begin() + count, batch_max) - d2.begin());
    }
    if (!tolerance.empty()) {
      const double* tol = tolerance.data() + l0 * ni;
      for (int64_t q = 0; q < count; ++q) {
        const double r2 = d2[q] / (tol[q] * tol[q]);
        if (r2 > max_ratio_squared) {
          max_ratio_squared = r2;
          dev.max_ratio_at = index_of(q);
        }
      }
    }
  }
  dev.max = std::sqrt(std::max(max_squared, 0.0));
  dev.max_ratio = std::sqrt(std::max(max_ratio_squared, 0.0));
  dev.rms = std::sqrt(sum_squares / static_cast<double>(dev.num_points));
  return dev;
}

absl::StatusOr<FittedBlock> FitBlock(const StructuredBlock& block, const FitOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const Extents& m = block.extents();
  SG_RETURN_IF_ERROR(options.Validate(m));
  const std::array<std::vector<double>, 3> params =
      ParametrizeBlock(block, options.parametrization);
  std::array<KnotVector, 3> knots;
  for (int d = 0; d < 3; ++d) {
    const DirectionShape shape = ShapeOf(options, m, d);
    if (m[d] == 1) continue;  // default KnotVector: the constant basis
    if (options.knot_placement == KnotPlacement::kUniform) {
      knots[d] = KnotVector::Uniform(shape.order, shape.controls);
    } else {
      const std::vector<int> breaks =
          KnotVector::UsableBreaks(shape.order, shape.controls, m[d], options.breaks[d]);
      SG_ASSIGN_OR_RETURN(
          knots[d], KnotVector::AveragedWithBreaks(shape.order, shape.controls, params[d], breaks));
    }
  }
  const EndCondition ends =
      options.interpolate_ends ? EndCondition::kInterpolate : EndCondition::kFree;
  // Non-finite points are found without a pass of their own: every point reaches some control
  // point with a nonzero weight (A^+ e_r != 0 for a nonzero row r of A), and NaN or Inf
  // survives the rotations, so the fitted net is non-finite exactly when a point is. Only then
  // is the block scanned, for an error that names the point.
  absl::StatusOr<TensorSpline> fit =
      FitTensor(block, params, knots, ends, options.cancel, {}, options.fairing);
  if (!fit.ok() && fit.status().code() == absl::StatusCode::kInvalidArgument) {
    SG_RETURN_IF_ERROR(ValidateFinite(block, "points"));
  }
  SG_ASSIGN_OR_RETURN(TensorSpline spline, std::move(fit));
  SG_ASSIGN_OR_RETURN(Deviation deviation, MeasureDeviation(spline, params, block, options.cancel));
  SG_ASSIGN_OR_RETURN(PointDistribution distribution, PointDistribution::Create(params));

  FittedBlock fitted{std::move(spline), std::move(distribution), {}};
  FitSummary& summary = fitted.summary;
  summary.deviation = deviation;
  summary.num_points = block.num_points();
  summary.num_control_points = fitted.spline.num_control_points();
  summary.compression_ratio = static_cast<double>(summary.num_points) / summary.num_control_points;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return fitted;
}

}  // namespace splinegrid
