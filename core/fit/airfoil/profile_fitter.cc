// ProfileFitter and the curve evaluation it shares with the curvature judgement
// (profile_fitter.h).
#include "core/fit/airfoil/profile_fitter.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "core/bspline/basis.h"
#include "core/fit/solve/fairing.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

// Projection: Newton stops when the parameter step is below kFootTolerance (the domain is
// [0, 1]) or after kMaxNewtonSteps; from the previous foot 2-4 steps are typical.
constexpr double kFootTolerance = 1e-13;
constexpr int kMaxNewtonSteps = 12;
// Parameter correction stops when a round reduces the sum of squared distances by less than
// this fraction. Hoschek's iteration converges linearly: a few rounds take most of the gain,
// then the parameters drift along the curve for little (0.2% over 100 rounds on RAE 2822).
constexpr double kSettledGain = 1e-2;

}  // namespace

void EvaluateJet(const Curve& curve, std::span<const double> u, int max_derivative,
                 std::vector<double>& out) {
  const SampledBasis basis = SampleBasis(curve.knots, u, max_derivative);
  const int k = curve.knots.order();
  out.assign(u.size() * (max_derivative + 1) * 2, 0.0);
  for (int q = 0; q < basis.num_samples(); ++q) {
    const double* p = curve.control.data() + 2 * basis.first[q];
    for (int d = 0; d <= max_derivative; ++d) {
      const double* row = basis.Row(q, d);
      double* o = out.data() + (q * (max_derivative + 1) + d) * 2;
      for (int t = 0; t < k; ++t) {
        o[0] += row[t] * p[2 * t];
        o[1] += row[t] * p[2 * t + 1];
      }
    }
  }
}

double JetCurvature(const double* x) {
  const double speed = std::hypot(x[2], x[3]);
  return speed > 0.0 ? (x[2] * x[5] - x[3] * x[4]) / (speed * speed * speed) : 0.0;
}

ProfileFitter::ProfileFitter(std::vector<double> fit_data, std::vector<double> data, int order,
                             const std::vector<int>& features, int max_corrections,
                             const CancelCheck& cancel)
    : fit_data_(std::move(fit_data)),
      data_(std::move(data)),
      m_(static_cast<int>(data_.size() / 2)),
      order_(order),
      max_corrections_(max_corrections),
      cancel_(cancel) {
  anchors_.push_back(0);
  anchors_.insert(anchors_.end(), features.begin(), features.end());
  anchors_.push_back(m_ - 1);
  segment_.resize(m_);
  for (size_t a = 0; a + 1 < anchors_.size(); ++a) {
    for (int i = anchors_[a]; i < anchors_[a + 1]; ++i) segment_[i] = static_cast<int>(a);
  }
  segment_[m_ - 1] = static_cast<int>(anchors_.size()) - 2;
}

absl::StatusOr<KnotVector> ProfileFitter::Knots(const std::vector<double>& interior) const {
  std::vector<double> t(order_, 0.0);
  t.insert(t.end(), interior.begin(), interior.end());
  t.insert(t.end(), order_, 1.0);
  return KnotVector::Create(order_, std::move(t));
}

std::vector<Pin> ProfileFitter::FeaturePins(const KnotVector& knots,
                                            std::span<const double> params) const {
  std::vector<Pin> pins;
  for (size_t a = 1; a + 1 < anchors_.size(); ++a) {
    const int r = anchors_[a];
    pins.push_back({knots.FindSpan(params[r]) - order_ + 1, r});
  }
  return pins;
}

bool ProfileFitter::WellPosed(const KnotVector& knots, std::span<const double> params) const {
  std::vector<int> pinned = {0, knots.num_controls() - 1};
  for (const Pin& pin : FeaturePins(knots, params)) pinned.push_back(pin.control);
  return SchoenbergWhitneyHolds(knots, params, pinned);
}

bool ProfileFitter::WellPosed(const std::vector<double>& interior,
                              std::span<const double> params) const {
  const absl::StatusOr<KnotVector> knots = Knots(interior);
  return knots.ok() && WellPosed(*knots, params);
}

