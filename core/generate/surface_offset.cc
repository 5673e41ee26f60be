#include "core/generate/surface_offset.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>

#include "Eigen/Core"
#include "Eigen/Geometry"
#include "absl/strings/str_cat.h"
#include "core/bspline/evaluation.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/generate/offset_march.h"
#include "core/grid/sampling.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

using Vec = Eigen::Vector3d;
// The points (or normals) of one layer, i fastest.
using Layer = std::vector<Vec>;
// Point indices of the block edges that collapse to one point.
using EdgeGroups = std::vector<std::vector<int64_t>>;

// A derivative shorter than this times the surface's size has vanished (a collapsed edge), and
// an edge whose points all lie this close to its first point is collapsed.
constexpr double kCollapsed = 1e-9;
// A cell edge shorter than this times the cell's longest edge is collapsed: the Jacobians at
// its corners vanish and are not checked.
constexpr double kCollapsedCellEdge = 1e-9;

Vec ToVec(const Point3& p) { return Vec(p[0], p[1], p[2]); }

// The ni x nj layer grid: index of point (i, j).
struct Shape {
  int ni;
  int nj;
  int64_t At(int i, int j) const { return i + int64_t{ni} * j; }
  int64_t size() const { return int64_t{ni} * nj; }
};

StructuredBlock ToBlock(const Layer& p, const Shape& s) {
  StructuredBlock block({s.ni, s.nj, 1}, 3);
  for (int64_t q = 0; q < s.size(); ++q)
    std::copy(p[q].data(), p[q].data() + 3, block.Point(q % s.ni, q / s.ni, 0));
  return block;
}

// The four block edges (j = 0, j = nj - 1, i = 0, i = ni - 1) whose points all coincide.
EdgeGroups CollapsedEdges(const Layer& p, const Shape& s, double tolerance) {
  std::vector<std::vector<int64_t>> edges(4);
  for (int i = 0; i < s.ni; ++i) {
    edges[0].push_back(s.At(i, 0));
    edges[1].push_back(s.At(i, s.nj - 1));
  }
  for (int j = 0; j < s.nj; ++j) {
    edges[2].push_back(s.At(0, j));
    edges[3].push_back(s.At(s.ni - 1, j));
  }
  EdgeGroups collapsed;
  for (auto& edge : edges) {
    const bool one_point = std::all_of(edge.begin(), edge.end(), [&](int64_t q) {
      return (p[q] - p[edge.front()]).norm() <= tolerance;
    });
    if (one_point) collapsed.push_back(std::move(edge));
  }
  return collapsed;
}

// Every collapsed edge's points replaced by their mean.
void Unite(Layer& values, const EdgeGroups& collapsed) {
  for (const auto& edge : collapsed) {
    Vec mean = Vec::Zero();
    for (int64_t q : edge) mean += values[q];
    mean /= static_cast<double>(edge.size());
    for (int64_t q : edge) values[q] = mean;
  }
}

// Unit normals (oriented by `side`) and largest principal curvatures against them (positive
// where the surface is concave towards the normal) of a fitted layer at its data parameters.
struct Geometry {
  Layer normal;
  std::vector<double> kappa;
};

