#include "core/bspline/line_arc_length.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/bspline/basis.h"
#include "core/util/check.h"

namespace splinegrid {
namespace {

// 8-point Gauss-Legendre nodes and weights on [-1, 1] (Abramowitz & Stegun, table 25.4).
constexpr std::array<double, 4> kNodes = {0.1834346424956498, 0.5255324099163290,
                                          0.7966664774136267, 0.9602898564975363};
constexpr std::array<double, 4> kWeights = {0.3626837833783620, 0.3137066458778873,
                                            0.2223810344533745, 0.1012285362903763};
constexpr int kPiecesPerSpan = 4;

}  // namespace

LineArcLength::LineArcLength(const TensorSpline& spline, int direction, const Point3& fixed,
                             double begin, double end)
    : knots_(spline.knots(direction)), spatial_dim_(spline.spatial_dim()) {
  SG_CHECK(direction >= 0 && direction < 3 && 0.0 <= begin && begin <= end && end <= 1.0);
  // The other two directions' nonzero basis functions at `fixed`.
  const Extents n = spline.control_extents();
  std::array<int, 3> first = {0, 0, 0}, order = {1, 1, 1};
  std::array<std::array<double, kMaxOrder>, 3> basis{};
  for (int e = 0; e < 3; ++e) {
    if (e == direction) continue;
    const KnotVector& knots = spline.knots(e);
    const double u = std::clamp(fixed[e], 0.0, 1.0);
    const int span = knots.FindSpan(u);
    order[e] = knots.order();
    first[e] = span - knots.order() + 1;
    BasisFunctions(knots, span, u, basis[e].data());
  }
  // Control point r of the curve: the other directions contracted at `fixed`.
  const int s = spatial_dim_;
  control_.assign(int64_t{s} * n[direction], 0.0);
  const int e1 = direction == 0 ? 1 : 0, e2 = direction == 2 ? 1 : 2;  // the other two
  std::array<int, 3> index = {0, 0, 0};
  for (int r = 0; r < n[direction]; ++r) {
    index[direction] = r;
    double* q = control_.data() + int64_t{s} * r;
    for (int t2 = 0; t2 < order[e2]; ++t2) {
      for (int t1 = 0; t1 < order[e1]; ++t1) {
        const double w = basis[e1][t1] * basis[e2][t2];
        index[e1] = first[e1] + t1;
        index[e2] = first[e2] + t2;
        const double* p = spline.ControlPoint(index[0], index[1], index[2]);
        for (int c = 0; c < s; ++c) q[c] += w * p[c];
      }
    }
  }
  // Pieces: the knot spans inside [begin, end], each split in four.
  std::vector<double> ends = {begin};
  for (double knot : knots_.knots()) {
    if (knot > begin && knot < end && knot > ends.back()) ends.push_back(knot);
  }
  ends.push_back(end);
  breaks_ = {begin};
  cumulative_ = {0.0};
  for (size_t q = 1; q < ends.size(); ++q) {
    for (int p = 1; p <= kPiecesPerSpan; ++p) {
      const double b = p == kPiecesPerSpan
                           ? ends[q]
                           : ends[q - 1] + (ends[q] - ends[q - 1]) * p / kPiecesPerSpan;
      if (!(b > breaks_.back())) continue;
      cumulative_.push_back(cumulative_.back() + PieceLength(breaks_.back(), b));
      breaks_.push_back(b);
    }
  }
}

double LineArcLength::Speed(double t) const {
  const int k = knots_.order();
  const int span = knots_.FindSpan(t);
  std::array<double, 2 * kMaxOrder> ders;
  BasisDerivatives(knots_, span, t, 1, ders.data());
  Point3 d = {0.0, 0.0, 0.0};
  for (int i = 0; i < k; ++i) {
    const double* p = control_.data() + int64_t{spatial_dim_} * (span - k + 1 + i);
    for (int c = 0; c < spatial_dim_; ++c) d[c] += ders[k + i] * p[c];
  }
  return std::hypot(d[0], d[1], d[2]);
}

double LineArcLength::PieceLength(double a, double b) const {
  const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
  double sum = 0.0;
  for (int q = 0; q < 4; ++q) {
    sum += kWeights[q] * (Speed(mid - half * kNodes[q]) + Speed(mid + half * kNodes[q]));
  }
  return half * sum;
}

double LineArcLength::LengthAt(double t) const {
  t = std::clamp(t, breaks_.front(), breaks_.back());
  const size_t p = std::upper_bound(breaks_.begin(), breaks_.end(), t) - breaks_.begin();
  if (p >= breaks_.size()) return length();
  return cumulative_[p - 1] + PieceLength(breaks_[p - 1], t);
}

double LineArcLength::ParameterAt(double s) const {
  if (!(s > 0.0) || length() == 0.0) return breaks_.front();
  if (s >= length()) return breaks_.back();
  // The piece [breaks_[p - 1], breaks_[p]] whose lengths hold s.
  const size_t p =
      std::upper_bound(cumulative_.begin(), cumulative_.end(), s) - cumulative_.begin();
  double lo = breaks_[p - 1], hi = breaks_[p];
  const double base = cumulative_[p - 1], piece = cumulative_[p] - base;
  // Newton on g(t) = base + PieceLength(breaks_[p - 1], t) - s, g' = speed, kept inside the
  // bracket [lo, hi] (bisection when a step leaves it or the speed vanishes).
  double t = lo + (hi - lo) * (s - base) / piece;
  for (int iteration = 0; iteration < 60; ++iteration) {
    const double g = base + PieceLength(breaks_[p - 1], t) - s;
    if (g == 0.0) return t;
    (g > 0.0 ? hi : lo) = t;
    const double speed = Speed(t);
    double next = speed > 0.0 ? t - g / speed : lo;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - t) <= 1e-15 * (breaks_[p] - breaks_[p - 1]) || hi - lo <= 0.0) {
      return next;
    }
    t = next;
  }
  return t;
}

}  // namespace splinegrid
