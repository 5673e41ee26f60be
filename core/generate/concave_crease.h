// Concave creases of a surface marched into layers (surface_offset.h): where blocks meet at a
// concave angle, as a wing meets a fuselage or the two faces inside an L.
//
// The exact offset by h of two faces meeting at a concave crease keeps a crease: the line where
// the two faces' offsets meet, h away from each face, which lies along the faces' bisector n at
// the distance
//   h / (n . n_f)        (the miter; n_f the unit normals of the faces meeting there),
// h sqrt(2) inside a right angle. A crease stepped by h alone lags cos(angle / 2) of a step behind
// both faces, and within a few cells' height the faces' layers fold back over it. Stepped by the
// miter it keeps pace, but then the faces' points within about h of the crease are overtaken by
// it: their offsets lie inside the other face's offset. So the points near a crease are moved
// along their layer as well, away from the crease, by a share of the crease's own move:
//   x_v' = x_v + s_v n_v + w(d_v / R) P_f (x_c' - x_c),   n_v = w n_f + (1 - w) n_smooth,
// c the crease vertex nearest to v (d_v its distance along the layer's grid edges), f the face
// of c that v lies on (normal n_f nearest v's own), P_f the projection onto f's plane, and
// R = kCreaseReach H sqrt(m^2 - 1) (H the new layer's height above the surface, m the largest
// miter: sqrt(m^2 - 1) = tan(angle / 2) is the crease's move along a face per unit of height, 1
// in a right angle). Next to the crease (w = 1) v moves as its face does; the crease point itself
// goes to x_c0 + H d (x_c0 on the surface, d = CreaseOffset of the surface's faces), so no error
// accumulates from layer to layer. w(t) = 1 - 3 t^2 + 2 t^3 (0 for t >= 1) is the smooth step;
// w'(0) = 0, so the shifts of a stack of layers do not pile up next to the crease. Summed over a
// geometric stack, the slope of the shift along the layer at distance d from the crease is sum_k
// (h_k / (c H_k)) |w'(d / (c H_k))|, which for many layers tends to (1 / c) int_0^1 |w'(t)| / t dt
// = 3 / c per unit of the crease's move along the face (c = kCreaseReach, H_k the heights), so the
// points keep their order along the layer for c > 3; with c = 4 the spacing next to a crease
// shrinks at most to a quarter. The faces' points spread out over a band of width R on either side
// of the crease, and every layer stays h above both faces.
//
// A vertex is a concave crease when the normal of some block meeting there makes more than
// kCreaseDegrees with the vertex's mean normal (a turn of more than twice that between faces)
// and its grid neighbours lie, on average, on the side the layers march to. Smooth surfaces
// (their blocks' normals agree at shared edges) and convex edges (which fan out along the mean
// normal) have none. The miter is capped at kMaxMiter: a crease sharper than 2 acos(1 / 4)
// (151 degrees of turning) lags, and its layers may fold (the fold check names the cell).
// Inside one block a crease is a grid line across which the block kinks: its faces are the
// block's normals on either side (surface_offset.cc, KinkNormals), so it is found and marched
// as one between blocks is.
// Where the faces of creases meeting at a vertex span space (three planes: the inside corner of a
// box) the vertex is a corner: CreaseOffset puts it at the height above all of them, (H, H, H)
// inside a box, and a crease point at distance d along the creases from it slides along its
// crease t by w(d / R) H (d_corner . t) t, away from the corner (SlidesFromCorners): its layer
// point would otherwise lie within H of the third face. The faces' points follow their nearest
// crease point's move, slide included, so next to the corner they move as the corner does.
// Measured on three 17 x 17 unit faces, 16 layers: every layer min(x, y, z) = H to 1e-15,
// smallest scaled Jacobian 0.41 to 0.3 and 0.22 to 1.0 (the faces' length). Before, the crease
// points did not slide and layer 1 folded at the corner.
// Measured on wedges of two 33 x 33 faces, openings 45-150 degrees, 16 layers to 0.3 of the
// face: every point of every layer at its height above the nearer face to 1e-13, the smallest
// scaled Jacobian sin(opening / 2), the cells at the crease; also to 1.0 (the face's length).
#ifndef SPLINEGRID_CORE_GENERATE_CONCAVE_CREASE_H_
#define SPLINEGRID_CORE_GENERATE_CONCAVE_CREASE_H_