// The normals and curvatures of `g` at the regular points; at singular ones (X_u x X_v
// vanishes) `known` is cleared and `lhopital` holds the l'Hopital normal direction.
void RegularGeometry(const TensorSpline& spline, const std::array<std::vector<double>, 3>& params,
                     const Shape& s, int side, double scale, Geometry& g, std::vector<char>& known,
                     Layer& lhopital) {
  const std::vector<double>& u = params[0];
  const std::vector<double>& v = params[1];
  for (int j = 0; j < s.nj; ++j) {
    for (int i = 0; i < s.ni; ++i) {
      const int64_t q = s.At(i, j);
      const PartialDerivatives d = EvaluateDerivatives(spline, {u[i], v[j], 0.0}, 2);
      const Vec xu = ToVec(d(1, 0, 0)), xv = ToVec(d(0, 1, 0)), xuv = ToVec(d(1, 1, 0));
      const double a = xu.norm(), b = xv.norm();
      const Vec c = xu.cross(xv);
      if (a <= kCollapsed * scale || b <= kCollapsed * scale || c.norm() <= 1e-12 * a * b) {
        // Singular: on a pole X_u ~ t X_uv (or X_v ~ t X_uv), t the parameter distance.
        known[q] = 0;
        if (a <= kCollapsed * scale && b > kCollapsed * scale) lhopital[q] = xuv.cross(xv);
        if (b <= kCollapsed * scale && a > kCollapsed * scale) lhopital[q] = xu.cross(xuv);
        continue;
      }
      const Vec n = side * c.normalized();
      // Shape operator I^-1 II: mean and Gauss curvature, the larger principal curvature.
      const double e = a * a, f = xu.dot(xv), gg = b * b, det = c.squaredNorm();
      const double l = ToVec(d(2, 0, 0)).dot(n), m = xuv.dot(n), nn = ToVec(d(0, 2, 0)).dot(n);
      const double h = (e * nn - 2.0 * f * m + gg * l) / (2.0 * det);
      const double k = (l * nn - m * m) / det;
      g.normal[q] = n;
      g.kappa[q] = h + std::sqrt(std::max(h * h - k, 0.0));
    }
  }
}

// Singular points: the l'Hopital normal oriented like the regular neighbours (or their mean
// normal when it vanishes too), their largest curvature; filled inwards from the regular ones
// (`known`), as far as they reach.
void FillSingular(const Shape& s, const Layer& lhopital, Geometry& g, std::vector<char>& known) {
  for (bool changed = true; changed;) {
    changed = false;
    const std::vector<char> before = known;
    for (int j = 0; j < s.nj; ++j) {
      for (int i = 0; i < s.ni; ++i) {
        const int64_t q = s.At(i, j);
        if (before[q]) continue;
        Vec mean = Vec::Zero();
        double kappa = -HUGE_VAL;
        for (int dj = -1; dj <= 1; ++dj) {
          for (int di = -1; di <= 1; ++di) {
            const int ii = i + di, jj = j + dj;
            if (ii < 0 || jj < 0 || ii >= s.ni || jj >= s.nj || !before[s.At(ii, jj)]) continue;
            mean += g.normal[s.At(ii, jj)];
            kappa = std::max(kappa, g.kappa[s.At(ii, jj)]);
          }
        }
        if (!(mean.norm() > 0.0)) continue;
        const Vec& c = lhopital[q];
        g.normal[q] =
            c.norm() > 0.0 ? (c.dot(mean) >= 0.0 ? c : Vec(-c)).normalized() : mean.normalized();
        g.kappa[q] = kappa;
        known[q] = 1;
        changed = true;
      }
    }
  }
}

// Every collapsed edge's points given one normal (the normalised mean, unless it vanishes) and
// their largest curvature.
void ShareOverCollapsedEdges(const EdgeGroups& collapsed, Geometry& g) {
  for (const auto& edge : collapsed) {
    Vec mean = Vec::Zero();
    double kappa = -HUGE_VAL;
    for (int64_t q : edge) {
      mean += g.normal[q];
      kappa = std::max(kappa, g.kappa[q]);
    }
    for (int64_t q : edge) {
      if (mean.norm() > 0.0) g.normal[q] = mean.normalized();
      g.kappa[q] = kappa;
    }
  }
}

// The Geometry of the layer `spline` at its data parameters `params`: regular points, then the
// singular ones filled in, then the collapsed edges made to agree; INVALID_ARGUMENT when no
// point is regular.
absl::StatusOr<Geometry> LayerGeometry(const TensorSpline& spline,
                                       const std::array<std::vector<double>, 3>& params,
                                       const Shape& s, int side, double scale,
                                       const EdgeGroups& collapsed) {
  Geometry g{Layer(s.size(), Vec::Zero()), std::vector<double>(s.size(), 0.0)};
  std::vector<char> known(s.size(), 1);
  Layer lhopital(s.size(), Vec::Zero());
  RegularGeometry(spline, params, s, side, scale, g, known, lhopital);
  FillSingular(s, lhopital, g, known);
  if (std::find(known.begin(), known.end(), 0) != known.end()) {
    return absl::InvalidArgumentError(
        "surface: the fitted surface has no regular point (X_u x X_v vanishes everywhere)");
  }
  ShareOverCollapsedEdges(collapsed, g);
  return g;
}

