#include "core/generate/elliptic.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/bspline/evaluation.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/generate/offset_march.h"
#include "core/grid/sampling.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

// |phi|, |psi| at most this (neighbour weights e^3 = 20 apart); reached only at a few points by
// the seam, where the algebraic grid's lines fan out from a trailing-edge corner.
constexpr double kMaxControl = 3.0;

// Multigrid cycles: one fine sweep before and after the coarse level's correction (the line
// relaxation already damps what the coarse level cannot see, and a coarse sweep costs a quarter
// of a fine one); on the coarse level, at least kCoarsestPoints x kCoarsestLayers points, sweeps
// until one moves no point by the tolerance, at most kCoarsestSweeps.
constexpr int kCoarsestSweeps = 20;
constexpr int kCoarsestPoints = 17;
constexpr int kCoarsestLayers = 9;
// Levels, the finest included: two. V-cycles over 3-5 levels diverged on the coarser ones (on
// 33 x 17 points and below the held boundary layer is one or two layers, and the corrected
// coarse grids folded) or stalled; one coarse level already gives 12-19x at 1e-3.
constexpr int kMaxLevels = 2;
// Cycles without a new low of the largest fine move: the cycles have stalled (seen when the
// first free layer is a thin wall layer, which the coarse level cannot resolve: RAE 2822 65 x 33
// with a 1e-3 first layer and only the wall held) and the rest is relaxation alone from the
// initial grid, which converges there.
constexpr int kStallCycles = 20;
// Over-relaxation (omega 1.3) can keep points by a sharp trailing edge's seam from settling: on
// the RAE 2822 with 320 or more layers they jumped by 10-1000 times their spacing for 20,000
// sweeps on both levels (277 s at 512 layers, never converged), where omega 1 converges in
// 700-850 coarse sweeps. So when the largest move has not fallen to a new low for
// kStallSweeps sweeps, or a move is not finite, the iteration starts again from the initial grid
// with omega times kRelaxationBackoff, down to kMinRelaxation (stalled cycles first go on as
// relaxation alone, as above); a stall there ends it, not converged, with the iterate nearest
// convergence (BestIterate; the 30P30N slat at 256 and 512 layers: points in the cove collapse
// at any omega; it went on for 20,000 sweeps, 74 s at 256, and at 512 its last iterate had 122
// folded cells). A converging run makes a new low nearly every sweep (the slow far-field mode
// too).
constexpr int kStallSweeps = 50;
constexpr double kRelaxationBackoff = 0.75;
constexpr double kMinRelaxation = 0.5;

// B(z) = z / (e^z - 1), B(0) = 1: the weights of the exponentially fitted (Allen-Southwell,
// Il'in) difference of x'' + c x': B(c) x_{i-1} + B(-c) x_{i+1} - (B(c) + B(-c)) x_i, exact
// for constant c, positive for every c.
double Bernoulli(double z) {
  if (std::abs(z) < 1e-4) return 1.0 - 0.5 * z + z * z / 12.0;
  return z / std::expm1(z);
}

// B'(z) = (e^z - 1 - z e^z) / (e^z - 1)^2, negative: B falls monotonically.
double BernoulliSlope(double z) {
  if (std::abs(z) < 1e-4) return -0.5 + z / 6.0;
  const double e = std::expm1(z);
  return (e - z * (e + 1.0)) / (e * e);
}

// The root in [-kMaxControl, kMaxControl] of f(psi) = B(-psi) up + B(psi) down + r0, which
// increases monotonically (up > 0 > down), or the end of the interval nearer to it: Newton's
// method kept inside a bracket that every step narrows, a bisection step wherever Newton's would
// leave it (after W. H. Press et al., "Numerical Recipes", 3rd ed., sec. 9.4, rtsafe, without
// its switch to bisection on slow steps: f is smooth and monotone). Quadratic near the root:
// about 7 evaluations with the two at the ends, where a plain bisection to the same width took
// 50.
double TrackingPsi(double up, double down, double r0) {
  const auto f = [&](double psi) { return Bernoulli(-psi) * up + Bernoulli(psi) * down + r0; };
  double lo = -kMaxControl, hi = kMaxControl;
  if (f(lo) >= 0.0) return lo;
  if (f(hi) <= 0.0) return hi;
  double psi = 0.0;
  for (int k = 0; k < 60 && hi - lo > 1e-14; ++k) {
    const double value = f(psi);
    if (value == 0.0) return psi;
    (value < 0.0 ? lo : hi) = psi;
    const double slope = -BernoulliSlope(-psi) * up + BernoulliSlope(psi) * down;
    const double next = psi - value / slope;
    // Converged first: a step that rounds to nothing at a bracket end is not one to bisect.
    if (std::abs(next - psi) <= 1e-15 * (1.0 + std::abs(psi))) return next;
    psi = next > lo && next < hi ? next : 0.5 * (lo + hi);
  }
  return psi;
}

struct Vec {
  double x, y;
};

