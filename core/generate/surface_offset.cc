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
#include "core/fit/adaptive/refinement.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/generate/concave_crease.h"
#include "core/generate/offset_march.h"
#include "core/grid/sampling.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

using Vec = Eigen::Vector3d;
// Per block point (i fastest) or per vertex of the surface (surface_topology.h).
using Layer = std::vector<Vec>;

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

// The layer's block points as an ni x nj x 1 block.
StructuredBlock ToBlock(const Layer& p, const Shape& s) {
  StructuredBlock block({s.ni, s.nj, 1}, 3);
  for (int64_t q = 0; q < s.size(); ++q)
    std::copy(p[q].data(), p[q].data() + 3, block.Point(q % s.ni, q / s.ni, 0));
  return block;
}

// The unit normals (oriented by `side`) of a fitted layer at its regular points (at its data
// parameters; X_u and X_v on the whole grid by sum factorisation); at singular ones (X_u x X_v
// vanishes) `known` is cleared and `lhopital` holds the l'Hopital normal direction.
void RegularNormals(const TensorSpline& spline, const std::array<std::vector<double>, 3>& params,
                    const Shape& s, int side, double scale, Layer& normal, std::vector<char>& known,
                    Layer& lhopital) {
  GridEvaluator evaluator(spline, params, /*first_derivatives=*/true);
  std::vector<double> points(3 * s.size()), du(3 * s.size()), dv(3 * s.size()), dw(3 * s.size());
  evaluator.EvaluateLines(0, evaluator.num_lines(), points.data(), du.data(), dv.data(), dw.data());
  for (int64_t q = 0; q < s.size(); ++q) {
    const Vec xu(du[3 * q], du[3 * q + 1], du[3 * q + 2]);
    const Vec xv(dv[3 * q], dv[3 * q + 1], dv[3 * q + 2]);
    const double a = xu.norm(), b = xv.norm();
    const Vec c = xu.cross(xv);
    if (a <= kCollapsedFraction * scale || b <= kCollapsedFraction * scale ||
        c.norm() <= 1e-12 * a * b) {
      // Singular: on a pole X_u ~ t X_uv (or X_v ~ t X_uv), t the parameter distance.
      known[q] = 0;
      const PartialDerivatives d =
          EvaluateDerivatives(spline, {params[0][q % s.ni], params[1][q / s.ni], 0.0}, 2);
      const Vec xuv = ToVec(d(1, 1, 0));
      if (a <= kCollapsedFraction * scale && b > kCollapsedFraction * scale)
        lhopital[q] = xuv.cross(xv);
      if (b <= kCollapsedFraction * scale && a > kCollapsedFraction * scale)
        lhopital[q] = xu.cross(xuv);
      continue;
    }
    normal[q] = side * c.normalized();
  }
}

// Singular points: the l'Hopital normal oriented like the regular neighbours (or their mean
// normal when it vanishes too); filled inwards from the regular ones (`known`), as far as they
// reach.
void FillSingular(const Shape& s, const Layer& lhopital, Layer& normal, std::vector<char>& known) {
  for (bool changed = true; changed;) {
    changed = false;
    const std::vector<char> before = known;
    for (int j = 0; j < s.nj; ++j) {
      for (int i = 0; i < s.ni; ++i) {
        const int64_t q = s.At(i, j);
        if (before[q]) continue;
        Vec mean = Vec::Zero();
        for (int dj = -1; dj <= 1; ++dj) {
          for (int di = -1; di <= 1; ++di) {
            const int ii = i + di, jj = j + dj;
            if (ii < 0 || jj < 0 || ii >= s.ni || jj >= s.nj || !before[s.At(ii, jj)]) continue;
            mean += normal[s.At(ii, jj)];
          }
        }
        if (!(mean.norm() > 0.0)) continue;
        const Vec& c = lhopital[q];
        normal[q] =
            c.norm() > 0.0 ? (c.dot(mean) >= 0.0 ? c : Vec(-c)).normalized() : mean.normalized();
        known[q] = 1;
        changed = true;
      }
    }
  }
}

// One surface block's share of the march: its shape, orientation, the surface spline's
// parameters, the spline of the current layer, and the vertex of each point.
struct BlockMarch {
  Shape s;
  int side = 1;
  std::array<std::vector<double>, 3> params;
  TensorSpline fit;
  const std::vector<int64_t>* vertex = nullptr;
  // Per direction i, j: the indices of the grid lines across which the surface kinks
  // (SurfaceKinks); the block's splines are only C0 there.
  std::array<std::vector<int>, 2> kinks;

  int64_t V(int i, int j) const { return (*vertex)[s.At(i, j)]; }
};

// The weights of the normal smoothing (surface_topology.h's kinds), per vertex the
// neighbouring vertices and their weights (rows in CSR form, built once): a shared vertex takes
// the sum of the (1 2 1) x (1 2 1) stencils of all its block points (each cut off at its
// block's edges); a free-edge vertex the (1 2 1) stencil along its edge; a fixed one none. A
// concave crease (concave_crease.h) is smoothed along itself, and its faces without it.
struct SmoothingStencil {
  std::vector<int64_t> start;  // row v is [start[v], start[v + 1])
  std::vector<int64_t> neighbour;
  std::vector<double> weight;
};