// The curvature each point's step is limited by: the spline's largest principal curvature
// `kappa`, or, if larger, how fast the normals in use converge along a grid edge at the point,
//   kappa_e = -(n_b - n_a).(x_b - x_a) / |x_b - x_a|^2,
// the discrete 1 - h kappa (the edge's extent along itself vanishes at h = 1 / kappa_e). The
// second catches what smoothing or a distorted layer does to the normals that the spline's
// curvature does not see.
std::vector<double> LimitingCurvature(const Layer& p, const Layer& normals,
                                      const std::vector<double>& kappa, const Shape& s) {
  std::vector<double> out = kappa;
  auto edge = [&](int64_t a, int64_t b) {
    const Vec dx = p[b] - p[a];
    const double length2 = dx.squaredNorm();
    if (!(length2 > 0.0)) return;  // a collapsed edge
    const double converge = -(normals[b] - normals[a]).dot(dx) / length2;
    out[a] = std::max(out[a], converge);
    out[b] = std::max(out[b], converge);
  };
  for (int j = 0; j < s.nj; ++j) {
    for (int i = 0; i < s.ni; ++i) {
      if (i + 1 < s.ni) edge(s.At(i, j), s.At(i + 1, j));
      if (j + 1 < s.nj) edge(s.At(i, j), s.At(i, j + 1));
    }
  }
  return out;
}

// One Jacobi sweep: every normal not `fixed` becomes the normalised (1 2 1) x (1 2 1) weighted
// mean of its 3 x 3 neighbourhood, on block edges the (1 2 1) mean along the edge.
void SmoothNormals(Layer& normals, const Shape& s, const std::vector<char>& fixed) {
  Layer next = normals;
  for (int j = 0; j < s.nj; ++j) {
    for (int i = 0; i < s.ni; ++i) {
      const int64_t q = s.At(i, j);
      if (fixed[q]) continue;
      const bool edge_i = i == 0 || i == s.ni - 1, edge_j = j == 0 || j == s.nj - 1;
      Vec m = Vec::Zero();
      if (edge_j) {
        m = normals[q - 1] + 2.0 * normals[q] + normals[q + 1];
      } else if (edge_i) {
        m = normals[q - s.ni] + 2.0 * normals[q] + normals[q + s.ni];
      } else {
        for (int dj = -1; dj <= 1; ++dj) {
          for (int di = -1; di <= 1; ++di) {
            m += static_cast<double>((2 - std::abs(di)) * (2 - std::abs(dj))) *
                 normals[s.At(i + di, j + dj)];
          }
        }
      }
      if (m.norm() > 0.0) next[q] = m.normalized();
    }
  }
  normals = std::move(next);
}

// The cells between layers p (below) and q (above): the smallest scaled corner Jacobian
// side det[x_i, x_j, x_k] / (|x_i| |x_j| |x_k|) and the first cell with one <= 0.
struct CellCheck {
  double min_scaled = 1.0;
  bool folded = false;
  int i = 0, j = 0;
};