absl::StatusOr<Curve> ProfileFitter::Fit(const std::vector<double>& interior,
                                         const Penalty& penalty, std::vector<double>& params,
                                         int max_rounds) {
  SG_ASSIGN_OR_RETURN(KnotVector knots, Knots(interior));
  Curve curve{knots, std::vector<double>(2 * knots.num_controls())};
  const std::vector<Pin> pins = FeaturePins(knots, params);
  double previous = std::numeric_limits<double>::infinity();  // sum of squared distances
  for (int round = 0;; ++round) {
    SG_RETURN_IF_ERROR(PollCancel(cancel_));
    std::vector<PenaltyRow> rows = JumpPenaltyRows(knots, params, penalty.lambda);
    if (penalty.row_scale.size() == rows.size()) {
      for (size_t q = 0; q < rows.size(); ++q) {
        for (double& v : rows[q].values) v *= penalty.row_scale[q];
      }
    }
    SG_ASSIGN_OR_RETURN(
        DirectionFit fit,
        DirectionFit::Create(knots, params, EndCondition::kInterpolate, pins, rows));
    SG_RETURN_IF_ERROR(fit.Apply(fit_data_.data(), 2, 1, curve.control.data()));
    ++fits_;
    if (round >= std::min(max_rounds, max_corrections_)) break;
    std::vector<double> next = params, distance;
    Project(curve, next, &distance);
    if (max_focal_ratio_ < std::numeric_limits<double>::infinity()) {
      KeepRegularFeet(curve, params, distance, next);
    }
    if (!KeepOrder(params, next) || !WellPosed(knots, next)) break;
    params = std::move(next);
    double sum = 0.0;
    for (double d : distance) sum += d * d;
    if (!(sum < (1.0 - kSettledGain) * previous)) break;
    previous = sum;
  }
  return curve;
}

void ProfileFitter::Project(const Curve& curve, std::vector<double>& u,
                            std::vector<double>* distance) const {
  const KnotVector& knots = curve.knots;
  const int k = knots.order();
  std::array<double, 3 * kMaxOrder> ders;
  if (distance != nullptr) distance->resize(m_);
  for (int i = 0; i < m_; ++i) {
    const int s = segment_[i];
    const bool anchor = i == anchors_[s] || i == m_ - 1;
    const double lo = u[anchors_[s]], hi = u[anchors_[s + 1]];
    double t = u[i], best = std::numeric_limits<double>::infinity(), best_t = t;
    for (int step = 0; step < kMaxNewtonSteps; ++step) {
      const int span = knots.FindSpan(t);
      BasisDerivatives(knots, span, t, 2, ders.data());
      double x[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};  // C, C', C''
      for (int j = 0; j < k; ++j) {
        const double* p = curve.control.data() + 2 * (span - k + 1 + j);
        for (int d = 0; d < 3; ++d) {
          x[2 * d] += ders[d * k + j] * p[0];
          x[2 * d + 1] += ders[d * k + j] * p[1];
        }
      }
      const double rx = x[0] - data_[2 * i], ry = x[1] - data_[2 * i + 1];
      const double dist = std::sqrt(rx * rx + ry * ry);
      if (dist < best) best = dist, best_t = t;
      if (anchor) break;
      const double speed2 = x[2] * x[2] + x[3] * x[3];
      double slope = speed2 + rx * x[4] + ry * x[5];
      if (!(slope > 0.0)) slope = speed2;  // not convex here: a gradient step
      if (!(slope > 0.0)) break;
      const double next = std::clamp(t - (rx * x[2] + ry * x[3]) / slope, lo, hi);
      if (std::abs(next - t) <= kFootTolerance) break;
      t = next;
    }
    u[i] = best_t;
    if (distance != nullptr) (*distance)[i] = best;
  }
}

void ProfileFitter::KeepRegularFeet(const Curve& curve, const std::vector<double>& old,
                                    const std::vector<double>& distance,
                                    std::vector<double>& next) const {
  std::vector<double> jet;
  EvaluateJet(curve, next, 2, jet);
  for (int i = 0; i < m_; ++i) {
    if (std::abs(JetCurvature(jet.data() + 6 * i)) * distance[i] > max_focal_ratio_) {
      next[i] = old[i];
    }
  }
}

bool ProfileFitter::KeepOrder(const std::vector<double>& old, std::vector<double>& next) const {
  for (int i = 1; i + 1 < m_; ++i) {
    if (!(next[i] > next[i - 1]) || !(next[i] < next[i + 1])) next[i] = old[i];
  }
  for (int i = 1; i < m_; ++i) {
    if (!(next[i] > next[i - 1])) return false;
  }
  return true;
}

absl::StatusOr<Fitted> FitAndMeasure(ProfileFitter& fitter, const std::vector<double>& interior,
                                     const Penalty& penalty, std::vector<double> params,
                                     int max_rounds) {
  SG_ASSIGN_OR_RETURN(Curve curve, fitter.Fit(interior, penalty, params, max_rounds));
  Fitted out{std::move(curve), std::move(params), {}, {}, penalty.lambda};
  out.feet = out.params;
  fitter.Project(out.curve, out.feet, &out.distances);
  return out;
}

}  // namespace splinegrid