// What the layers share: the options, the topology, the blocks, the surface's size, the
// smoothing weights.
struct March {
  const SurfaceOffsetOptions& options;
  const SurfaceTopology& topology;
  std::vector<BlockMarch> blocks;
  double scale = 0.0;
  SmoothingStencil stencil;
  VertexGraph graph;  // the grid edges of every block, between vertices
  // The concave creases of the surface (concave_crease.h) and their points on it: the crease of
  // the layer at height H is at origin + H offset.
  ConcaveCreases creases;
  CreaseSlides slides;  // of the creases near corners
  std::vector<Vec> crease_origin;
  std::vector<char> is_crease;  // per vertex
  int64_t num_vertices() const { return topology.num_vertices; }
};

// Normals kept parallel to the symmetry planes their vertices lie on.
void ProjectNormals(const March& m, Layer& normals) {
  for (int64_t v = 0; v < m.num_vertices(); ++v) {
    if (m.topology.plane[v] == 0) continue;
    Vec n = normals[v];
    for (size_t p = 0; p < m.topology.planes.size(); ++p) {
      if (m.topology.plane[v] >> p & 1) n[m.topology.planes[p].axis] = 0.0;
    }
    if (n.norm() > 0.0) normals[v] = n.normalized();
  }
}

// Points kept on the symmetry planes their vertices lie on.
void ProjectPoints(const March& m, Layer& points) {
  for (int64_t v = 0; v < m.num_vertices(); ++v) {
    for (size_t p = 0; p < m.topology.planes.size(); ++p) {
      if (m.topology.plane[v] >> p & 1) {
        points[v][m.topology.planes[p].axis] = m.topology.planes[p].value;
      }
    }
  }
}

// Near a symmetry plane a normal that leans towards it has that lean scaled by
// min(1, d / height), d the vertex's distance to the plane and `height` the layer's total height
// above the surface: the front meets the plane at right angles, and the vertices' distances to
// the plane map by d -> d - h c min(1, d / height) (c the lean, h <= height the step), which is
// monotone in d, so no row of the layer overtakes another towards the plane.
void LeanTowardsPlanes(const March& m, const Layer& p, double height, Layer& normals) {
  for (size_t index = 0; index < m.topology.planes.size(); ++index) {
    const SymmetryPlane& plane = m.topology.planes[index];
    for (int64_t v = 0; v < m.num_vertices(); ++v) {
      const double d = p[v][plane.axis] - plane.value;  // signed: the surface's side
      Vec& n = normals[v];
      if ((m.topology.plane[v] >> index & 1) || !(n[plane.axis] * d < 0.0)) continue;
      n[plane.axis] *= std::min(1.0, std::abs(d) / height);
      n.normalize();
    }
  }
}

// The unit normals of `block` on either side of its kinked grid line (BlockMarch::kinks) at
// index c of direction d, at point t along the line: X_d^- x X_t and X_d^+ x X_t (one-sided
// differences of the layer `p` across the line, central along it) in the order of X_i x X_j,
// times the block's side.
std::array<Vec, 2> KinkNormals(const BlockMarch& block, const Layer& p, int d, int c, int t) {
  const int along = d == 0 ? block.s.nj : block.s.ni;
  auto at = [&](int across, int line) -> const Vec& {
    return p[d == 0 ? block.V(across, line) : block.V(line, across)];
  };
  const Vec tangent = at(c, std::min(t + 1, along - 1)) - at(c, std::max(t - 1, 0));
  const Vec before = at(c, t) - at(c - 1, t), after = at(c + 1, t) - at(c, t);
  const double sign = block.side * (d == 0 ? 1.0 : -1.0);
  return {(sign * before.cross(tangent)).normalized(), (sign * after.cross(tangent)).normalized()};
}