CellCheck CheckCells(const Layer& p, const Layer& q, const Shape& s, int side) {
  CellCheck check;
  std::array<Vec, 8> x;
  std::array<std::array<Vec, 3>, 8> e;
  for (int j = 0; j + 1 < s.nj; ++j) {
    for (int i = 0; i + 1 < s.ni; ++i) {
      for (int c = 0; c < 8; ++c) x[c] = (c & 4 ? q : p)[s.At(i + (c & 1), j + ((c >> 1) & 1))];
      double longest = 0.0;
      for (int c = 0; c < 8; ++c) {
        e[c] = {x[c | 1] - x[c & ~1], x[c | 2] - x[c & ~2], x[c | 4] - x[c & ~4]};
        for (const Vec& edge : e[c]) longest = std::max(longest, edge.norm());
      }
      for (int c = 0; c < 8; ++c) {
        const double a = e[c][0].norm(), b = e[c][1].norm(), h = e[c][2].norm();
        if (std::min({a, b, h}) <= kCollapsedCellEdge * longest) continue;
        const double scaled = side * e[c][0].dot(e[c][1].cross(e[c][2])) / (a * b * h);
        check.min_scaled = std::min(check.min_scaled, scaled);
        if (!(scaled > 0.0) && !check.folded) {
          check.folded = true;
          check.i = i;
          check.j = j;
        }
      }
    }
  }
  return check;
}

// A faired displacement field: its spline and the field it gives at the data parameters.
struct Displacement {
  TensorSpline spline;
  Layer moved;
};

// The displacements d (one per point) fitted with the layer's parameters and knots, ends
// interpolated, fairing weight `lambda` (fairing.h), and evaluated back at the parameters.
absl::StatusOr<Displacement> FitDisplacement(const Layer& d, const Shape& s,
                                             const std::array<std::vector<double>, 3>& params,
                                             const std::array<KnotVector, 3>& knots, double lambda,
                                             const CancelCheck& cancel) {
  SG_ASSIGN_OR_RETURN(
      TensorSpline spline,
      FitTensor(ToBlock(d, s), params, knots, EndCondition::kInterpolate, cancel, {}, lambda));
  const StructuredBlock at = EvaluateGrid(spline, params);
  Layer moved(s.size());
  for (int64_t i = 0; i < s.size(); ++i) {
    const double* x = at.Point(i % s.ni, i / s.ni, 0);
    moved[i] = Vec(x[0], x[1], x[2]);
  }
  return Displacement{std::move(spline), std::move(moved)};
}

// a + b, two splines on the same knots.
absl::StatusOr<TensorSpline> AddSplines(const TensorSpline& a, const TensorSpline& b) {
  std::vector<double> control(a.control().begin(), a.control().end());
  for (size_t c = 0; c < control.size(); ++c) control[c] += b.control()[c];
  return TensorSpline::Create(a.all_knots(), a.spatial_dim(), std::move(control));
}

// The size checks of OffsetSurface's input: a finite 3D surface block of at least 4 x 4 points.
absl::Status CheckSurface(const StructuredBlock& surface) {
  const Extents& n = surface.extents();
  if (surface.spatial_dim() != 3) {
    return absl::InvalidArgumentError(
        absl::StrCat("surface: spatial_dim = ", surface.spatial_dim(), "; a 3D surface is needed"));
  }
  if (n[2] != 1) {
    return absl::InvalidArgumentError(absl::StrCat("surface: nk = ", n[2],
                                                   "; a surface block has nk = 1 (", n[0], " x ",
                                                   n[1], " x ", n[2], " given)"));
  }
  if (n[0] < 4 || n[1] < 4) {
    return absl::InvalidArgumentError(absl::StrCat(
        "surface: ", n[0], " x ", n[1], " points; at least 4 x 4 are needed for a cubic fit"));
  }
  return ValidateFinite(surface, "surface");
}

// The points of `surface` as a layer, and into `*scale` its size (the bounding-box diagonal).
absl::StatusOr<Layer> SurfacePoints(const StructuredBlock& surface, const Shape& s, double* scale) {
  Layer p(s.size());
  Vec lo = Vec::Constant(HUGE_VAL), hi = Vec::Constant(-HUGE_VAL);
  for (int64_t q = 0; q < s.size(); ++q) {
    const double* x = surface.Point(q % s.ni, q / s.ni, 0);
    p[q] = Vec(x[0], x[1], x[2]);
    lo = lo.cwiseMin(p[q]);
    hi = hi.cwiseMax(p[q]);
  }
  *scale = (hi - lo).norm();
  if (!(*scale > 0.0)) {
    return absl::InvalidArgumentError("surface: all points coincide; there is no surface");
  }
  return p;
}

