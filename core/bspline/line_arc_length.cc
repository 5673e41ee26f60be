#include "core/bspline/line_arc_length.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

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
constexpr double kUlps = 4 * std::numeric_limits<double>::epsilon();

}  // namespace

LineArcLength::LineArcLength(const TensorSpline& spline, int direction, const Point3& fixed,
                             double begin, double end) {
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
  const int s = spline.spatial_dim();
  std::vector<Point3> control(n[direction], Point3{0.0, 0.0, 0.0});
  const int e1 = direction == 0 ? 1 : 0, e2 = direction == 2 ? 1 : 2;  // the other two
  std::array<int, 3> index = {0, 0, 0};
  for (int r = 0; r < n[direction]; ++r) {
    index[direction] = r;
    for (int t2 = 0; t2 < order[e2]; ++t2) {
      for (int t1 = 0; t1 < order[e1]; ++t1) {
        const double w = basis[e1][t1] * basis[e2][t2];
        index[e1] = first[e1] + t1;
        index[e2] = first[e2] + t2;
        const double* p = spline.ControlPoint(index[0], index[1], index[2]);
        for (int c = 0; c < s; ++c) control[r][c] += w * p[c];
      }
    }
  }
  // The knot intervals inside [begin, end]; on each, dX/dt as its Taylor polynomial about the
  // interval's knot: coefficient m is X^(m+1)(knot) / m!, m < degree (exact: the curve is a
  // polynomial there).
  const KnotVector& knots = spline.knots(direction);
  const int k = knots.order();
  degree_ = k - 1;
  std::vector<double> ends = {begin};
  for (double knot : knots.knots()) {
    if (knot > begin && knot < end && knot > ends.back()) ends.push_back(knot);
  }
  ends.push_back(end);
  std::array<double, kMaxOrder * kMaxOrder> ders;
  breaks_ = {begin};
  cumulative_ = {0.0};
  for (size_t q = 1; q < ends.size() && degree_ > 0; ++q) {
    if (!(ends[q] > ends[q - 1])) continue;
    const int span = knots.FindSpan(0.5 * (ends[q - 1] + ends[q]));
    const int interval = static_cast<int>(centers_.size());
    centers_.push_back(knots.knot(span));
    BasisDerivatives(knots, span, centers_.back(), degree_, ders.data());
    double factorial = 1.0;
    for (int m = 0; m < degree_; ++m) {
      if (m > 0) factorial *= m;
      Point3 coefficient = {0.0, 0.0, 0.0};
      for (int i = 0; i < k; ++i) {
        const Point3& p = control[span - k + 1 + i];
        for (int c = 0; c < 3; ++c) coefficient[c] += ders[(m + 1) * k + i] * p[c];
      }
      for (double& c : coefficient) c /= factorial;
      coefficients_.push_back(coefficient);
    }
    // Pieces: the interval split in four.
    if (speeds_.empty()) speeds_.push_back(Speed(interval, begin));
    for (int p = 1; p <= kPiecesPerSpan; ++p) {
      const double b = p == kPiecesPerSpan
                           ? ends[q]
                           : ends[q - 1] + (ends[q] - ends[q - 1]) * p / kPiecesPerSpan;
      if (!(b > breaks_.back())) continue;
      piece_interval_.push_back(interval);
      cumulative_.push_back(cumulative_.back() + PieceLength(interval, breaks_.back(), b));
      breaks_.push_back(b);
      speeds_.push_back(Speed(interval, b));
    }
  }
  if (speeds_.empty()) speeds_.push_back(0.0);  // no pieces: a point, or a constant curve
}

