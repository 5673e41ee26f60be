#include "core/generate/concave_crease.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

#include "Eigen/QR"
#include "Eigen/SVD"

namespace splinegrid {

using Vec = Eigen::Vector3d;

VertexGraph BuildVertexGraph(int64_t num_vertices,
                             const std::vector<std::pair<int64_t, int64_t>>& edges) {
  std::vector<std::vector<int64_t>> rows(num_vertices);
  for (const auto& [a, b] : edges) {
    if (a == b) continue;  // a collapsed edge (a pole)
    rows[a].push_back(b);
    rows[b].push_back(a);
  }
  VertexGraph graph;
  graph.start.reserve(num_vertices + 1);
  graph.start.push_back(0);
  for (std::vector<int64_t>& row : rows) {
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
    graph.neighbour.insert(graph.neighbour.end(), row.begin(), row.end());
    graph.start.push_back(static_cast<int64_t>(graph.neighbour.size()));
  }
  return graph;
}

ConcaveCreases FindConcaveCreases(const VertexGraph& graph, const std::vector<Vec>& points,
                                  const std::vector<Vec>& mean_normals,
                                  const std::vector<std::vector<Vec>>& faces) {
  const double min_cos = std::cos(kCreaseDegrees * M_PI / 180.0);
  ConcaveCreases creases;
  for (int64_t v = 0; v < graph.num_vertices(); ++v) {
    if (faces[v].size() < 2) continue;
    const Vec& n = mean_normals[v];
    const bool creased = std::any_of(faces[v].begin(), faces[v].end(),
                                     [&](const Vec& f) { return f.dot(n) < min_cos; });
    if (!creased) continue;
    // Concave: the neighbours rise, on average, above the tangent plane of the mean normal.
    double rise = 0.0;
    for (int64_t e = graph.start[v]; e < graph.start[v + 1]; ++e) {
      const Vec d = points[graph.neighbour[e]] - points[v];
      const double length = d.norm();
      if (length > 0.0) rise += d.dot(n) / length;
    }
    if (!(rise > 0.0)) continue;
    creases.vertices.push_back(v);
    creases.faces.push_back(faces[v]);
    creases.offset.push_back(CreaseOffset(faces[v]));
  }
  return creases;
}

Vec CreaseOffset(const std::vector<Vec>& faces) {
  Eigen::MatrixX3d n(faces.size(), 3);
  for (size_t f = 0; f < faces.size(); ++f) n.row(f) = faces[f].transpose();
  Vec d = n.completeOrthogonalDecomposition().solve(Eigen::VectorXd::Ones(n.rows()));
  if (d.norm() > kMaxMiter) d *= kMaxMiter / d.norm();
  return d;
}

CreaseDistances DistancesToCreases(const VertexGraph& graph, const std::vector<Vec>& points,
                                   const std::vector<int64_t>& creases, double reach,
                                   const std::vector<char>* walkable) {
  const int64_t n = graph.num_vertices();
  CreaseDistances out{std::vector<double>(n, std::numeric_limits<double>::infinity()),
                      std::vector<int>(n, -1)};
  using Entry = std::pair<double, int64_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  for (size_t c = 0; c < creases.size(); ++c) {
    out.distance[creases[c]] = 0.0;
    out.nearest[creases[c]] = static_cast<int>(c);
    queue.emplace(0.0, creases[c]);
  }
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > out.distance[v]) continue;  // a stale entry
    for (int64_t e = graph.start[v]; e < graph.start[v + 1]; ++e) {
      const int64_t u = graph.neighbour[e];
      if (walkable && !(*walkable)[u]) continue;
      const double next = d + (points[u] - points[v]).norm();
      if (next < out.distance[u] && next < reach) {
        out.distance[u] = next;
        out.nearest[u] = out.nearest[v];
        queue.emplace(next, u);
      }
    }
  }
  return out;
}

CreaseSlides SlidesFromCorners(const VertexGraph& graph, const std::vector<Vec>& points,
                               const ConcaveCreases& creases) {
  const size_t n = creases.vertices.size();
  CreaseSlides out{std::vector<double>(n, std::numeric_limits<double>::infinity()),
                   std::vector<Vec>(n, Vec::Zero())};
  // The faces' normals as rows: a corner has three singular values; a crease's direction is the
  // right singular vector of its smallest.
  const double min_spread = std::sin(2.0 * kCreaseDegrees * M_PI / 180.0);
  std::vector<Vec> direction(n, Vec::Zero());
  std::vector<int64_t> corners;  // crease indices
  std::vector<int64_t> corner_vertices;
  std::vector<char> on_crease(graph.num_vertices(), 0);
  for (size_t c = 0; c < n; ++c) {
    on_crease[creases.vertices[c]] = 1;
    Eigen::MatrixX3d normals(creases.faces[c].size(), 3);
    for (size_t f = 0; f < creases.faces[c].size(); ++f) {
      normals.row(f) = creases.faces[c][f].transpose();
    }
    const Eigen::JacobiSVD<Eigen::MatrixX3d> svd(normals, Eigen::ComputeFullV);
    const auto& sigma = svd.singularValues();
    if (sigma.size() == 3 && sigma[2] > min_spread * sigma[0]) {
      corners.push_back(static_cast<int64_t>(c));
      corner_vertices.push_back(creases.vertices[c]);
    } else {
      direction[c] = svd.matrixV().col(2);
    }
  }
  if (corners.empty()) return out;
  // Distances along the creases (through crease vertices only) from the corners.
  const CreaseDistances near = DistancesToCreases(
      graph, points, corner_vertices, std::numeric_limits<double>::infinity(), &on_crease);
  for (size_t c = 0; c < n; ++c) {
    const int nearest = near.nearest[creases.vertices[c]];
    if (nearest < 0) continue;
    out.distance[c] = near.distance[creases.vertices[c]];
    const Vec& t = direction[c];  // zero at a corner: no slide
    out.slide[c] = creases.offset[corners[nearest]].dot(t) * t;
  }
  return out;
}

double CreaseShiftWeight(double t) {
  if (!(t < 1.0)) return 0.0;
  if (t <= 0.0) return 1.0;
  return 1.0 - t * t * (3.0 - 2.0 * t);
}

}  // namespace splinegrid