// The points whose normals are not smoothed: corners (no neighbours on both sides along an
// edge) and collapsed edges.
std::vector<char> UnsmoothedPoints(const Shape& s, const EdgeGroups& collapsed) {
  std::vector<char> fixed(s.size(), 0);
  for (int64_t q : {s.At(0, 0), s.At(s.ni - 1, 0), s.At(0, s.nj - 1), s.At(s.ni - 1, s.nj - 1)}) {
    fixed[q] = 1;
  }
  for (const auto& edge : collapsed) {
    for (int64_t q : edge) fixed[q] = 1;
  }
  return fixed;
}

// What OffsetSurface's layers share: the options, the layer shape, the collapsed edges, the
// points not smoothed and the surface spline's parameters.
struct MarchContext {
  const SurfaceOffsetOptions& options;
  Shape s;
  const EdgeGroups& collapsed;
  const std::vector<char>& fixed;
  const std::array<std::vector<double>, 3>& params;
};

// One layer's steps: wanted (h plus the height denied earlier), taken (curvature limited), and
// the curvature that limited them.
struct LayerSteps {
  std::vector<double> want, step, kappa;
};

// The steps of the layer above p along `normals` (LimitingCurvature with the spline's `kappa`),
// the points of a collapsed edge all taking the smallest of theirs.
void LimitedSteps(const Layer& p, const Layer& normals, const std::vector<double>& kappa, double h,
                  const std::vector<double>& deficit, const MarchContext& c, LayerSteps& steps) {
  // Curvature limit, with the height denied earlier carried over.
  steps.kappa = LimitingCurvature(p, normals, kappa, c.s);
  for (int64_t i = 0; i < c.s.size(); ++i) {
    steps.want[i] = h + deficit[i];
    steps.step[i] = steps.kappa[i] > 0.0
                        ? std::min(steps.want[i], c.options.max_curvature_step / steps.kappa[i])
                        : steps.want[i];
  }
  for (const auto& edge : c.collapsed) {
    double common = HUGE_VAL;
    for (int64_t i : edge) common = std::min(common, steps.step[i]);
    for (int64_t i : edge) steps.step[i] = common;
  }
}

// The layer q above p, its normals smoothed two more sweeps per retry (counted in `*retries`)
// until its cells do not fold or max_retries is spent; the check of the last attempt.
CellCheck OffsetWithRetries(const Layer& p, Geometry& geometry, double h,
                            const std::vector<double>& deficit, const MarchContext& c,
                            LayerSteps& steps, Layer& q, int* retries) {
  Layer& normals = geometry.normal;
  CellCheck check;
  for (int attempt = 0; attempt <= c.options.max_retries; ++attempt) {
    if (attempt > 0) {
      for (int t = 0; t < 2 * attempt; ++t) SmoothNormals(normals, c.s, c.fixed);
      ++*retries;
    }
    LimitedSteps(p, normals, geometry.kappa, h, deficit, c, steps);
    for (int64_t i = 0; i < c.s.size(); ++i) q[i] = p[i] + steps.step[i] * normals[i];
    Unite(q, c.collapsed);
    check = CheckCells(p, q, c.s, c.options.side);
    if (!check.folded) break;
  }
  return check;
}

// The error for layer k + 1 (step h) folding at `check` after every retry: the curvature limit
// is named when it held steps back.
absl::Status FoldedLayerError(const CellCheck& check, int k, double h, const LayerSteps& steps,
                              const SurfaceOffsetOptions& options) {
  double held_back = 0.0;
  for (size_t i = 0; i < steps.want.size(); ++i) {
    held_back = std::max(held_back, steps.want[i] - steps.step[i]);
  }
  if (held_back > 0.0) {
    return absl::FailedPreconditionError(absl::StrCat(
        "distance = ", options.distance, " is not reachable on the concave side: layer ", k + 1,
        " folds at cell (", check.i, ", ", check.j,
        ") while the curvature limit (max_curvature_step = ", options.max_curvature_step,
        ") holds its steps up to ", held_back, " short; lower the distance"));
  }
  return absl::FailedPreconditionError(absl::StrCat(
      "layer ", k + 1, " folds at cell (", check.i, ", ", check.j,
      ") even with smoothed normals (step ", h, ", max_retries = ", options.max_retries,
      "); use more layers, a smaller growth or a smoother surface"));
}