// Per vertex: the normalised mean of its block points' normals (from each block's layer
// spline; on a kinked grid line, where the spline is only C0, the mean of the normals on either
// side, KinkNormals); with `faces`, also the faces a crease needs (FindConcaveCreases): each
// block point's normal at every vertex joined from several, and both sides' normals at the
// points of a kinked line (empty elsewhere). INVALID_ARGUMENT when a block's fitted layer has no
// regular point.
absl::StatusOr<Layer> VertexNormals(const March& m, const Layer& p,
                                    std::vector<std::vector<Vec>>* faces = nullptr) {
  Layer normal(m.num_vertices(), Vec::Zero());
  std::vector<Layer> block_normals;
  std::vector<std::vector<std::pair<int64_t, std::array<Vec, 2>>>> kink_faces;
  std::vector<int> joined(m.num_vertices(), 0);  // block points per vertex
  for (size_t b = 0; b < m.blocks.size(); ++b) {
    const BlockMarch& block = m.blocks[b];
    const Shape& s = block.s;
    Layer local(s.size(), Vec::Zero());
    std::vector<char> known(s.size(), 1);
    Layer lhopital(s.size(), Vec::Zero());
    RegularNormals(block.fit, block.params, s, block.side, m.scale, local, known, lhopital);
    FillSingular(s, lhopital, local, known);
    if (std::find(known.begin(), known.end(), 0) != known.end()) {
      return absl::InvalidArgumentError(
          absl::StrCat("surface block ", b,
                       ": the fitted surface has no regular point (X_u x X_v vanishes "
                       "everywhere)"));
    }
    kink_faces.emplace_back();
    for (int d = 0; d < 2; ++d) {
      for (const int c : block.kinks[d]) {
        for (int t = 0; t < (d == 0 ? s.nj : s.ni); ++t) {
          const int64_t q = d == 0 ? s.At(c, t) : s.At(t, c);
          const std::array<Vec, 2> sides = KinkNormals(block, p, d, c, t);
          local[q] = (sides[0] + sides[1]).normalized();
          if (faces != nullptr) kink_faces.back().emplace_back(q, sides);
        }
      }
    }
    for (int64_t q = 0; q < s.size(); ++q) {
      const int64_t v = (*block.vertex)[q];
      normal[v] += local[q];
      ++joined[v];
    }
    if (faces != nullptr) block_normals.push_back(std::move(local));
  }
  for (Vec& n : normal) {
    if (n.norm() > 0.0) n.normalize();
  }
  if (faces != nullptr) {
    faces->assign(m.num_vertices(), {});
    for (size_t b = 0; b < m.blocks.size(); ++b) {
      const std::vector<int64_t>& vertex = *m.blocks[b].vertex;
      std::vector<char> kinked(m.blocks[b].s.size(), 0);
      for (const auto& [q, sides] : kink_faces[b]) {
        kinked[q] = 1;
        (*faces)[vertex[q]].push_back(sides[0]);
        (*faces)[vertex[q]].push_back(sides[1]);
      }
      for (int64_t q = 0; q < m.blocks[b].s.size(); ++q) {
        if (joined[vertex[q]] > 1 && !kinked[q]) (*faces)[vertex[q]].push_back(block_normals[b][q]);
      }
    }
  }
  ProjectNormals(m, normal);
  return normal;
}

// The grid edges of every block as a graph of vertices.
VertexGraph BuildGridGraph(const March& m) {
  std::vector<std::pair<int64_t, int64_t>> edges;
  for (const BlockMarch& block : m.blocks) {
    for (int j = 0; j < block.s.nj; ++j) {
      for (int i = 0; i < block.s.ni; ++i) {
        if (i + 1 < block.s.ni) edges.emplace_back(block.V(i, j), block.V(i + 1, j));
        if (j + 1 < block.s.nj) edges.emplace_back(block.V(i, j), block.V(i, j + 1));
      }
    }
  }
  return BuildVertexGraph(m.num_vertices(), edges);
}

// The stencil of the march's blocks and vertex kinds.
SmoothingStencil BuildSmoothingStencil(const March& m) {
  std::vector<std::vector<std::pair<int64_t, double>>> rows(m.num_vertices());
  for (const BlockMarch& block : m.blocks) {
    const Shape& s = block.s;
    for (int j = 0; j < s.nj; ++j) {
      for (int i = 0; i < s.ni; ++i) {
        const int64_t v = block.V(i, j);
        auto& row = rows[v];
        switch (m.topology.kind[v]) {
          case VertexKind::kFixed:
            break;
          case VertexKind::kFreeEdge: {  // one block point: the row is its own
            const bool along_i = j == 0 || j == s.nj - 1;
            row = {{along_i ? block.V(i - 1, j) : block.V(i, j - 1), 1.0},
                   {v, 2.0},
                   {along_i ? block.V(i + 1, j) : block.V(i, j + 1), 1.0}};
            break;
          }
          case VertexKind::kShared:
            for (int dj = -1; dj <= 1; ++dj) {
              for (int di = -1; di <= 1; ++di) {
                const int ii = i + di, jj = j + dj;
                if (ii < 0 || jj < 0 || ii >= s.ni || jj >= s.nj) continue;
                row.emplace_back(block.V(ii, jj), (2 - std::abs(di)) * (2 - std::abs(dj)));
              }
            }
            break;
        }
      }
    }
  }
  SmoothingStencil stencil;
  stencil.start.push_back(0);
  for (int64_t v = 0; v < m.num_vertices(); ++v) {
    for (const auto& [neighbour, weight] : rows[v]) {
      // A concave crease is a feature line: smoothed along itself only, and not into its faces.
      if (m.is_crease[v] != m.is_crease[neighbour]) continue;
      stencil.neighbour.push_back(neighbour);
      stencil.weight.push_back(weight);
    }
    stencil.start.push_back(static_cast<int64_t>(stencil.neighbour.size()));
  }
  return stencil;
}

// One Jacobi sweep: every vertex with a stencil row takes the normalised weighted sum of its
// neighbours' normals, kept parallel to its symmetry plane.
void SmoothNormals(const March& m, const SmoothingStencil& stencil, Layer& normals) {
  Layer next = normals;
  for (int64_t v = 0; v < m.num_vertices(); ++v) {
    Vec sum = Vec::Zero();
    for (int64_t e = stencil.start[v]; e < stencil.start[v + 1]; ++e) {
      sum += stencil.weight[e] * normals[stencil.neighbour[e]];
    }
    if (sum.norm() > 0.0) next[v] = sum.normalized();
  }
  normals = std::move(next);
  ProjectNormals(m, normals);
}

// `sweeps` Jacobi sweeps, polling the cancel check between them.
absl::Status Smooth(const March& m, int sweeps, Layer& normals) {
  for (int t = 0; t < sweeps; ++t) {
    SG_RETURN_IF_ERROR(PollCancel(m.options.cancel));
    SmoothNormals(m, m.stencil, normals);
  }
  return absl::OkStatus();
}

