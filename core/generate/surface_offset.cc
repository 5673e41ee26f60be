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
#include "core/fit/tensor_fit.h"
#include "core/generate/offset_march.h"
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

absl::StatusOr<Geometry> LayerGeometry(const TensorSpline& spline,
                                       const std::array<std::vector<double>, 3>& params,
                                       const Shape& s, int side, double scale,
                                       const EdgeGroups& collapsed) {
  const std::vector<double>& u = params[0];
  const std::vector<double>& v = params[1];
  Geometry g{Layer(s.size(), Vec::Zero()), std::vector<double>(s.size(), 0.0)};
  std::vector<char> known(s.size(), 1);
  Layer lhopital(s.size(), Vec::Zero());
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
  // Singular points: the l'Hopital normal oriented like the regular neighbours (or their mean
  // normal when it vanishes too), their largest curvature; filled inwards from the regular ones.
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
  if (std::find(known.begin(), known.end(), 0) != known.end()) {
    return absl::InvalidArgumentError(
        "surface: the fitted surface has no regular point (X_u x X_v vanishes everywhere)");
  }
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
  SG_RETURN_IF_ERROR(ValidateFinite(surface, "surface"));
  const Shape s{n[0], n[1]};
  Layer p(s.size());
  Vec lo = Vec::Constant(HUGE_VAL), hi = Vec::Constant(-HUGE_VAL);
  for (int64_t q = 0; q < s.size(); ++q) {
    const double* x = surface.Point(q % s.ni, q / s.ni, 0);
    p[q] = Vec(x[0], x[1], x[2]);
    lo = lo.cwiseMin(p[q]);
    hi = hi.cwiseMax(p[q]);
  }
  const double scale = (hi - lo).norm();
  if (!(scale > 0.0)) {
    return absl::InvalidArgumentError("surface: all points coincide; there is no surface");
  }
  const EdgeGroups collapsed = CollapsedEdges(p, s, kCollapsed * scale);
  // Not smoothed: corners (no neighbours on both sides along an edge) and collapsed edges.
  std::vector<char> fixed(s.size(), 0);
  for (int64_t q : {s.At(0, 0), s.At(s.ni - 1, 0), s.At(0, s.nj - 1), s.At(s.ni - 1, s.nj - 1)}) {
    fixed[q] = 1;
  }
  for (const auto& edge : collapsed) {
    for (int64_t q : edge) fixed[q] = 1;
  }

  SurfaceOffsetGrid out;
  out.growth_ratio = GrowthRatio(options.first_height, options.distance, options.layers);
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
  TensorSpline fit = surface_fit.spline;
  std::vector<double> deficit(s.size(), 0.0), step(s.size()), want(s.size());
  std::vector<double> last_kappa(s.size(), 0.0);
  Layer q(s.size());
  for (int k = 0; k < options.layers; ++k) {
    SG_RETURN_IF_ERROR(PollCancel(options.cancel));
    const double h = options.first_height * std::pow(out.growth_ratio, k);
    out.steps.push_back(h);
    const double fraction = static_cast<double>(k + 1) / options.layers;
    SG_ASSIGN_OR_RETURN(Geometry geometry,
                        LayerGeometry(fit, params, s, options.side, scale, collapsed));
    Layer& normals = geometry.normal;
    const int sweeps = static_cast<int>(std::lround(options.normal_smoothing * fraction));
    for (int t = 0; t < sweeps; ++t) SmoothNormals(normals, s, fixed);
    CellCheck check;
    for (int attempt = 0; attempt <= options.max_retries; ++attempt) {
      if (attempt > 0) {
        for (int t = 0; t < 2 * attempt; ++t) SmoothNormals(normals, s, fixed);
        ++out.retries;
      }
      // Curvature limit, with the height denied earlier carried over.
      last_kappa = LimitingCurvature(p, normals, geometry.kappa, s);
      for (int64_t i = 0; i < s.size(); ++i) {
        want[i] = h + deficit[i];
        step[i] = last_kappa[i] > 0.0
                      ? std::min(want[i], options.max_curvature_step / last_kappa[i])
                      : want[i];
      }
      for (const auto& edge : collapsed) {
        double common = HUGE_VAL;
        for (int64_t i : edge) common = std::min(common, step[i]);
        for (int64_t i : edge) step[i] = common;
      }
      for (int64_t i = 0; i < s.size(); ++i) q[i] = p[i] + step[i] * normals[i];
      Unite(q, collapsed);
      check = CheckCells(p, q, s, options.side);
      if (!check.folded) break;
    }
    if (check.folded) {
      double held_back = 0.0;
      for (int64_t i = 0; i < s.size(); ++i) held_back = std::max(held_back, want[i] - step[i]);
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
    // Fair the displacement and add its spline to the layer's (file comment); a faired
    // displacement that folds a cell is dropped for the interpolating one.
    Layer d(s.size());
    for (int64_t i = 0; i < s.size(); ++i) d[i] = q[i] - p[i];
    SG_ASSIGN_OR_RETURN(
        Displacement faired,
        FitDisplacement(d, s, params, fit.all_knots(), options.fairing * fraction, options.cancel));
    for (int64_t i = 0; i < s.size(); ++i) faired.moved[i] += p[i];
    Unite(faired.moved, collapsed);
    if (const CellCheck faired_check = CheckCells(p, faired.moved, s, options.side);
        !faired_check.folded) {
      q = std::move(faired.moved);
      check = faired_check;
    } else {
      ++out.refits_dropped;
      SG_ASSIGN_OR_RETURN(faired,
                          FitDisplacement(d, s, params, fit.all_knots(), 0.0, options.cancel));
    }
    SG_ASSIGN_OR_RETURN(fit, AddSplines(fit, faired.spline));
    for (int64_t i = 0; i < s.size(); ++i) {
      if (step[i] < want[i]) ++out.limited_steps;
    }
    out.min_scaled_jacobian = std::min(out.min_scaled_jacobian, check.min_scaled);
    for (int64_t i = 0; i < s.size(); ++i) deficit[i] = want[i] - step[i];
    // Refused as soon as the height held back anywhere exceeds what the last layer may miss:
    // towards a centre of curvature it is not given back, and marching on only distorts the
    // layers there.
    const auto worst = std::max_element(deficit.begin(), deficit.end());
    out.shortfall = *worst;
    if (out.shortfall > options.max_shortfall * options.distance) {
      const int64_t at = worst - deficit.begin();
      return absl::FailedPreconditionError(absl::StrCat(
          "distance = ", options.distance,
          " cannot be reached on the concave side: at surface point (", at % s.ni, ", ", at / s.ni,
          ") layer ", k + 1, " is ", out.shortfall,
          " short, its steps limited to max_curvature_step = ", options.max_curvature_step,
          " of the radius of curvature (", 1.0 / last_kappa[at],
          " there); allowed: max_shortfall = ", options.max_shortfall, " of the distance"));
    }
    std::swap(p, q);
    store(k + 1);
  }
  return out;
}

}  // namespace splinegrid
