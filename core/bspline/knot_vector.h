// Clamped knot vectors of B-splines of order k (degree k - 1).
//
// A knot vector t_0 <= ... <= t_{n+k-1} defines n B-splines of order k. Clamped: the first k
// knots equal the start of the domain and the last k its end, so the spline interpolates its
// first and last control points. Interior knots have multiplicity at most k - 1 (the spline
// stays at least C^0). Notation follows Piegl & Tiller, The NURBS Book (2nd ed., 1997), with
// order k = p + 1.
#ifndef SPLINEGRID_CORE_BSPLINE_KNOT_VECTOR_H_
#define SPLINEGRID_CORE_BSPLINE_KNOT_VECTOR_H_

#include <span>
#include <vector>

#include "absl/status/statusor.h"

namespace splinegrid {

// Highest supported order (degree 9). Basis evaluation keeps k x k tables on the stack.
inline constexpr int kMaxOrder = 10;

// Knot placement for a least-squares fit.
enum class KnotPlacement {
  kUniform,   // equally spaced interior knots
  kAveraged,  // from the data parameters, Piegl & Tiller eq. 9.8 / 9.68-9.69
};

class KnotVector {
 public:
  // The single constant B-spline on [0, 1] (order 1, knots {0, 1}): the basis of an unused
  // direction of a tensor-product spline.
  KnotVector() : order_(1), knots_{0.0, 1.0} {}

  // Validates and wraps `knots`: order in [1, kMaxOrder], at least 2k knots, all finite and
  // non-decreasing, clamped at both ends, non-empty domain, interior multiplicity <= k - 1.
  static absl::StatusOr<KnotVector> Create(int order, std::vector<double> knots);

  // Clamped knots on [0, 1] with equally spaced interior knots.
  // Precondition: 1 <= order <= kMaxOrder, num_controls >= order.
  static KnotVector Uniform(int order, int num_controls);

  // Clamped knots on [0, 1] placed from strictly increasing data parameters u_0 = 0 < ... <
  // u_{m-1} = 1 so that every knot span holds data (Schoenberg-Whitney), which keeps the
  // least-squares problem well posed:
  //  - num_controls == m: knot averaging, P&T eq. 9.8, t_{j+k-1} = mean(u_j .. u_{j+k-2});
  //  - num_controls < m: P&T eq. 9.68-9.69, d = m / (n - k + 1), i = floor(j d),
  //    a = j d - i, t_{k-1+j} = (1 - a) u_{i-1} + a u_i, j = 1 .. n - k.
  // Errors: INVALID_ARGUMENT if the parameters are not strictly increasing on [0, 1] or
  // num_controls is outside [order, m].
  static absl::StatusOr<KnotVector> Averaged(int order, int num_controls,
                                             std::span<const double> params);

  // Averaged knots that break at data indices: at every index r of `breaks` (ascending, in
  // (0, m - 1)) a knot of multiplicity k - 1 at u_r, so the spline is only C0 there (a kink of
  // the data, e.g. the corner of a blunt trailing edge, stays a kink instead of being rounded
  // off by a C2 spline that then swings beside it). Between breaks every piece p of m_p data
  // (the data at both of its ends included) gets the Averaged knots of its own parameters,
  // rescaled to [u_first, u_last]. The pieces share one control at each break; they get
  // n_p = k + a share of the remaining controls in proportion to m_p - k (largest remainders),
  // adding up to num_controls. With num_controls == m that is n_p = m_p: every piece
  // interpolates its own data, and the whole is still the interpolation of the m data.
  // Errors: INVALID_ARGUMENT as Averaged, or if the breaks are not ascending inside (0, m - 1),
  // leave a piece of fewer than k data, or ask for more than num_controls controls (k per
  // piece, less one per break); UsableBreaks keeps the breaks that do not.
  static absl::StatusOr<KnotVector> AveragedWithBreaks(int order, int num_controls,
                                                       std::span<const double> params,
                                                       std::span<const int> breaks);
  // The greedy selection, in order, of the `candidates` (ascending data indices) that
  // AveragedWithBreaks accepts for m data: a candidate is kept when it leaves at least k data
  // to the previous kept break (or the start) and to the end, and the pieces still get k
  // controls each.
  static std::vector<int> UsableBreaks(int order, int num_controls, int m,
                                       std::span<const int> candidates);

  int order() const { return order_; }
  int degree() const { return order_ - 1; }
  int num_controls() const { return static_cast<int>(knots_.size()) - order_; }
  std::span<const double> knots() const { return knots_; }
  double knot(int i) const { return knots_[i]; }
  double domain_begin() const { return knots_[order_ - 1]; }
  double domain_end() const { return knots_[knots_.size() - order_]; }

  // The knot span mu with t_mu <= u < t_{mu+1}, in [k - 1, n - 1]; u at or beyond the end of
  // the domain gives the last non-empty span, u before it the first (P&T A2.1, binary search).
  int FindSpan(double u) const;

  // Number of knots equal to u.
  int Multiplicity(double u) const;

  // The distinct interior knots (excluding the domain ends), ascending.
  std::vector<double> InteriorBreaks() const;

  friend bool operator==(const KnotVector& a, const KnotVector& b) = default;

 private:
  KnotVector(int order, std::vector<double> knots) : order_(order), knots_(std::move(knots)) {}

  int order_;
  std::vector<double> knots_;
};

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_BSPLINE_KNOT_VECTOR_H_