#include <cstdint>
#include <vector>

#include "Eigen/Core"

namespace splinegrid {

inline constexpr double kCreaseDegrees = 10.0;
inline constexpr double kMaxMiter = 4.0;
inline constexpr double kCreaseReach = 4.0;

// The vertices of a surface and their grid edges, in CSR form (both directions stored).
struct VertexGraph {
  std::vector<int64_t> start;  // the neighbours of v are neighbour[start[v] .. start[v + 1])
  std::vector<int64_t> neighbour;
  int64_t num_vertices() const { return static_cast<int64_t>(start.size()) - 1; }
};

// The graph of `num_vertices` vertices with the given undirected `edges` (duplicates allowed).
VertexGraph BuildVertexGraph(int64_t num_vertices,
                             const std::vector<std::pair<int64_t, int64_t>>& edges);

struct ConcaveCreases {
  std::vector<int64_t> vertices;  // ascending
  // Per crease vertex: the unit normals of the block points joined there, and its offset per
  // unit of height (CreaseOffset).
  std::vector<std::vector<Eigen::Vector3d>> faces;
  std::vector<Eigen::Vector3d> offset;
};

// The concave creases of a layer (file comment): `points` and `mean_normals` per vertex,
// `faces` per vertex the unit normals of its block points (empty or one for a vertex of one
// block point).
ConcaveCreases FindConcaveCreases(const VertexGraph& graph,
                                  const std::vector<Eigen::Vector3d>& points,
                                  const std::vector<Eigen::Vector3d>& mean_normals,
                                  const std::vector<std::vector<Eigen::Vector3d>>& faces);

// The move d of a crease point per unit of height: the shortest with d . n_f = 1 for every face
// (least squares where they disagree), so that the crease stays one unit above each face's
// tangent plane: along the bisector with |d| = 1 / cos(angle / 2) for two faces, to the corner
// for three. Faces repeated (two blocks on one face) count once in effect. |d| is capped at
// kMaxMiter.
Eigen::Vector3d CreaseOffset(const std::vector<Eigen::Vector3d>& faces);

// For every vertex within `reach` of a crease vertex (shortest path along the graph's edges,
// lengths from `points`; with `walkable`, only through vertices marked there): the distance and
// the index of the nearest crease in `creases`; elsewhere infinity and -1.
struct CreaseDistances {
  std::vector<double> distance;
  std::vector<int> nearest;
};
CreaseDistances DistancesToCreases(const VertexGraph& graph,
                                   const std::vector<Eigen::Vector3d>& points,
                                   const std::vector<int64_t>& creases, double reach,
                                   const std::vector<char>* walkable = nullptr);

// Corners where three or more creases' faces span space (the inside corner of a box), and how
// the crease points near them slide along their crease (file comment): per crease (an index into
// `creases`) the distance along the creases to the nearest corner (infinity when the crease
// reaches none, 0 at a corner) and the slide per unit of height, (d_corner . t) t, with t the
// crease's direction and d_corner that corner's CreaseOffset.
struct CreaseSlides {
  std::vector<double> distance;
  std::vector<Eigen::Vector3d> slide;
};
CreaseSlides SlidesFromCorners(const VertexGraph& graph, const std::vector<Eigen::Vector3d>& points,
                               const ConcaveCreases& creases);

// w(t) = 1 - 3 t^2 + 2 t^3 on [0, 1], 0 beyond.
double CreaseShiftWeight(double t);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GENERATE_CONCAVE_CREASE_H_