// The curvature each vertex's step is limited by (file comment): the fastest convergence of the
// normals in use along a grid edge at the vertex, over the grid edges of every block,
//   kappa_e = -(n_b - n_a).(x_b - x_a) / |x_b - x_a|^2;
// zero where they diverge everywhere (convex). Edges at a concave crease are left out: the
// crease's normals converge at once, but its offset does not focus (concave_crease.h).
std::vector<double> LimitingCurvature(const March& m, const Layer& p, const Layer& normals) {
  std::vector<double> out(m.num_vertices(), 0.0);
  for (int64_t a = 0; a < m.num_vertices(); ++a) {
    if (m.is_crease[a]) continue;
    for (int64_t e = m.graph.start[a]; e < m.graph.start[a + 1]; ++e) {
      const int64_t b = m.graph.neighbour[e];
      if (m.is_crease[b]) continue;
      const Vec dx = p[b] - p[a];
      const double length2 = dx.squaredNorm();
      if (!(length2 > 0.0)) continue;  // coinciding points
      out[a] = std::max(out[a], -(normals[b] - normals[a]).dot(dx) / length2);
    }
  }
  return out;
}

// A check of the cells between two layers: the smallest scaled corner Jacobian
// side det[x_i, x_j, x_k] / (|x_i| |x_j| |x_k|) and the first cell with one <= 0.
struct CellCheck {
  double min_scaled = 1.0;
  bool folded = false;
  int block = 0, i = 0, j = 0;
};

// The cells of every block between vertex layers p (below) and q (above), each block with its
// side: the smallest scaled corner Jacobian and the first block and cell with one <= 0.
CellCheck CheckCells(const March& m, const Layer& p, const Layer& q) {
  CellCheck check;
  std::array<Vec, 8> x;
  std::array<std::array<Vec, 3>, 8> e;
  for (size_t b = 0; b < m.blocks.size(); ++b) {
    const BlockMarch& block = m.blocks[b];
    const Shape& s = block.s;
    for (int j = 0; j + 1 < s.nj; ++j) {
      for (int i = 0; i + 1 < s.ni; ++i) {
        for (int c = 0; c < 8; ++c) {
          x[c] = (c & 4 ? q : p)[block.V(i + (c & 1), j + ((c >> 1) & 1))];
        }
        double longest = 0.0;
        for (int c = 0; c < 8; ++c) {
          e[c] = {x[c | 1] - x[c & ~1], x[c | 2] - x[c & ~2], x[c | 4] - x[c & ~4]};
          for (const Vec& edge : e[c]) longest = std::max(longest, edge.norm());
        }
        for (int c = 0; c < 8; ++c) {
          const double a = e[c][0].norm(), bb = e[c][1].norm(), h = e[c][2].norm();
          if (std::min({a, bb, h}) <= kCollapsedCellEdge * longest) continue;
          const double scaled = block.side * e[c][0].dot(e[c][1].cross(e[c][2])) / (a * bb * h);
          check.min_scaled = std::min(check.min_scaled, scaled);
          if (!(scaled > 0.0) && !check.folded) {
            check.folded = true;
            check.block = static_cast<int>(b);
            check.i = i;
            check.j = j;
          }
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
                                             const std::array<KnotVector, 3>& knots,
                                             const std::array<std::vector<int>, 2>& kinks,
                                             double lambda, const CancelCheck& cancel) {
  // The control at a kink (a C0 knot line) interpolates it, as the end controls do a block's
  // edge: the fairing rows beside the kink would otherwise pull a crease's displacement, which
  // differs from its faces' by design (concave_crease.h), towards theirs.
  DirectionPins pins;
  for (int dir = 0; dir < 2; ++dir) {
    for (const int c : kinks[dir]) {
      pins[dir].push_back({knots[dir].FindSpan(params[dir][c]) - knots[dir].order() + 1, c});
    }
  }
  SG_ASSIGN_OR_RETURN(
      TensorSpline spline,
      FitTensor(ToBlock(d, s), params, knots, EndCondition::kInterpolate, cancel, pins, lambda));
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

// The size checks of a surface block: a finite 3D surface block of at least 4 x 4 points.
absl::Status CheckSurface(const StructuredBlock& surface, const std::string& name) {
  const Extents& n = surface.extents();
  if (surface.spatial_dim() != 3) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, ": spatial_dim = ", surface.spatial_dim(), "; a 3D surface is needed"));
  }
  if (n[2] != 1) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": nk = ", n[2],
                                                   "; a surface block has nk = 1 (", n[0], " x ",
                                                   n[1], " x ", n[2], " given)"));
  }
  if (n[0] < 4 || n[1] < 4) {
    return absl::InvalidArgumentError(absl::StrCat(
        name, ": ", n[0], " x ", n[1], " points; at least 4 x 4 are needed for a cubic fit"));
  }
  return ValidateFinite(surface, name);
}

