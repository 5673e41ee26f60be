// Deformation of a fitted multi-block grid: move part of its boundary, let the rest follow.
//
// The work is on the control nets (a few thousand points for a 257 x 129 grid), not on the grid
// points, and everything that depends only on the reference grid is done once, in Create:
// the roles of the controls (boundary_controls.h: moved, fixed, free), every free control's
// distance d to the moved boundary, the decay radius, and (per boundary range and level) the
// factored boundary fits. Each step is then O(controls):
//
//  - moved controls follow the motion exactly, so the moved boundary moves exactly as asked;
//  - fixed controls stay (outer boundaries, walls that are not moved), exactly;
//  - free controls (interior, block interfaces, a C-grid's wake cut) follow a part f(d) of it,
//      f(d) = 1 for d <= r0,  0 for d >= r1,  1 - 3 t^2 + 2 t^3 with t = (d - r0) / (r1 - r0),
//    r0 the rigid radius (default 0), r1 the decay radius (default: the distance from the moved
//    boundary to the nearest fixed control, so fixed boundaries are never reached). For a rigid
//    motion the free controls take the motion by the fraction f of its angle and translation
//    (rigid_motion.h), so the cells near the wall, where f is close to 1, turn with it and keep
//    their shape and orthogonality; for given displacements they take f times the inverse
//    distance weighted average of the moved controls' displacements (Shepard's method with
//    weights |P - B_i|^-3, as in A. de Boer, M. van der Schoot, H. Bijl, "Mesh deformation based
//    on radial basis function interpolation", Comput. Struct. 85, 2007, and J. Witteveen,
//    H. Bijl, "Explicit mesh deformation using inverse distance weighting interpolation", AIAA
//    2009-3996).
//
// Propagation kTransfinite instead fills the interior of every planar or volume block by Coons
// (transfinite) interpolation of its faces' displacements, in the Greville abscissae of its
// controls (W. J. Gordon, C. A. Hall, "Construction of curvilinear co-ordinate systems and
// applications to mesh generation", IJNME 7, 1973): faces get the displacements above, the
// interior a blend of them. It is smooth for bending boundaries; under rotation the near-wall
// cells shear (the wall's displacement is carried, not turned), so kBlend is the default.
// smoothing_iterations adds Jacobi sweeps of a weighted Laplacian of the displacement of the
// interior controls (not on any face), each neighbour weighted by the inverse squared distance
// between the reference controls (the spring analogy, J. T. Batina, "Unsteady Euler airfoil
// solutions using unstructured dynamic meshes", AIAA J. 28(8), 1990): the short wall-normal
// spacing of a boundary layer dominates there, so its thin cells keep their height (an index
// Laplacian would average across cells a thousand times taller and fold them).
//
// Watertightness: a free control's displacement is a function of its reference position, and
// afterwards every group of controls that coincided bitwise in the reference is set to one
// value, so a watertight grid stays watertight (bitwise identical shared boundary controls).
#ifndef SPLINEGRID_CORE_DEFORM_DEFORMER_H_
#define SPLINEGRID_CORE_DEFORM_DEFORMER_H_

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include "absl/status/statusor.h"
#include "core/deform/boundary_controls.h"
#include "core/deform/range_fit.h"
#include "core/deform/rigid_motion.h"
#include "core/fit/solve/tensor_fit.h"
#include "core/grid/boundary_kinds.h"

namespace splinegrid {

enum class Propagation {
  kBlend,        // every free control by its distance to the moved boundary (default)
  kTransfinite,  // faces as kBlend, block interiors by Coons interpolation of the faces
};

struct DeformOptions {
  BoundarySelection moved;  // default: every wall point
  Propagation propagation = Propagation::kBlend;
  // Free controls within rigid_radius of the moved boundary move with it in full; beyond
  // decay_radius not at all (0: the distance to the nearest fixed control; infinite when there
  // is none, so everything follows).
  double rigid_radius = 0.0;
  double decay_radius = 0.0;
  // Jacobi sweeps of the interior displacement's weighted Laplacian (0: none).
  int smoothing_iterations = 0;

  // INVALID_ARGUMENT naming the field.
  absl::Status Validate() const;
};

// New positions (or displacements) of the points of one face range at a refinement level: the
// range's points at that level in point order, spatial_dim coordinates each.
struct BoundaryPoints {
  FaceRange range;
  int level = 0;
  std::vector<double> coordinates;
  bool displacements = false;  // coordinates are displacements, not positions
};

// How far a deformed boundary lies from the points asked of it (Deformer::BoundaryMiss).
struct BoundaryMiss {
  double distance = 0.0;                     // the largest distance
  int range = 0;                             // of the range given as points[range]
  std::array<int64_t, 3> point = {0, 0, 0};  // at this point of its block, at the range's level
};

class Deformer {
 public:
  // Prepares the deformation of `reference` (the blocks of a revision), whose boundary points
  // have `kinds`. Errors: INVALID_ARGUMENT for bad options, a selection naming no existing face
  // or no point at all; FAILED_PRECONDITION when no control moves.
  static absl::StatusOr<Deformer> Create(std::vector<FittedBlock> reference, BoundaryKinds kinds,
                                         const DeformOptions& options);

  // The grid moved by `motion`.
  absl::StatusOr<std::vector<FittedBlock>> Rigid(const RigidMotion& motion) const;

  // The grid with the moved controls displaced by `displacements`: spatial_dim values per moved
  // control, in the order of moved_controls(). INVALID_ARGUMENT for a wrong count or NaN.
  absl::StatusOr<std::vector<FittedBlock>> DisplaceControls(
      std::span<const double> displacements) const;