Vec At(const StructuredBlock& g, int i, int j) {
  const double* p = g.Point(i, j, 0);
  return {p[0], p[1]};
}

// The nine-point neighbourhood of interior point (i, j) of a periodic O-grid (the last line
// repeats the first) and the central differences and metric terms the equations use.
struct Neighbourhood {
  Vec centre, e, w, n, s;
  Vec xi, eta, cross;         // x_xi, x_eta, x_xieta
  double alpha, beta, gamma;  // |x_eta|^2, x_xi . x_eta, |x_xi|^2
};

Neighbourhood Around(const StructuredBlock& g, int i, int j) {
  const int ni = g.extent(0);
  const int im = i == 0 ? ni - 2 : i - 1, ip = i == ni - 1 ? 1 : i + 1;
  Neighbourhood h;
  h.centre = At(g, i, j);
  h.e = At(g, ip, j);
  h.w = At(g, im, j);
  h.n = At(g, i, j + 1);
  h.s = At(g, i, j - 1);
  const Vec ne = At(g, ip, j + 1), se = At(g, ip, j - 1), nw = At(g, im, j + 1),
            sw = At(g, im, j - 1);
  h.xi = {0.5 * (h.e.x - h.w.x), 0.5 * (h.e.y - h.w.y)};
  h.eta = {0.5 * (h.n.x - h.s.x), 0.5 * (h.n.y - h.s.y)};
  h.cross = {0.25 * (ne.x - se.x - nw.x + sw.x), 0.25 * (ne.y - se.y - nw.y + sw.y)};
  h.alpha = h.eta.x * h.eta.x + h.eta.y * h.eta.y;
  h.beta = h.xi.x * h.eta.x + h.xi.y * h.eta.y;
  h.gamma = h.xi.x * h.xi.x + h.xi.y * h.xi.y;
  return h;
}

absl::Status CheckOGrid(const StructuredBlock& grid) {
  const int ni = grid.extent(0), nj = grid.extent(1);
  if (grid.spatial_dim() != 2 || grid.extent(2) != 1 || ni < 5 || nj < 3) {
    return absl::InvalidArgumentError(absl::StrCat(
        "elliptic smoothing needs a planar O-grid of at least 5 x 3 points, not ", ni, " x ", nj,
        " x ", grid.extent(2), " with ", grid.spatial_dim(), " coordinates"));
  }
  for (int j = 0; j < nj; ++j) {
    const double* a = grid.Point(0, j, 0);
    const double* b = grid.Point(ni - 1, j, 0);
    if (a[0] != b[0] || a[1] != b[1]) {
      return absl::InvalidArgumentError(absl::StrCat("the grid is not periodic in i: point (0, ", j,
                                                     ") differs from (", ni - 1, ", ", j, ")"));
    }
  }
  return absl::OkStatus();
}

// A tridiagonal system lower[r] x[r-1] + diag[r] x[r] + upper[r] x[r+1] = b[r] with two
// right-hand sides (x and y), solved in place into bx, by.
struct LineSystem {
  std::vector<double> lower, diag, upper, bx, by, scratch, zx, zy;

  void Resize(int n) {
    for (auto* v : {&lower, &diag, &upper, &bx, &by, &scratch, &zx, &zy}) v->resize(n);
  }

  // Thomas algorithm on rows [0, n) (no pivoting: the matrices here are diagonally dominant,
  // the exponentially fitted weights being positive), for the right-hand sides in `x` and `y`.
  void Thomas(int n, double* x, double* y) {
    for (int r = 0; r < n; ++r) {
      const double m = diag[r] - (r > 0 ? lower[r] * scratch[r - 1] : 0.0);
      scratch[r] = upper[r] / m;
      x[r] = (x[r] - (r > 0 ? lower[r] * x[r - 1] : 0.0)) / m;
      if (y != nullptr) y[r] = (y[r] - (r > 0 ? lower[r] * y[r - 1] : 0.0)) / m;
    }
    for (int r = n - 2; r >= 0; --r) {
      x[r] -= scratch[r] * x[r + 1];
      if (y != nullptr) y[r] -= scratch[r] * y[r + 1];
    }
  }

  void Solve() { Thomas(static_cast<int>(diag.size()), bx.data(), by.data()); }

  // Periodic: lower[0] couples row 0 to row n-1 and upper[n-1] row n-1 to row 0. Sherman-
  // Morrison: A = T + u v^T with u = (g, 0, .., 0, c), v = (1, 0, .., 0, a / g), g = -diag[0],
  // c = upper[n-1], a = lower[0]; x = T^-1 b - (v . T^-1 b) / (1 + v . T^-1 u) T^-1 u.
  void SolveCyclic() {
    const int n = static_cast<int>(diag.size());
    const double a = lower[0], c = upper[n - 1], gg = -diag[0];
    const double d0 = diag[0], dn = diag[n - 1];
    diag[0] -= gg;
    diag[n - 1] -= a * c / gg;
    std::fill(zx.begin(), zx.end(), 0.0);
    zx[0] = gg;
    zx[n - 1] = c;
    Thomas(n, bx.data(), by.data());
    Thomas(n, zx.data(), nullptr);
    const double vz = zx[0] + a / gg * zx[n - 1];
    const double fx = (bx[0] + a / gg * bx[n - 1]) / (1.0 + vz);
    const double fy = (by[0] + a / gg * by[n - 1]) / (1.0 + vz);
    for (int r = 0; r < n; ++r) {
      bx[r] -= fx * zx[r];
      by[r] -= fy * zx[r];
    }
    diag[0] = d0;
    diag[n - 1] = dn;
  }
};