// The k = 0 vertex layer: the mean of each vertex's block points (matched points may differ by
// the matches' gap); INVALID_ARGUMENT for a surface of one point.
absl::StatusOr<Layer> SurfaceVertices(const MultiBlockGrid& surface, const SurfaceTopology& t) {
  Layer sum(t.num_vertices, Vec::Zero());
  std::vector<int> count(t.num_vertices, 0);
  for (size_t b = 0; b < surface.blocks.size(); ++b) {
    const StructuredBlock& block = surface.blocks[b];
    for (int64_t q = 0; q < block.num_points(); ++q) {
      const double* x = block.coords().data() + 3 * q;
      sum[t.vertex[b][q]] += Vec(x[0], x[1], x[2]);
      ++count[t.vertex[b][q]];
    }
  }
  if (!(t.scale > 0.0)) {
    return absl::InvalidArgumentError("surface: all points coincide; there is no surface");
  }
  for (int64_t v = 0; v < t.num_vertices; ++v) sum[v] /= static_cast<double>(count[v]);
  return sum;
}

// One layer's steps per vertex: wanted (h plus the height denied earlier), taken (curvature
// limited), and the curvature that limited them.
struct LayerSteps {
  std::vector<double> want, step, kappa;
};

// The steps of the layer above p along `normals` (LimitingCurvature).
void LimitedSteps(const March& m, const Layer& p, const Layer& normals, double h,
                  const std::vector<double>& deficit, LayerSteps& steps) {
  steps.kappa = LimitingCurvature(m, p, normals);
  for (int64_t v = 0; v < m.num_vertices(); ++v) {
    steps.want[v] = h + deficit[v];
    steps.step[v] = steps.kappa[v] > 0.0
                        ? std::min(steps.want[v], m.options.max_curvature_step / steps.kappa[v])
                        : steps.want[v];
  }
}

// The vertices near the surface's concave creases (concave_crease.h) at a layer: per vertex
// the nearest crease (an index into March::creases, -1 for none or a crease itself), the
// crease's face it lies on (the face whose normal is nearest its own) and the weight w(d / R);
// empty for a surface without creases.
struct CreaseBand {
  std::vector<int> crease;
  std::vector<int> face;
  std::vector<double> weight;
  double reach = 0.0;  // R
};

// The band of the layer p at `height` (its normals `layer_normals`, unsmoothed): the reach is
// R = kCreaseReach height times the largest move of a crease along one of its faces per unit
// of height.
CreaseBand BandOfCreases(const March& m, const Layer& p, const Layer& layer_normals,
                         double height) {
  const ConcaveCreases& creases = m.creases;
  double along = 0.0;
  for (size_t c = 0; c < creases.vertices.size(); ++c) {
    const Vec& d = creases.offset[c];
    for (const Vec& f : creases.faces[c]) along = std::max(along, (d - d.dot(f) * f).norm());
  }
  if (!(along > 0.0)) return {};
  const double reach = kCreaseReach * height * along;
  CreaseBand band{std::vector<int>(m.num_vertices(), -1), std::vector<int>(m.num_vertices(), -1),
                  std::vector<double>(m.num_vertices(), 0.0), reach};
  const CreaseDistances near = DistancesToCreases(m.graph, p, creases.vertices, reach);
  for (int64_t v = 0; v < m.num_vertices(); ++v) {
    const int c = near.nearest[v];
    if (c < 0 || m.is_crease[v]) continue;
    const std::vector<Vec>& faces = creases.faces[c];
    int best = 0;
    for (size_t f = 1; f < faces.size(); ++f) {
      if (faces[f].dot(layer_normals[v]) > faces[best].dot(layer_normals[v])) best = f;
    }
    band.crease[v] = c;
    band.face[v] = best;
    band.weight[v] = CreaseShiftWeight(near.distance[v] / reach);
  }
  return band;
}

// Next to a crease a vertex marches along the normal of the crease's face it lies on, farther
// away along its own (smoothed) normal: n = w face + (1 - w) n, normalised.
void BlendBandNormals(const March& m, const CreaseBand& band, Layer& normals) {
  for (size_t v = 0; v < band.crease.size(); ++v) {
    const int c = band.crease[v];
    if (c < 0) continue;
    const double w = band.weight[v];
    const Vec n = w * m.creases.faces[c][band.face[v]] + (1.0 - w) * normals[v];
    if (n.norm() > 0.0) normals[v] = n.normalized();
  }
}

// The creases' share of layer q above p: each crease point goes to its place at the layer's
// `height`, and each vertex of the band moves w times its crease's move along their face.
void StepCreases(const March& m, const CreaseBand& band, const Layer& p, double height, Layer& q) {
  const ConcaveCreases& creases = m.creases;
  for (size_t c = 0; c < creases.vertices.size(); ++c) {
    const double slide =
        band.reach > 0.0 ? CreaseShiftWeight(m.slides.distance[c] / band.reach) : 0.0;
    q[creases.vertices[c]] =
        m.crease_origin[c] + height * (creases.offset[c] + slide * m.slides.slide[c]);
  }
  for (size_t v = 0; v < band.crease.size(); ++v) {
    const int c = band.crease[v];
    if (c < 0) continue;
    const int64_t crease = creases.vertices[c];
    const Vec move = q[crease] - p[crease];
    const Vec& face = creases.faces[c][band.face[v]];
    q[v] += band.weight[v] * (move - move.dot(face) * face);
  }
}