double LineArcLength::Speed(int interval, double t) const {
  // Horner on the Taylor polynomial of dX/dt.
  const Point3* c = coefficients_.data() + int64_t{interval} * degree_;
  const double x = t - centers_[interval];
  Point3 d = c[degree_ - 1];
  for (int m = degree_ - 2; m >= 0; --m) {
    for (int i = 0; i < 3; ++i) d[i] = d[i] * x + c[m][i];
  }
  // The coordinates are finite and far from overflow (TensorSpline::Create, ValidateFittable).
  return std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

double LineArcLength::PieceLength(int interval, double a, double b) const {
  const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
  double sum = 0.0;
  for (int q = 0; q < 4; ++q) {
    sum += kWeights[q] *
           (Speed(interval, mid - half * kNodes[q]) + Speed(interval, mid + half * kNodes[q]));
  }
  return half * sum;
}

double LineArcLength::StepLength(int interval, double a, double b) const {
  // 3-point Gauss-Legendre: Newton's steps are short against the piece, where it is exact to
  // O(step^6).
  const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
  constexpr double kNode = 0.7745966692414834, kOuter = 5.0 / 9.0, kInner = 8.0 / 9.0;
  return half *
         (kOuter * (Speed(interval, mid - half * kNode) + Speed(interval, mid + half * kNode)) +
          kInner * Speed(interval, mid));
}

double LineArcLength::LengthAt(double t) const {
  t = std::clamp(t, breaks_.front(), breaks_.back());
  const size_t p = std::upper_bound(breaks_.begin(), breaks_.end(), t) - breaks_.begin();
  if (p >= breaks_.size()) return length();
  return cumulative_[p - 1] + PieceLength(piece_interval_[p - 1], breaks_[p - 1], t);
}

double LineArcLength::ParameterAt(double s) const {
  if (!(s > 0.0) || length() == 0.0) return breaks_.front();
  if (s >= length()) return breaks_.back();
  // The piece [breaks_[p - 1], breaks_[p]] whose lengths hold s.
  const size_t p =
      std::upper_bound(cumulative_.begin(), cumulative_.end(), s) - cumulative_.begin();
  const double a = breaks_[p - 1], b = breaks_[p];
  const int interval = piece_interval_[p - 1];
  const double base = cumulative_[p - 1], piece = cumulative_[p] - base;
  // Start: t(s) by cubic Hermite interpolation over the piece, dt/ds = 1 / speed at its ends
  // (O(piece^4) accurate where the speed is positive, else linear).
  const double x = (s - base) / piece;
  double t = a + (b - a) * x;
  if (speeds_[p - 1] > 0.0 && speeds_[p] > 0.0) {
    const double x2 = x * x, x3 = x2 * x;
    t = (2 * x3 - 3 * x2 + 1) * a + (x3 - 2 * x2 + x) * piece / speeds_[p - 1] +
        (-2 * x3 + 3 * x2) * b + (x3 - x2) * piece / speeds_[p];
    if (!(t > a && t < b)) t = a + (b - a) * x;
  }
  // Newton on g(t) = base + length(a, t) - s with g' = speed, kept inside the bracket [lo, hi]
  // (bisection when a step leaves it or the speed vanishes). g is integrated over the piece
  // once; a short step (under 1% of the piece) then updates it by the step's own length. It
  // stops when g is within a few ulps of s, below which it cannot be computed, or the step
  // within a few ulps of t.
  const double g_floor = kUlps * s;
  double lo = a, hi = b;
  double g = base + PieceLength(interval, a, t) - s;
  for (int iteration = 0; iteration < 100 && std::abs(g) > g_floor; ++iteration) {
    (g > 0.0 ? hi : lo) = t;
    const double speed = Speed(interval, t);
    double next = speed > 0.0 ? t - g / speed : 0.5 * (lo + hi);
    if (!(next >= lo && next <= hi)) next = 0.5 * (lo + hi);
    const double step = next - t;
    if (std::abs(step) <= kUlps * std::abs(t) || !(hi > lo)) return next;
    g = std::abs(step) < 1e-2 * (b - a)
            ? g + (step > 0.0 ? StepLength(interval, t, next) : -StepLength(interval, next, t))
            : base + PieceLength(interval, a, next) - s;
    t = next;
  }
  return t;
}

}  // namespace splinegrid