// Fairs the displacement p -> q with weight `lambda` and adds its spline to `fit` (file
// comment); q and `check` become the faired layer's unless it folds a cell, in which case the
// interpolating displacement is added instead (counted in `*refits_dropped`).
absl::Status FairLayer(const Layer& p, double lambda, const MarchContext& c, Layer& q,
                       CellCheck& check, TensorSpline& fit, int* refits_dropped) {
  const Shape& s = c.s;
  Layer d(s.size());
  for (int64_t i = 0; i < s.size(); ++i) d[i] = q[i] - p[i];
  SG_ASSIGN_OR_RETURN(Displacement faired,
                      FitDisplacement(d, s, c.params, fit.all_knots(), lambda, c.options.cancel));
  for (int64_t i = 0; i < s.size(); ++i) faired.moved[i] += p[i];
  Unite(faired.moved, c.collapsed);
  if (const CellCheck faired_check = CheckCells(p, faired.moved, s, c.options.side);
      !faired_check.folded) {
    q = std::move(faired.moved);
    check = faired_check;
  } else {
    ++*refits_dropped;
    SG_ASSIGN_OR_RETURN(faired,
                        FitDisplacement(d, s, c.params, fit.all_knots(), 0.0, c.options.cancel));
  }
  SG_ASSIGN_OR_RETURN(fit, AddSplines(fit, faired.spline));
  return absl::OkStatus();
}