// The layer q above p (at `height` above the surface, step h), its normals smoothed two more
// sweeps per retry (counted in `*retries`) until its cells do not fold or max_retries is spent;
// the check of the last attempt.
absl::StatusOr<CellCheck> OffsetWithRetries(const March& m, const Layer& p, const CreaseBand& band,
                                            Layer& normals, double height, double h,
                                            const std::vector<double>& deficit, LayerSteps& steps,
                                            Layer& q, int* retries) {
  CellCheck check;
  for (int attempt = 0; attempt <= m.options.max_retries; ++attempt) {
    if (attempt > 0) {
      SG_RETURN_IF_ERROR(Smooth(m, 2 * attempt, normals));
      ++*retries;
    }
    Layer leaning = normals;  // the lean is taken afresh from the smoothed normals each attempt
    LeanTowardsPlanes(m, p, height, leaning);
    BlendBandNormals(m, band, leaning);
    LimitedSteps(m, p, leaning, h, deficit, steps);
    for (int64_t v = 0; v < m.num_vertices(); ++v) q[v] = p[v] + steps.step[v] * leaning[v];
    StepCreases(m, band, p, height, q);
    ProjectPoints(m, q);
    check = CheckCells(m, p, q);
    if (!check.folded) break;
  }
  return check;
}

// "block 3 cell (4, 5)", or "cell (4, 5)" for a one-block surface.
std::string CellName(const March& m, int block, int i, int j) {
  return absl::StrCat(m.blocks.size() > 1 ? absl::StrCat("block ", block, " ") : "", "cell (", i,
                      ", ", j, ")");
}

// The error for layer k + 1 (step h) folding at `check` after every retry: the curvature limit
// is named when it held steps back.
absl::Status FoldedLayerError(const March& m, const CellCheck& check, int k, double h,
                              const LayerSteps& steps) {
  const SurfaceOffsetOptions& options = m.options;
  double held_back = 0.0;
  for (size_t v = 0; v < steps.want.size(); ++v) {
    held_back = std::max(held_back, steps.want[v] - steps.step[v]);
  }
  const std::string cell = CellName(m, check.block, check.i, check.j);
  if (held_back > 0.0) {
    return absl::FailedPreconditionError(absl::StrCat(
        "distance = ", options.distance, " is not reachable on the concave side: layer ", k + 1,
        " folds at ", cell, " while the curvature limit (max_curvature_step = ",
        options.max_curvature_step, ") holds its steps up to ", held_back,
        " short; lower the distance, or, if the surface is a fit within a tolerance, march off an "
        "interpolating fit of its points (FitGrid without tolerances), which follows them "
        "exactly"));
  }
  return absl::FailedPreconditionError(absl::StrCat(
      "layer ", k + 1, " folds at ", cell, " even with smoothed normals (step ", h,
      ", max_retries = ", options.max_retries,
      "); use more normal_smoothing (sweeps at the last layer: ", options.normal_smoothing,
      "), more layers or a smaller growth"));
}

// Fairs the displacement p -> q of every block with weight `lambda` and adds its spline to the
// block's (file comment); q becomes the mean of the blocks' faired points (so the blocks stay
// watertight) unless a cell folds, in which case q stays and every block adds its interpolating
// displacement instead (counted in `*refits_dropped`).
absl::Status FairLayer(March& m, const Layer& p, double lambda, Layer& q, CellCheck& check,
                       int* refits_dropped) {
  // The displacement p -> q of one block's points, fitted with weight `weight`.
  auto fit_block = [&](const BlockMarch& block, double weight) {
    Layer d(block.s.size());
    for (int64_t i = 0; i < block.s.size(); ++i) {
      const int64_t v = (*block.vertex)[i];
      d[i] = q[v] - p[v];
    }
    return FitDisplacement(d, block.s, block.params, block.fit.all_knots(), block.kinks, weight,
                           m.options.cancel);
  };
  std::vector<Displacement> faired;
  Layer sum(m.num_vertices(), Vec::Zero());
  std::vector<int> count(m.num_vertices(), 0);
  for (const BlockMarch& block : m.blocks) {
    SG_ASSIGN_OR_RETURN(Displacement fit, fit_block(block, lambda));
    for (int64_t i = 0; i < block.s.size(); ++i) {
      const int64_t v = (*block.vertex)[i];
      sum[v] += p[v] + fit.moved[i];
      ++count[v];
    }
    faired.push_back(std::move(fit));
  }
  for (int64_t v = 0; v < m.num_vertices(); ++v) sum[v] /= static_cast<double>(count[v]);
  ProjectPoints(m, sum);
  if (const CellCheck faired_check = CheckCells(m, p, sum); !faired_check.folded) {
    q = std::move(sum);
    check = faired_check;
  } else {
    ++*refits_dropped;
    for (size_t b = 0; b < m.blocks.size(); ++b) {
      SG_ASSIGN_OR_RETURN(faired[b], fit_block(m.blocks[b], 0.0));
    }
  }
  for (size_t b = 0; b < m.blocks.size(); ++b) {
    SG_ASSIGN_OR_RETURN(m.blocks[b].fit, AddSplines(m.blocks[b].fit, faired[b].spline));
  }
  return absl::OkStatus();
}