// The fitted differences' weights B(-phi), B(phi), B(-psi), B(psi) at every point.
std::vector<double> FittedWeights(const ControlFunctions& control, int64_t num_points) {
  std::vector<double> weights(4 * num_points);
  for (int64_t p = 0; p < num_points; ++p) {
    weights[4 * p] = Bernoulli(-control.phi[p]);
    weights[4 * p + 1] = Bernoulli(control.phi[p]);
    weights[4 * p + 2] = Bernoulli(-control.psi[p]);
    weights[4 * p + 3] = Bernoulli(control.psi[p]);
  }
  return weights;
}

// Alternating line relaxation of an O-grid in place: every line of constant i solved at once
// (tridiagonal in j), then every line of constant j (cyclic tridiagonal in i), each with its
// neighbouring lines as they are, and relaxed by omega. Near the wall the flat cells couple
// strongly in j, far out the stretched ones in i; point relaxation would carry either a point
// per sweep. Layers below `first` and the outer loop stay.
class LineRelaxation {
 public:
  LineRelaxation(StructuredBlock& g, const ControlFunctions& control, int first, double omega)
      : g_(g),
        ni_(g.extent(0)),
        nj_(g.extent(1)),
        first_(first),
        rows_(nj_ - 1 - first),
        cols_(ni_ - 1),
        omega_(omega),
        weights_(FittedWeights(control, g.num_points())) {}

  double omega() const { return omega_; }
  void set_omega(double omega) { omega_ = omega; }

  // Unknowns j = first .. nj - 2 per line of constant i.
  int rows() const { return rows_; }

  // Relax N(x) = source instead of N(x) = 0 (two values per point, point order; empty: 0),
  // N(x) the discrete equation of the file comment: at (i, j)
  //   N(x) = we x_e + ww x_w + wn x_n + ws x_s - 2 beta x_xieta - (we + ww + wn + ws) x.
  void SetSource(std::vector<double> source) { source_ = std::move(source); }

  // source - N(x) at every free point (2 values per point, point order), 0 at held points, the
  // outer loop and the repeated line i = ni - 1.
  std::vector<double> Residual() const {
    std::vector<double> out(2 * g_.num_points(), 0.0);
    for (int j = first_; j + 1 < nj_; ++j) {
      for (int i = 0; i < cols_; ++i) {
        double lower, diag, upper;
        Vec rest;  // with the source: rest - lower x_s - upper x_n - diag x = N(x) - source
        Stencil(i, j, true, &lower, &diag, &upper, &rest);
        const Vec c = At(g_, i, j), n = At(g_, i, j + 1), s = At(g_, i, j - 1);
        const int64_t p = g_.Index(i, j, 0);
        out[2 * p] = -(rest.x - lower * s.x - upper * n.x - diag * c.x);
        out[2 * p + 1] = -(rest.y - lower * s.y - upper * n.y - diag * c.y);
      }
    }
    return out;
  }

  // One sweep over both line directions; the largest move relative to the moved point's
  // smallest spacing to its neighbours (infinity when a move is not finite).
  double largest() const { return largest_; }

  double Sweep() {
    largest_ = 0.0;
    SweepLinesAlongJ();
    SweepLinesAlongI();
    return largest_;
  }

 private:
  // The discrete equation at (i, j), split into the neighbours along the line and the rest.
  void Stencil(int i, int j, bool along_j, double* lower, double* diag, double* upper, Vec* rest,
               bool with_source = true) const {
    const Neighbourhood h = Around(g_, i, j);
    const Vec &e = h.e, &w = h.w, &n = h.n, &s = h.s, &cross = h.cross;
    const double alpha = h.alpha, beta = h.beta, gamma = h.gamma;
    const int64_t p = g_.Index(i, j, 0);
    // (we + ww + wn + ws) x = we x_e + ww x_w + wn x_n + ws x_s - 2 beta x_xieta, with
    // we = alpha B(-phi), ww = alpha B(phi), wn = gamma B(-psi), ws = gamma B(psi).
    const double we = alpha * weights_[4 * p], ww = alpha * weights_[4 * p + 1];
    const double wn = gamma * weights_[4 * p + 2], ws = gamma * weights_[4 * p + 3];
    *diag = we + ww + wn + ws;
    rest->x = -2.0 * beta * cross.x;
    rest->y = -2.0 * beta * cross.y;
    if (!source_.empty()) {
      rest->x -= source_[2 * p];
      rest->y -= source_[2 * p + 1];
    }
    if (along_j) {
      *lower = -ws;
      *upper = -wn;
      rest->x += we * e.x + ww * w.x;
      rest->y += we * e.y + ww * w.y;
    } else {
      *lower = -ww;
      *upper = -we;
      rest->x += wn * n.x + ws * s.x;
      rest->y += wn * n.y + ws * s.y;
    }
  }

