#include "core/bspline/evaluation.h"

#include <algorithm>

#include "core/bspline/contraction.h"
#include "core/util/check.h"

namespace splinegrid {
namespace {

// Span and derivatives of the basis of every direction at one parameter point.
struct LocalBasis {
  int first[3];
  int order[3];
  double ders[3][(kMaxOrder)*kMaxOrder];  // [d * order + t], d <= max_order < kMaxOrder
};

LocalBasis ComputeLocalBasis(const TensorSpline& spline, const Point3& uvw, int max_order) {
  LocalBasis local;
  for (int d = 0; d < 3; ++d) {
    const KnotVector& kv = spline.knots(d);
    const double u = std::clamp(uvw[d], kv.domain_begin(), kv.domain_end());
    const int span = kv.FindSpan(u);
    local.first[d] = span - kv.order() + 1;
    local.order[d] = kv.order();
    BasisDerivatives(kv, span, u, max_order, local.ders[d]);
  }
  return local;
}

}  // namespace

Point3 EvaluatePoint(const TensorSpline& spline, const Point3& uvw) {
  return EvaluateDerivatives(spline, uvw, 0)(0, 0, 0);
}

PartialDerivatives EvaluateDerivatives(const TensorSpline& spline, const Point3& uvw,
                                       int max_order) {
  SG_CHECK(max_order >= 0 && max_order < kMaxOrder);
  const LocalBasis b = ComputeLocalBasis(spline, uvw, max_order);
  const int s = spline.spatial_dim();
  PartialDerivatives result(max_order);
  for (int dc = 0; dc <= max_order; ++dc) {
    for (int db = 0; db <= max_order; ++db) {
      for (int da = 0; da <= max_order; ++da) {
        Point3 sum = {0.0, 0.0, 0.0};
        for (int tc = 0; tc < b.order[2]; ++tc) {
          const double wc = b.ders[2][dc * b.order[2] + tc];
          if (wc == 0.0) continue;
          for (int tb = 0; tb < b.order[1]; ++tb) {
            const double wbc = wc * b.ders[1][db * b.order[1] + tb];
            if (wbc == 0.0) continue;
            for (int ta = 0; ta < b.order[0]; ++ta) {
              const double w = wbc * b.ders[0][da * b.order[0] + ta];
              const double* p =
                  spline.ControlPoint(b.first[0] + ta, b.first[1] + tb, b.first[2] + tc);
              for (int c = 0; c < s; ++c) sum[c] += w * p[c];
            }
          }
        }
        result(da, db, dc) = sum;
      }
    }
  }
  return result;
}

GridEvaluator::GridEvaluator(const TensorSpline& spline,
                             const std::array<std::vector<double>, 3>& params,
                             bool first_derivatives)
    : spatial_dim_(spline.spatial_dim()), derivatives_(first_derivatives) {
  for (int d = 0; d < 3; ++d) {
    SG_CHECK(!params[d].empty());
    extents_[d] = static_cast<int>(params[d].size());
  }
  const int deriv = first_derivatives ? 1 : 0;
  n_v_ = spline.knots(1).num_controls();
  n_w_ = spline.knots(2).num_controls();
  if (n_v_ == 1 && n_w_ == 1 && num_lines() == 1) {
    curve_ = true;
    knots_u_ = spline.knots(0);
    params_u_ = params[0];
    control_.assign(spline.control().begin(), spline.control().end());
    return;
  }
  const SampledBasis basis_u = SampleBasis(spline.knots(0), params[0], deriv);
  basis_v_ = SampleBasis(spline.knots(1), params[1], deriv);
  basis_w_ = SampleBasis(spline.knots(2), params[2], deriv);
  const int64_t s = spatial_dim_, ni = extents_[0];
  y_.resize(s * ni * n_v_ * n_w_);
  ContractDirection(spline.control().data(), s, int64_t{n_v_} * n_w_, basis_u, 0, y_.data());
  z_.resize(s * ni * n_v_);
  if (derivatives_) {
    y_du_.resize(y_.size());
    ContractDirection(spline.control().data(), s, int64_t{n_v_} * n_w_, basis_u, 1, y_du_.data());
    z_du_.resize(z_.size());
    z_dw_.resize(z_.size());
  }
}

void GridEvaluator::ComputePlane(int k) {
  // Z = sum_t L_t(w_k) Y(., ., first + t): planes of Y are contiguous (length s n_u' n_v).
  const int64_t plane = int64_t{spatial_dim_} * extents_[0] * n_v_;
  const int order = basis_w_.order;
  const double* rows[kMaxOrder];
  const double* first = y_.data() + plane * basis_w_.first[k];
  for (int t = 0; t < order; ++t) rows[t] = first + plane * t;
  WeightedRowSum(rows, basis_w_.Row(k, 0), order, plane, z_.data());
  if (derivatives_) {
    WeightedRowSum(rows, basis_w_.Row(k, 1), order, plane, z_dw_.data());
    const double* first_du = y_du_.data() + plane * basis_w_.first[k];
    for (int t = 0; t < order; ++t) rows[t] = first_du + plane * t;
    WeightedRowSum(rows, basis_w_.Row(k, 0), order, plane, z_du_.data());
  }
  plane_ = k;
}

void GridEvaluator::EvaluateCurve(int i_begin, int i_end, double* points, double* du, double* dv,
                                  double* dw) const {
  constexpr int kChunk = 4096;
  const int s = spatial_dim_;
  for (int q0 = i_begin; q0 < i_end; q0 += kChunk) {
    const int count = std::min(kChunk, i_end - q0);
    const int64_t at = int64_t{s} * (q0 - i_begin);
    const SampledBasis basis = SampleBasis(
        knots_u_, std::span<const double>(params_u_.data() + q0, count), derivatives_ ? 1 : 0);
    ContractDirection(control_.data(), s, 1, basis, 0, points + at);
    if (derivatives_) {
      ContractDirection(control_.data(), s, 1, basis, 1, du + at);
      std::fill_n(dv + at, int64_t{s} * count, 0.0);
      std::fill_n(dw + at, int64_t{s} * count, 0.0);
    }
  }
}

void GridEvaluator::EvaluateLines(int64_t begin, int64_t end, double* points, double* du,
                                  double* dv, double* dw) {
  SG_CHECK(begin >= 0 && begin <= end && end <= num_lines());
  const int64_t size = line_size();
  auto at = [&](double* p, int64_t line) { return p ? p + (line - begin) * size : nullptr; };
  for (int64_t line = begin; line < end; ++line) {
    EvaluateLineRange(line, 0, extents_[0], at(points, line), at(du, line), at(dv, line),
                      at(dw, line));
  }
}

void GridEvaluator::EvaluateLineRange(int64_t line, int i_begin, int i_end, double* points,
                                      double* du, double* dv, double* dw) {
  SG_CHECK(line >= 0 && line < num_lines() && 0 <= i_begin && i_begin <= i_end &&
           i_end <= extents_[0]);
  SG_CHECK(!derivatives_ || (du && dv && dw));
  if (curve_) return EvaluateCurve(i_begin, i_end, points, du, dv, dw);
  const int64_t row = line_size();
  const int64_t first = int64_t{spatial_dim_} * i_begin;
  const int64_t length = int64_t{spatial_dim_} * (i_end - i_begin);
  const int order = basis_v_.order;
  const double* rows[kMaxOrder];
  auto gather = [&](const std::vector<double>& z, int j) {
    const double* start = z.data() + row * basis_v_.first[j] + first;
    for (int t = 0; t < order; ++t) rows[t] = start + row * t;
  };
  const int j = static_cast<int>(line % extents_[1]);
  const int k = static_cast<int>(line / extents_[1]);
  if (k != plane_) ComputePlane(k);
  gather(z_, j);
  WeightedRowSum(rows, basis_v_.Row(j, 0), order, length, points);
  if (!derivatives_) return;
  WeightedRowSum(rows, basis_v_.Row(j, 1), order, length, dv);
  gather(z_du_, j);
  WeightedRowSum(rows, basis_v_.Row(j, 0), order, length, du);
  gather(z_dw_, j);
  WeightedRowSum(rows, basis_v_.Row(j, 0), order, length, dw);
}

StructuredBlock EvaluateGrid(const TensorSpline& spline,
                             const std::array<std::vector<double>, 3>& params) {
  GridEvaluator evaluator(spline, params, /*first_derivatives=*/false);
  StructuredBlock block(evaluator.extents(), spline.spatial_dim());
  evaluator.EvaluateLines(0, evaluator.num_lines(), block.coords().data());
  return block;
}

}  // namespace splinegrid