// Counts the limited steps and carries the height they held back into `deficit`; refused as
// soon as the height held back anywhere exceeds what the last layer may miss: towards a centre
// of curvature it is not given back, and marching on only distorts the layers there.
absl::Status CarryDeficit(const March& m, const LayerSteps& steps, int k,
                          std::vector<double>& deficit, SurfaceOffsetGrid& out) {
  const SurfaceOffsetOptions& options = m.options;
  for (int64_t v = 0; v < m.num_vertices(); ++v) {
    if (steps.step[v] < steps.want[v]) ++out.limited_steps;
    deficit[v] = steps.want[v] - steps.step[v];
  }
  const auto worst = std::max_element(deficit.begin(), deficit.end());
  out.shortfall = *worst;
  if (out.shortfall > options.max_shortfall * options.distance) {
    const int64_t at = worst - deficit.begin();
    // The first block point of the vertex, to name it.
    std::string point;
    for (size_t b = 0; b < m.blocks.size() && point.empty(); ++b) {
      const std::vector<int64_t>& vertex = *m.blocks[b].vertex;
      const auto found = std::find(vertex.begin(), vertex.end(), at);
      if (found == vertex.end()) continue;
      const int64_t q = found - vertex.begin();
      point =
          absl::StrCat(m.blocks.size() > 1 ? absl::StrCat("block ", b, " ") : "", "surface point (",
                       q % m.blocks[b].s.ni, ", ", q / m.blocks[b].s.ni, ")");
    }
    return absl::FailedPreconditionError(absl::StrCat(
        "distance = ", options.distance, " cannot be reached on the concave side: at ", point,
        " layer ", k + 1, " is ", out.shortfall,
        " short, its steps limited to max_curvature_step = ", options.max_curvature_step,
        " of the radius of curvature (", 1.0 / steps.kappa[at],
        " there); allowed: max_shortfall = ", options.max_shortfall, " of the distance"));
  }
  return absl::OkStatus();
}

// The sides of the blocks: the topology's times options.side, or outward.
absl::StatusOr<std::vector<int>> BlockSides(const MultiBlockGrid& surface,
                                            SurfaceTopology& topology,
                                            const SurfaceOffsetOptions& options) {
  if (options.outward) {
    SG_RETURN_IF_ERROR(OrientOutward(surface, topology));
    return topology.side;
  }
  std::vector<int> sides = topology.side;
  for (int& side : sides) side *= options.side;
  return sides;
}

// The interior grid lines across which a surface block kinks, per direction i, j: where its
// boundary lines have a tangent discontinuity (DetectFeatures with kink_ratio 2, as the service's
// fit of the volume grid finds them, grid_fit.cc FitBlocks), so that the layers' splines are C0
// there and the crease is treated as one between blocks is (concave_crease.h).
std::array<std::vector<int>, 2> SurfaceKinks(const StructuredBlock& block) {
  FeatureOptions features;
  features.kink_ratio = 2.0;
  std::array<std::vector<int>, 2> kinks;
  for (int d = 0; d < 2; ++d) {
    for (const int c : DetectFeatures(block, d, features)) {
      if (c > 0 && c < block.extent(d) - 1) kinks[d].push_back(c);
    }
  }
  return kinks;
}