  // Moves point (i, j) by omega towards (x, y), tracking the largest move relative to the
  // point's smallest spacing to its neighbours.
  void Relax(int i, int j, double x, double y) {
    double* p = g_.Point(i, j, 0);
    const double dx = omega_ * (x - p[0]), dy = omega_ * (y - p[1]);
    if (!std::isfinite(dx) || !std::isfinite(dy)) {
      largest_ = std::numeric_limits<double>::infinity();
      return;
    }
    const Vec b = {p[0], p[1]}, e = At(g_, i + 1, j), n = At(g_, i, j + 1), s = At(g_, i, j - 1);
    const double h = std::min({std::hypot(e.x - b.x, e.y - b.y), std::hypot(n.x - b.x, n.y - b.y),
                               std::hypot(s.x - b.x, s.y - b.y)});
    p[0] += dx;
    p[1] += dy;
    if (h > 0.0) largest_ = std::max(largest_, std::hypot(dx, dy) / h);
    if (i == 0) std::copy(p, p + 2, g_.Point(ni_ - 1, j, 0));
  }

  // Every line of constant i, tridiagonal in j.
  void SweepLinesAlongJ() {
    line_.Resize(rows_);
    for (int i = 0; i < cols_; ++i) {
      for (int r = 0; r < rows_; ++r) {
        Vec rest;
        Stencil(i, first_ + r, true, &line_.lower[r], &line_.diag[r], &line_.upper[r], &rest);
        line_.bx[r] = rest.x;
        line_.by[r] = rest.y;
      }
      // The held layer below and the outer loop above are fixed: move them to the right.
      line_.bx[0] -= line_.lower[0] * At(g_, i, first_ - 1).x;
      line_.by[0] -= line_.lower[0] * At(g_, i, first_ - 1).y;
      line_.bx[rows_ - 1] -= line_.upper[rows_ - 1] * At(g_, i, nj_ - 1).x;
      line_.by[rows_ - 1] -= line_.upper[rows_ - 1] * At(g_, i, nj_ - 1).y;
      line_.Solve();
      for (int r = 0; r < rows_; ++r) Relax(i, first_ + r, line_.bx[r], line_.by[r]);
    }
  }

  // Every line of constant j, cyclic tridiagonal in i (periodic).
  void SweepLinesAlongI() {
    line_.Resize(cols_);
    for (int j = first_; j + 1 < nj_; ++j) {
      for (int i = 0; i < cols_; ++i) {
        Vec rest;
        Stencil(i, j, false, &line_.lower[i], &line_.diag[i], &line_.upper[i], &rest);
        line_.bx[i] = rest.x;
        line_.by[i] = rest.y;
      }
      line_.SolveCyclic();
      for (int i = 0; i < cols_; ++i) Relax(i, j, line_.bx[i], line_.by[i]);
    }
  }

  StructuredBlock& g_;
  const int ni_, nj_;
  const int first_;  // the first unknown layer
  const int rows_;   // unknowns j = first .. nj - 2
  const int cols_;   // unknowns i = 0 .. ni - 2 (periodic)
  double omega_;
  const std::vector<double> weights_;
  std::vector<double> source_;
  LineSystem line_;
  double largest_ = 0.0;
};

// Full weighting of the fine values `fine` (2 per point of an ni x nj O-grid, periodic in i)
// at the coarse point (I, J) = fine (2 I, 2 J): (4 c + 2 (e + w + n + s) + ne + nw + se + sw) / 16.
Vec FullWeighting(const std::vector<double>& fine, int ni, int i, int j) {
  Vec sum = {0.0, 0.0};
  for (int dj = -1; dj <= 1; ++dj) {
    for (int di = -1; di <= 1; ++di) {
      int f = i + di;
      if (f < 0) f += ni - 1;
      if (f > ni - 2) f -= ni - 1;
      const double w = (di == 0 ? 2.0 : 1.0) * (dj == 0 ? 2.0 : 1.0) / 16.0;
      const int64_t p = static_cast<int64_t>(j + dj) * ni + f;
      sum.x += w * fine[2 * p];
      sum.y += w * fine[2 * p + 1];
    }
  }
  return sum;
}

}  // namespace