  // The grid whose moved boundary passes through `points` (several ranges allowed; every range
  // must lie on the moved boundary): each range's moved controls are fitted to them by least
  // squares with the range's knots (factored once per range and level and kept), ends pinned
  // where the range ends at a break or a block edge. A face of a volume (two tangential
  // directions) must be given whole. The other moved controls keep their reference positions.
  // Errors: INVALID_ARGUMENT naming the range for a wrong count, NaN, a range off the moved
  // boundary or a partial volume face; FAILED_PRECONDITION when the points do not determine a
  // control (too coarse a level).
  absl::StatusOr<std::vector<FittedBlock>> MoveBoundaryPoints(
      std::span<const BoundaryPoints> points) const;

  // The largest distance of the boundary of `moved` (MoveBoundaryPoints(points)) from the
  // positions `points` ask for: the least-squares fit of a range's controls meets displacements
  // of the boundary's own basis exactly and others only approximately (a bump narrower than
  // the boundary's knot spans is missed by up to half its height), so a caller can see it and
  // refuse. O(samples) per range. Errors as MoveBoundaryPoints.
  absl::StatusOr<BoundaryMiss> Miss(const std::vector<FittedBlock>& moved,
                                    std::span<const BoundaryPoints> points) const;

  // (block, control index) of every moved control, block by block in control order.
  const std::vector<std::pair<int, int64_t>>& moved_controls() const { return moved_; }
  const std::vector<FittedBlock>& reference() const { return reference_; }
  const BoundaryKinds& kinds() const { return kinds_; }
  const std::vector<std::vector<ControlRole>>& roles() const { return roles_; }
  // The decay radius in use (infinity: no fixed control).
  double decay_radius() const { return decay_radius_; }

 private:
  struct BoundaryFit;  // the factored least-squares fits of one range at one level
  Deformer() = default;

  // Fills the free controls of `blocks` (whose moved controls are set) from the moved
  // displacements: `free_motion(b, c, reference position, f)` gives a free control's position.
  template <typename FreeMotion>
  void Propagate(std::vector<FittedBlock>& blocks, const FreeMotion& free_motion) const;
  // The Coons interior of one block from its faces (kTransfinite), then smoothing, then the
  // coinciding groups made equal.
  void Finish(std::vector<FittedBlock>& blocks) const;
  // Finish step: options_.smoothing_iterations Jacobi sweeps of the weighted Laplacian of
  // block b's control displacements D over its interior free controls.
  void SmoothInterior(size_t b, std::vector<Point3>& D) const;
  // Finish step: every group of coinciding controls set to one member's value.
  void EqualizeCoinciding(std::vector<FittedBlock>& blocks) const;
  // The IDW-blended displacement of a free control at reference position p with fraction f.
  Point3 BlendedDisplacement(const Point3& p, double f,
                             const std::vector<Point3>& moved_displacements) const;
  absl::StatusOr<std::shared_ptr<const BoundaryFit>> FitFor(const FaceRange& range,
                                                            int level) const;
  // MoveBoundaryPoints step: the fit of range r, `given` (blocks of point `extents`), after
  // checking that it lies on the moved boundary and that its level, point count and values are
  // valid (INVALID_ARGUMENT naming the range).
  absl::StatusOr<std::shared_ptr<const BoundaryFit>> CheckedFit(
      const BoundaryPoints& given, size_t r, const std::vector<Extents>& extents) const;
  // MoveBoundaryPoints step: the given points' displacements at the fit's samples.
  std::vector<double> SampleDisplacements(const BoundaryPoints& given,
                                          const BoundaryFit& fit) const;
  // MoveBoundaryPoints step: the least-squares control displacements of `delta` (s values per
  // sample), direction by direction; controls of the first tangential direction fastest.
  static std::vector<double> FitRangeControls(const BoundaryFit& fit,
                                              const std::vector<double>& delta, int s);
  // MoveBoundaryPoints step: adds those control displacements to the moved controls of the
  // range's face (`moved`, by `moved_index`), counting the ranges that reach each in `hits`.
  void AccumulateMoved(const BoundaryPoints& given, const BoundaryFit& fit,
                       const std::vector<double>& controls, const std::vector<Extents>& extents,
                       const std::map<std::pair<int, int64_t>, size_t>& moved_index,
                       std::vector<Point3>& moved, std::vector<int>& hits) const;

  std::vector<FittedBlock> reference_;
  BoundaryKinds kinds_;
  DeformOptions options_;
  std::vector<std::vector<uint8_t>> selected_;
  std::vector<std::vector<ControlRole>> roles_;
  std::vector<std::pair<int, int64_t>> moved_;
  std::vector<Point3> moved_positions_;  // reference positions of moved_
  // Per block, per control: the fraction f(d) of the motion a free control takes.
  std::vector<std::vector<double>> fraction_;
  double decay_radius_ = 0.0;
  // Groups of controls that coincide bitwise in the reference: (block, control) lists.
  std::vector<std::vector<std::pair<int, int64_t>>> coinciding_;
  // Boundary fits by (block, normal, upper, begin, end, level), built on first use.
  mutable std::map<std::vector<int>, std::shared_ptr<const BoundaryFit>> fits_;
  mutable std::shared_ptr<std::mutex> fits_mutex_ = std::make_shared<std::mutex>();
};

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_DEFORM_DEFORMER_H_