// The surface spline of every block (faired: for normals and curvatures only, k = 0 is the
// surface as given), whose parameters and knots every layer keeps.
absl::Status FitSurfaceBlocks(const MultiBlockGrid& surface, const SurfaceTopology& topology,
                              const std::vector<int>& sides, March& m) {
  FitOptions fit_options;
  fit_options.cancel = m.options.cancel;
  fit_options.fairing = m.options.surface_fairing;
  for (size_t b = 0; b < surface.blocks.size(); ++b) {
    const StructuredBlock& block = surface.blocks[b];
    BlockMarch march;
    const std::array<std::vector<int>, 2> kinks = SurfaceKinks(block);
    fit_options.breaks = {kinks[0], kinks[1], {}};
    SG_ASSIGN_OR_RETURN(const FittedBlock fitted, FitBlock(block, fit_options));
    // The kinks the fit could make C0 (a break too near an end, or another break, is not used:
    // KnotVector::UsableBreaks); a kink left out is smooth to the march as to the fit.
    for (int d = 0; d < 2; ++d) {
      const KnotVector& knots = fitted.spline.knots(d);
      for (const int c : kinks[d]) {
        if (knots.Multiplicity(fitted.distribution.params(d)[c]) >= knots.order() - 1) {
          march.kinks[d].push_back(c);
        }
      }
    }
    march.s = Shape{block.extent(0), block.extent(1)};
    march.side = sides[b];
    march.params = {fitted.distribution.params(0), fitted.distribution.params(1), {0.0}};
    march.fit = fitted.spline;
    march.vertex = &topology.vertex[b];
    m.blocks.push_back(std::move(march));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status SurfaceOffsetOptions::Validate() const {
  SG_RETURN_IF_ERROR(ValidateLayerStack(layers, first_height, distance));
  SG_RETURN_IF_ERROR(ValidateMarchedGrowth(layers, first_height, distance));
  if (side != 1 && side != -1) {
    return absl::InvalidArgumentError(absl::StrCat("side = ", side, " is neither +1 nor -1"));
  }
  if (normal_smoothing < 0 || normal_smoothing > kMaxNormalSmoothing) {
    return absl::InvalidArgumentError(absl::StrCat("normal_smoothing = ", normal_smoothing,
                                                   " is outside [0, ", kMaxNormalSmoothing, "]"));
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
  if (max_retries < 0 || max_retries > kMaxRetries) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_retries = ", max_retries, " is outside [0, ", kMaxRetries, "]"));
  }
  return absl::OkStatus();
}

absl::StatusOr<SurfaceOffsetGrid> OffsetSurfaceGrid(const MultiBlockGrid& surface,
                                                    const Connectivity& connectivity,
                                                    const SurfaceOffsetOptions& options) {
  SG_RETURN_IF_ERROR(options.Validate());
  if (surface.blocks.empty()) return absl::InvalidArgumentError("surface: no blocks");
  for (size_t b = 0; b < surface.blocks.size(); ++b) {
    SG_RETURN_IF_ERROR(CheckSurface(surface.blocks[b], surface.blocks.size() > 1
                                                           ? absl::StrCat("surface block ", b)
                                                           : std::string("surface")));
  }
  SG_ASSIGN_OR_RETURN(SurfaceTopology topology,
                      BuildSurfaceTopology(surface, connectivity, options.symmetry_planes));
  SG_ASSIGN_OR_RETURN(const std::vector<int> sides, BlockSides(surface, topology, options));
  March m{options, topology, {}, topology.scale, {}, {}, {}, {}, {}};
  SG_ASSIGN_OR_RETURN(Layer p, SurfaceVertices(surface, topology));
  ProjectPoints(m, p);
  SG_RETURN_IF_ERROR(FitSurfaceBlocks(surface, topology, sides, m));
  m.is_crease.assign(m.num_vertices(), 0);  // until the first layer finds them
  m.stencil = BuildSmoothingStencil(m);
  m.graph = BuildGridGraph(m);

  SurfaceOffsetGrid out;
  out.sides = sides;
  out.symmetry_planes = topology.planes;
  out.surface_gap = topology.max_gap;
  out.components = topology.components;
  out.growth_ratio = GeometricRatio(options.first_height, options.distance, options.layers);
  for (const BlockMarch& block : m.blocks) {
    out.blocks.emplace_back(Extents{block.s.ni, block.s.nj, options.layers + 1}, 3);
  }
  auto store = [&](int k) {
    for (size_t b = 0; b < m.blocks.size(); ++b) {
      const BlockMarch& block = m.blocks[b];
      for (int64_t q = 0; q < block.s.size(); ++q) {
        const Vec& x = p[(*block.vertex)[q]];
        std::copy(x.data(), x.data() + 3, out.blocks[b].Point(q % block.s.ni, q / block.s.ni, k));
      }
    }
  };
  store(0);
  const int64_t nv = m.num_vertices();
  std::vector<double> deficit(nv, 0.0);
  LayerSteps steps{std::vector<double>(nv), std::vector<double>(nv), std::vector<double>(nv, 0.0)};
  Layer q(nv);
  double height = 0.0;  // of layer k above the surface (nominal)
  for (int k = 0; k < options.layers; ++k) {
    SG_RETURN_IF_ERROR(PollCancel(options.cancel));
    const double h = options.first_height * std::pow(out.growth_ratio, k);
    out.steps.push_back(h);
    const double fraction = static_cast<double>(k + 1) / options.layers;
    std::vector<std::vector<Vec>> faces;  // the surface's, to find its creases
    SG_ASSIGN_OR_RETURN(const Layer layer_normals, VertexNormals(m, p, k == 0 ? &faces : nullptr));
    if (k == 0) {
      m.creases = FindConcaveCreases(m.graph, p, layer_normals, faces);
      for (const int64_t v : m.creases.vertices) {
        m.is_crease[v] = 1;
        m.crease_origin.push_back(p[v]);
      }
      m.slides = SlidesFromCorners(m.graph, p, m.creases);
      out.crease_vertices = static_cast<int64_t>(m.creases.vertices.size());
      if (out.crease_vertices > 0) m.stencil = BuildSmoothingStencil(m);
    }
    Layer normals = layer_normals;
    const int sweeps = static_cast<int>(std::lround(options.normal_smoothing * fraction));
    SG_RETURN_IF_ERROR(Smooth(m, sweeps, normals));
    const CreaseBand band = BandOfCreases(m, p, layer_normals, height + h);
    SG_ASSIGN_OR_RETURN(CellCheck check, OffsetWithRetries(m, p, band, normals, height + h, h,
                                                           deficit, steps, q, &out.retries));
    if (check.folded) return FoldedLayerError(m, check, k, h, steps);
    // Fair the displacement and add its spline to the layer's (file comment); a faired
    // displacement that folds a cell is dropped for the interpolating one.
    SG_RETURN_IF_ERROR(FairLayer(m, p, options.fairing * fraction, q, check, &out.refits_dropped));
    out.min_scaled_jacobian = std::min(out.min_scaled_jacobian, check.min_scaled);
    SG_RETURN_IF_ERROR(CarryDeficit(m, steps, k, deficit, out));
    height += h;
    std::swap(p, q);
    store(k + 1);
  }
  return out;
}

absl::StatusOr<SurfaceOffsetGrid> OffsetSurface(const StructuredBlock& surface,
                                                const SurfaceOffsetOptions& options) {
  SG_RETURN_IF_ERROR(CheckSurface(surface, "surface"));
  MultiBlockGrid grid;
  grid.blocks.push_back(surface);
  SG_ASSIGN_OR_RETURN(const Connectivity connectivity, FindConnectivity(grid, {}, options.cancel));
  return OffsetSurfaceGrid(grid, connectivity, options);
}

}  // namespace splinegrid