absl::StatusOr<ControlFunctions> TrackingControls(const StructuredBlock& grid, int inner,
                                                  const CancelCheck& cancel) {
  const int ni = grid.extent(0), nj = grid.extent(1);
  inner = std::clamp(inner, 0, nj - 2);
  ControlFunctions c;
  c.phi.assign(grid.num_points(), 0.0);
  c.psi.assign(grid.num_points(), 0.0);
  // phi on the inner and outer loops: the fitted difference reproduces their distributions.
  std::vector<double> inner_phi(ni), outer_phi(ni);
  for (int side = 0; side < 2; ++side) {
    const int j = side == 0 ? inner : nj - 1;
    std::vector<double>& phi = side == 0 ? inner_phi : outer_phi;
    for (int i = 0; i < ni; ++i) {
      const int im = i == 0 ? ni - 2 : i - 1, ip = i == ni - 1 ? 1 : i + 1;
      const Vec a = At(grid, im, j), b = At(grid, i, j), d = At(grid, ip, j);
      const double west = std::hypot(b.x - a.x, b.y - a.y);
      const double east = std::hypot(d.x - b.x, d.y - b.y);
      phi[i] = west > 0.0 && east > 0.0
                   ? std::clamp(std::log(west / east), -kMaxControl, kMaxControl)
                   : 0.0;
    }
  }
  for (int j = 0; j < nj; ++j) {
    // Polled every layer: with a bisection per point a 4097 x 2049 grid took 15 s unpolled, and
    // a GenerateGrid overran its deadline by that much (now about 1.5 s).
    SG_RETURN_IF_ERROR(PollCancel(cancel));
    const double t = std::max(0.0, static_cast<double>(j - inner) / (nj - 1 - inner));
    for (int i = 0; i < ni; ++i) {
      const int64_t p = grid.Index(i, j, 0);
      const double phi = (1.0 - t) * inner_phi[i] + t * outer_phi[i];
      c.phi[p] = phi;
      if (j == 0 || j == nj - 1) continue;
      // psi: the discrete equation's component along the layer normal n vanishes on `grid`,
      //   B(-psi) up + B(psi) down = -r0,  up = (x_n - x) . n > 0,  down = (x_s - x) . n < 0,
      // r0 the rest of the equation along n over gamma. The left side increases monotonically
      // from -inf to inf with psi (TrackingPsi).
      const Neighbourhood h = Around(grid, i, j);
      const Vec &b = h.centre, &e = h.e, &w = h.w, &n = h.n, &s = h.s, &xi = h.xi, &eta = h.eta;
      const double alpha = h.alpha, beta = h.beta, gamma = h.gamma;
      if (!(gamma > 0.0)) continue;
      const double ae = Bernoulli(-phi), aw = Bernoulli(phi);
      const Vec rest = {alpha * (ae * (e.x - b.x) + aw * (w.x - b.x)) - 2.0 * beta * h.cross.x,
                        alpha * (ae * (e.y - b.y) + aw * (w.y - b.y)) - 2.0 * beta * h.cross.y};
      const double length = std::sqrt(gamma);
      Vec normal = {-xi.y / length, xi.x / length};
      if (normal.x * eta.x + normal.y * eta.y < 0.0) normal = {-normal.x, -normal.y};
      const double r0 = (rest.x * normal.x + rest.y * normal.y) / gamma;
      const double up = (n.x - b.x) * normal.x + (n.y - b.y) * normal.y;
      const double down = (s.x - b.x) * normal.x + (s.y - b.y) * normal.y;
      if (!(up > 0.0) || !(down < 0.0)) continue;
      c.psi[p] = TrackingPsi(up, down, r0);
    }
  }
  return c;
}

namespace {

// Watches the largest move of successive sweeps (or cycles): stalled once it has not fallen to
// a new low for `patience` of them.
class StallWatch {
 public:
  explicit StallWatch(int patience) : patience_(patience) {}

  bool Stalled(double largest) {
    ++steps_;
    if (largest < lowest_) {
      lowest_ = largest;
      lowest_step_ = steps_;
    }
    return steps_ - lowest_step_ >= patience_;
  }

  void Reset() { *this = StallWatch(patience_); }

 private:
  int patience_;
  int steps_ = 0, lowest_step_ = 0;
  double lowest_ = std::numeric_limits<double>::infinity();
};

// The iterate nearest convergence so far (the smallest largest move of a sweep), which an
// unconverged run returns: its last iterate may be one whose points jump or collapse.
class BestIterate {
 public:
  void Offer(double largest, const StructuredBlock& grid) {
    if (!(largest < largest_)) return;
    largest_ = largest;
    coords_.assign(grid.coords().begin(), grid.coords().end());
  }
  void RestoreInto(StructuredBlock& grid) const {
    if (!coords_.empty()) std::copy(coords_.begin(), coords_.end(), grid.coords().begin());
  }

 private:
  double largest_ = std::numeric_limits<double>::infinity();
  std::vector<double> coords_;
};

// The next, smaller omega after a stall, or nullopt below kMinRelaxation.
std::optional<double> BackedOff(double omega) {
  const double next = omega * kRelaxationBackoff;
  if (next < kMinRelaxation) return std::nullopt;
  return next;
}

}  // namespace