// Counts the limited steps and carries the height they held back into `deficit`; refused as
// soon as the height held back anywhere exceeds what the last layer may miss: towards a centre
// of curvature it is not given back, and marching on only distorts the layers there.
absl::Status CarryDeficit(const LayerSteps& steps, int k, const MarchContext& c,
                          std::vector<double>& deficit, SurfaceOffsetGrid& out) {
  const SurfaceOffsetOptions& options = c.options;
  for (int64_t i = 0; i < c.s.size(); ++i) {
    if (steps.step[i] < steps.want[i]) ++out.limited_steps;
  }
  for (int64_t i = 0; i < c.s.size(); ++i) deficit[i] = steps.want[i] - steps.step[i];
  const auto worst = std::max_element(deficit.begin(), deficit.end());
  out.shortfall = *worst;
  if (out.shortfall > options.max_shortfall * options.distance) {
    const int64_t at = worst - deficit.begin();
    return absl::FailedPreconditionError(absl::StrCat(
        "distance = ", options.distance,
        " cannot be reached on the concave side: at surface point (", at % c.s.ni, ", ",
        at / c.s.ni, ") layer ", k + 1, " is ", out.shortfall,
        " short, its steps limited to max_curvature_step = ", options.max_curvature_step,
        " of the radius of curvature (", 1.0 / steps.kappa[at],
        " there); allowed: max_shortfall = ", options.max_shortfall, " of the distance"));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status SurfaceOffsetOptions::Validate() const {
  SG_RETURN_IF_ERROR(ValidateLayerStack(layers, first_height, distance));
  if (side != 1 && side != -1) {
    return absl::InvalidArgumentError(absl::StrCat("side = ", side, " is neither +1 nor -1"));
  }
  if (normal_smoothing < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("normal_smoothing = ", normal_smoothing, " is negative"));
  }
  if (!(fairing >= 0.0) || !std::isfinite(fairing)) {
    return absl::InvalidArgumentError(
        absl::StrCat("fairing = ", fairing, " is not a finite number >= 0"));
  }
  if (!(surface_fairing >= 0.0) || !std::isfinite(surface_fairing)) {
    return absl::InvalidArgumentError(
        absl::StrCat("surface_fairing = ", surface_fairing, " is not a finite number >= 0"));
  }
  if (!(max_curvature_step > 0.0 && max_curvature_step < 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_curvature_step = ", max_curvature_step, " is outside (0, 1)"));
  }
  if (!(max_shortfall >= 0.0 && max_shortfall <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_shortfall = ", max_shortfall, " is outside [0, 1]"));
  }
  if (max_retries < 0) {
    return absl::InvalidArgumentError(absl::StrCat("max_retries = ", max_retries, " is negative"));
  }
  return absl::OkStatus();
}

absl::StatusOr<SurfaceOffsetGrid> OffsetSurface(const StructuredBlock& surface,
                                                const SurfaceOffsetOptions& options) {
  SG_RETURN_IF_ERROR(options.Validate());
  SG_RETURN_IF_ERROR(CheckSurface(surface));
  const Shape s{surface.extent(0), surface.extent(1)};
  double scale = 0.0;
  SG_ASSIGN_OR_RETURN(Layer p, SurfacePoints(surface, s, &scale));
  const EdgeGroups collapsed = CollapsedEdges(p, s, kCollapsed * scale);
  const std::vector<char> fixed = UnsmoothedPoints(s, collapsed);

  SurfaceOffsetGrid out;
  out.growth_ratio = GeometricRatio(options.first_height, options.distance, options.layers);
  out.block = StructuredBlock({s.ni, s.nj, options.layers + 1}, 3);
  auto store = [&](int k) {
    for (int64_t q = 0; q < s.size(); ++q) {
      std::copy(p[q].data(), p[q].data() + 3, out.block.Point(q % s.ni, q / s.ni, k));
    }
  };
  store(0);
  // The surface's (faired) spline, for normals and curvatures only: k = 0 is the surface as
  // given, and every layer keeps its parameters and knots.
  FitOptions fit_options;
  fit_options.cancel = options.cancel;
  fit_options.fairing = options.surface_fairing;
  SG_ASSIGN_OR_RETURN(const FittedBlock surface_fit, FitBlock(surface, fit_options));
  const std::array<std::vector<double>, 3> params = {
      surface_fit.distribution.params(0), surface_fit.distribution.params(1), {0.0}};
  const MarchContext c{options, s, collapsed, fixed, params};
  TensorSpline fit = surface_fit.spline;
  std::vector<double> deficit(s.size(), 0.0);
  LayerSteps steps{std::vector<double>(s.size()), std::vector<double>(s.size()),
                   std::vector<double>(s.size(), 0.0)};
  Layer q(s.size());
  for (int k = 0; k < options.layers; ++k) {
    SG_RETURN_IF_ERROR(PollCancel(options.cancel));
    const double h = options.first_height * std::pow(out.growth_ratio, k);
    out.steps.push_back(h);
    const double fraction = static_cast<double>(k + 1) / options.layers;
    SG_ASSIGN_OR_RETURN(Geometry geometry,
                        LayerGeometry(fit, params, s, options.side, scale, collapsed));
    const int sweeps = static_cast<int>(std::lround(options.normal_smoothing * fraction));
    for (int t = 0; t < sweeps; ++t) SmoothNormals(geometry.normal, s, fixed);
    CellCheck check = OffsetWithRetries(p, geometry, h, deficit, c, steps, q, &out.retries);
    if (check.folded) return FoldedLayerError(check, k, h, steps, options);
    // Fair the displacement and add its spline to the layer's (file comment); a faired
    // displacement that folds a cell is dropped for the interpolating one.
    SG_RETURN_IF_ERROR(
        FairLayer(p, options.fairing * fraction, c, q, check, fit, &out.refits_dropped));
    out.min_scaled_jacobian = std::min(out.min_scaled_jacobian, check.min_scaled);
    SG_RETURN_IF_ERROR(CarryDeficit(steps, k, c, deficit, out));
    std::swap(p, q);
    store(k + 1);
  }
  return out;
}

}  // namespace splinegrid