absl::Status EllipticOptions::Validate() const {
  if (max_sweeps < 0) {
    return absl::InvalidArgumentError(absl::StrCat("max_sweeps = ", max_sweeps, " is negative"));
  }
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) {
    return absl::InvalidArgumentError(
        absl::StrCat("tolerance = ", tolerance, " is not a positive finite number"));
  }
  if (!(relaxation > 0.0 && relaxation < 2.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("relaxation = ", relaxation, " is outside (0, 2)"));
  }
  return absl::OkStatus();
}

absl::StatusOr<EllipticResult> SmoothElliptic(const StructuredBlock& initial,
                                              const ControlFunctions& control, int held_layers,
                                              const EllipticOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  SG_RETURN_IF_ERROR(options.Validate());
  SG_RETURN_IF_ERROR(CheckOGrid(initial));
  if (static_cast<int64_t>(control.phi.size()) != initial.num_points() ||
      control.psi.size() != control.phi.size()) {
    return absl::InvalidArgumentError(absl::StrCat("control functions for ", control.phi.size(),
                                                   " points; the grid has ", initial.num_points()));
  }
  const int nj = initial.extent(1);
  EllipticResult result;
  result.grid = initial;
  const int first = std::clamp(held_layers, 1, nj - 1);
  LineRelaxation relaxation(result.grid, control, first, options.relaxation);
  StallWatch watch(kStallSweeps);
  BestIterate best;
  for (result.sweeps = 0; result.sweeps < options.max_sweeps && relaxation.rows() > 0;) {
    SG_RETURN_IF_ERROR(PollCancel(options.cancel));
    ++result.sweeps;
    const double largest = relaxation.Sweep();
    if (largest < options.tolerance) {
      result.converged = true;
      break;
    }
    best.Offer(largest, result.grid);
    if (!std::isfinite(largest) || watch.Stalled(largest)) {
      const std::optional<double> damped = BackedOff(relaxation.omega());
      if (!damped) {
        if (std::isfinite(largest)) break;  // no better: reported as not converged
        return absl::FailedPreconditionError(absl::StrCat("elliptic smoothing diverged in sweep ",
                                                          result.sweeps, " (relaxation factor ",
                                                          relaxation.omega(), ")"));
      }
      relaxation.set_omega(*damped);
      std::copy(initial.coords().begin(), initial.coords().end(), result.grid.coords().begin());
      watch.Reset();
      ++result.restarts;
    }
  }
  if (!result.converged) best.RestoreInto(result.grid);
  result.relaxation = relaxation.omega();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

namespace {

// One level of the multigrid cycles: its iterate, its relaxation (with the source of the
// cycle), and the iterate as injected from the finer level at the cycle's start.
struct Level {
  Level(StructuredBlock g, const ControlFunctions& control, int first, double omega)
      : grid(std::move(g)), relax(grid, control, first, omega), first(first) {}
  StructuredBlock grid;
  LineRelaxation relax;
  std::vector<double> injected;
  int first;  // the first free layer
  int sweeps = 0;
};

// Every second point and layer of `grid` into `coarse` (of those extents).
void InjectInto(const StructuredBlock& grid, StructuredBlock& coarse) {
  for (int j = 0; j < coarse.extent(1); ++j) {
    for (int i = 0; i < coarse.extent(0); ++i) {
      std::copy_n(grid.Point(2 * i, 2 * j, 0), 2, coarse.Point(i, j, 0));
    }
  }
}

StructuredBlock Inject(const StructuredBlock& grid) {
  StructuredBlock coarse({(grid.extent(0) + 1) / 2, (grid.extent(1) + 1) / 2, 1}, 2);
  InjectInto(grid, coarse);
  return coarse;
}

class Multigrid {
 public:
  Multigrid(std::vector<std::unique_ptr<Level>> levels, const EllipticOptions& options)
      : levels_(std::move(levels)), options_(options) {}

  // One sweep of level l: its largest move (LineRelaxation::Sweep).
  double Sweep(int l) {
    Level& level = *levels_[l];
    ++level.sweeps;
    return level.relax.Sweep();
  }

  double omega() const { return levels_[0]->relax.omega(); }
  void set_omega(double omega) {
    for (auto& level : levels_) level->relax.set_omega(omega);
  }

  // The coarse-level correction of level l - 1 by level l, the coarsest (file comment): its
  // problem from level l - 1's residual, solved by sweeps, and the correction interpolated onto
  // level l - 1's free points.
  void Correct(int l) {
    Level& fine = *levels_[l - 1];
    Level& coarse = *levels_[l];
    const int ni = fine.grid.extent(0), nj = fine.grid.extent(1);
    const int nic = coarse.grid.extent(0), njc = coarse.grid.extent(1);
    const std::vector<double> residual = fine.relax.Residual();
    InjectInto(fine.grid, coarse.grid);
    coarse.injected.assign(coarse.grid.coords().begin(), coarse.grid.coords().end());
    coarse.relax.SetSource({});
    std::vector<double> source = coarse.relax.Residual();  // -N_c(I x)
    for (double& v : source) v = -v;
    for (int J = coarse.first; J + 1 < njc; ++J) {
      for (int I = 0; I + 1 < nic; ++I) {
        const Vec r = FullWeighting(residual, ni, 2 * I, 2 * J);
        const int64_t p = coarse.grid.Index(I, J, 0);
        source[2 * p] += 16.0 * r.x;
        source[2 * p + 1] += 16.0 * r.y;
      }
    }
    coarse.relax.SetSource(std::move(source));
    for (int k = 0; k < kCoarsestSweeps; ++k) {
      const double largest = Sweep(l);
      // Settled, or diverged: a move that is not finite reaches the fine level's next sweep.
      if (largest < options_.tolerance || !std::isfinite(largest)) break;
    }
    // The correction, bilinear in index space (periodic in i), on the free points.
    auto correction = [&](int I, int J) -> Vec {
      const int64_t p = coarse.grid.Index(I % (nic - 1), J, 0);
      return {coarse.grid.coords()[2 * p] - coarse.injected[2 * p],
              coarse.grid.coords()[2 * p + 1] - coarse.injected[2 * p + 1]};
    };
    for (int j = fine.first; j + 1 < nj; ++j) {
      for (int i = 0; i + 1 < ni; ++i) {
        const int I0 = i / 2, I1 = (i + 1) / 2, J0 = j / 2, J1 = (j + 1) / 2;
        const Vec a = correction(I0, J0), b = correction(I1, J0), c = correction(I0, J1),
                  d = correction(I1, J1);
        double* x = fine.grid.Point(i, j, 0);
        x[0] += 0.25 * (a.x + b.x + c.x + d.x);
        x[1] += 0.25 * (a.y + b.y + c.y + d.y);
        if (i == 0) std::copy_n(x, 2, fine.grid.Point(ni - 1, j, 0));
      }
    }
  }

  Level& level(int l) { return *levels_[l]; }
  int num_levels() const { return static_cast<int>(levels_.size()); }

 private:
  std::vector<std::unique_ptr<Level>> levels_;
  const EllipticOptions& options_;
};

}  // namespace

absl::StatusOr<EllipticResult> SmoothMultigrid(const StructuredBlock& initial,
                                               const StructuredBlock& algebraic, int held_layers,
                                               const EllipticOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  SG_RETURN_IF_ERROR(options.Validate());
  SG_RETURN_IF_ERROR(CheckOGrid(initial));
  SG_RETURN_IF_ERROR(CheckOGrid(algebraic));
  if (algebraic.extents() != initial.extents()) {
    return absl::InvalidArgumentError(
        absl::StrCat("the algebraic grid has ", algebraic.extent(0), " x ", algebraic.extent(1),
                     " points; the initial grid ", initial.extent(0), " x ", initial.extent(1)));
  }
  // Levels: halve while both extents are odd and the coarser level keeps at least
  // kCoarsestPoints x kCoarsestLayers points. Held layers: level l + 1 holds (h_l + 1) / 2, so
  // its held layers are level l's at even j and its first free layer is above level l's.
  std::vector<std::unique_ptr<Level>> levels;
  StructuredBlock algebraic_l = algebraic;
  StructuredBlock grid_l = initial;
  int held = std::clamp(held_layers, 1, initial.extent(1) - 2);
  for (;;) {
    SG_ASSIGN_OR_RETURN(const ControlFunctions control,
                        TrackingControls(algebraic_l, held - 1, options.cancel));
    levels.push_back(std::make_unique<Level>(grid_l, control, held, options.relaxation));
    const int ni = algebraic_l.extent(0), nj = algebraic_l.extent(1);
    const int coarse_held = (held + 1) / 2;
    if (static_cast<int>(levels.size()) == kMaxLevels || ni % 2 == 0 || nj % 2 == 0 ||
        (ni + 1) / 2 < kCoarsestPoints || (nj + 1) / 2 < kCoarsestLayers ||
        coarse_held + 1 >= (nj + 1) / 2) {
      break;
    }
    algebraic_l = Inject(algebraic_l);
    grid_l = Inject(grid_l);
    held = coarse_held;
  }
  Multigrid multigrid(std::move(levels), options);
  EllipticResult result;
  Level& fine = multigrid.level(0);
  bool cycling = multigrid.num_levels() > 1;
  StallWatch watch(cycling ? kStallCycles : kStallSweeps);
  BestIterate best;
  while (fine.sweeps < options.max_sweeps && fine.relax.rows() > 0) {
    SG_RETURN_IF_ERROR(PollCancel(options.cancel));
    double largest = multigrid.Sweep(0);
    if (largest < options.tolerance) {
      result.converged = true;
      break;
    }
    if (fine.sweeps >= options.max_sweeps) break;
    if (cycling && std::isfinite(largest)) {
      multigrid.Correct(1);
      largest = multigrid.Sweep(0);
      if (largest < options.tolerance) {
        result.converged = true;
        break;
      }
    }
    best.Offer(largest, fine.grid);
    if (std::isfinite(largest) && !watch.Stalled(largest)) continue;
    // Stalled or diverged: start again from the initial grid (the iterate can be a worse start
    // than that), within the same sweep budget: cycles by relaxation alone (the cycles' fixed
    // point can be another solution of the equations than relaxation's: RAE 2822 65 x 33 with
    // only the wall held), then with a smaller omega while it can be lowered.
    if (cycling) {
      cycling = false;
      result.stalled = true;
      watch = StallWatch(kStallSweeps);
    } else if (const std::optional<double> damped = BackedOff(multigrid.omega())) {
      multigrid.set_omega(*damped);
    } else if (std::isfinite(largest)) {
      break;  // no better: reported as not converged
    } else {
      return absl::FailedPreconditionError(absl::StrCat("elliptic smoothing diverged in sweep ",
                                                        fine.sweeps, " (relaxation factor ",
                                                        multigrid.omega(), ")"));
    }
    std::copy(initial.coords().begin(), initial.coords().end(), fine.grid.coords().begin());
    watch.Reset();
    ++result.restarts;
  }
  if (!result.converged) best.RestoreInto(fine.grid);
  result.relaxation = multigrid.omega();
  result.sweeps = fine.sweeps;
  for (int l = 1; l < multigrid.num_levels(); ++l) {
    result.coarse_work += multigrid.level(l).sweeps / std::pow(4.0, l);
  }
  result.levels = multigrid.num_levels();
  result.grid = std::move(fine.grid);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

int LayersWithin(const std::vector<double>& heights, double distance) {
  int within = 1;
  while (within < static_cast<int>(heights.size()) && heights[within] <= distance) ++within;
  return within;
}

absl::StatusOr<CoarseToFine> SmoothCoarseToFine(const StructuredBlock& algebraic, int held_layers,
                                                const EllipticOptions& options, bool compare) {
  SG_RETURN_IF_ERROR(options.Validate());
  SG_RETURN_IF_ERROR(CheckOGrid(algebraic));
  const int ni = algebraic.extent(0), nj = algebraic.extent(1);
  if (ni % 2 == 0 || nj % 2 == 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "coarse to fine needs an odd number of wall points (the first repeated) and an even "
        "number of layers, not wall_points = ",
        ni, " and layers = ", nj - 1));
  }
  CoarseToFine out;
  // Coarse level: every second point and layer of the algebraic grid (of a transfinite grid,
  // that is the transfinite grid with the heights d_{2j}).
  const StructuredBlock coarse_algebraic = Inject(algebraic);
  // Held: at least held_layers, rounded up so that the last held fine layer is a coarse one
  // (fine held = 2 coarse held - 1).
  const int coarse_held = std::clamp((held_layers + 2) / 2, 1, coarse_algebraic.extent(1) - 2);
  out.held_layers = 2 * coarse_held - 1;
  SG_ASSIGN_OR_RETURN(const ControlFunctions coarse_control,
                      TrackingControls(coarse_algebraic, coarse_held - 1, options.cancel));
  SG_ASSIGN_OR_RETURN(out.coarse,
                      SmoothElliptic(coarse_algebraic, coarse_control, coarse_held, options));
  // The coarse solution's spline at level 1 of its point distribution, with the fine level's
  // held layers and outer loop put back.
  FitOptions interpolation;
  interpolation.cancel = options.cancel;
  SG_ASSIGN_OR_RETURN(const FittedBlock spline, FitBlock(out.coarse.grid, interpolation));
  std::array<std::vector<double>, 3> params;
  for (int d = 0; d < 3; ++d) {
    params[d] =
        spline.distribution.Refined(d, 0, spline.distribution.num_points(d) - 1, d < 2 ? 1 : 0);
  }
  StructuredBlock guess = EvaluateGrid(spline.spline, params);  // ni x nj again
  for (int j = 0; j < nj; ++j) {
    const bool held = j < out.held_layers || j == nj - 1;
    for (int i = 0; i < ni; ++i) {
      const double* from = held ? algebraic.Point(i, j, 0) : guess.Point(i == ni - 1 ? 0 : i, j, 0);
      std::copy(from, from + 2, guess.Point(i, j, 0));  // periodic: the last line is the first
    }
  }
  // The fine level starts from the omega the coarse level ended with: one that had to be
  // lowered there would stall the fine cycles too. An unconverged coarse level is no guess: the
  // fine level starts from the algebraic grid with the caller's omega.
  EllipticOptions fine_options = options;
  if (out.coarse.converged) {
    fine_options.relaxation = out.coarse.relaxation;
  } else {
    guess = algebraic;
  }
  SG_ASSIGN_OR_RETURN(out.fine, SmoothMultigrid(guess, algebraic, out.held_layers, fine_options));
  if (compare) {
    SG_ASSIGN_OR_RETURN(const ControlFunctions control,
                        TrackingControls(algebraic, out.held_layers - 1, options.cancel));
    SG_ASSIGN_OR_RETURN(out.fine_from_transfinite,
                        SmoothElliptic(algebraic, control, out.held_layers, options));
  }
  return out;
}

}  // namespace splinegrid
