// How the directions of a multi-block grid share knots and parameters, so that blocks which
// touch are fitted identically where they touch.
//
// Every direction (block b, direction d) of a grid is cut at split points into segments: at the
// ends of every face range that matches another face (where a partial match begins or ends) and
// at feature points (kinks). At an interior split the knot vector has a knot of multiplicity
// order - 1 and the control there is pinned to the data point, so the segments of a direction
// are fitted independently of each other. Segments that coincide through a match (possibly
// reversed, possibly with hanging nodes: every point of the coarse segment on every second point
// of the fine one) form a class; all members of a class use the same normalised parameters and
// the same normalised knots. A block direction's global parameters keep the block's own
// parameter at each split point (so each block keeps its overall distribution) and use the
// class's distribution in between.
//
// Consequence: the data of a shared boundary, its parameters and its knots are the same in every
// block that touches it (up to an affine change of parameter, which B-splines are invariant
// under), so with interpolated ends every block fits the shared boundary to the same curve or
// surface; copying the boundary controls of one block into the others then makes them bitwise
// identical (MatchedControls).
#ifndef SPLINEGRID_CORE_FIT_ADAPTIVE_SEGMENT_MODEL_H_
#define SPLINEGRID_CORE_FIT_ADAPTIVE_SEGMENT_MODEL_H_

#include <array>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "core/bspline/knot_vector.h"
#include "core/fit/solve/direction_fit.h"
#include "core/grid/connectivity.h"
#include "core/grid/structured_grid.h"

namespace splinegrid {

// OK if `max_controls` (the cap on control points per direction of a fit to tolerances; 0: no
// cap) is 0 or at least `order`: a direction of order k starts with k controls, so a lower cap
// cannot be honoured. Otherwise INVALID_ARGUMENT naming max_controls_per_direction, its value
// and the order.
absl::Status ValidateControlCap(int max_controls, int order);

class SegmentModel {
 public:
  // A segment of a block direction, data indices [r0, r1], as a member of a class: class
  // coordinate c in [0, L] of data index r is stride * (r - r0), or L minus that if reversed.
  struct Member {
    int block = 0, dir = 0, r0 = 0, r1 = 0;
    bool reversed = false;
    int stride = 1;
    int ClassCoord(int r) const;
  };
  struct Class {
    int length = 0;  // L
    std::vector<Member> members;
    std::vector<double> params;  // at class coordinates 0..L, from 0 to 1
    std::vector<double> knots;   // interior simple knots in (0, 1), ascending
  };

  // Builds the model. `params[b][d]` are the blocks' own (averaged) parameters; `features[b][d]`
  // are optional split points (dropped where they would leave a segment with fewer than `order`
  // points or cannot be mapped through a match). `max_controls` caps the control points per
  // direction (0: the point count). Errors: FAILED_PRECONDITION when matches contradict each
  // other (a segment linked to another both forwards and reversed, or with inconsistent
  // hanging-node ratios) or leave a segment too short for the order, naming the match.
  static absl::StatusOr<SegmentModel> Build(
      const MultiBlockGrid& grid, const std::vector<std::array<std::vector<double>, 3>>& params,
      const Connectivity& connectivity,
      const std::vector<std::array<std::vector<int>, 3>>& features, int order, int max_controls);

  int num_blocks() const { return static_cast<int>(directions_.size()); }
  int num_classes() const { return static_cast<int>(classes_.size()); }
  const Class& segment_class(int c) const { return classes_[c]; }
  Class& mutable_class(int c) { return classes_[c]; }

  // Whether direction d of block b has more than one point.
  bool active(int b, int d) const { return directions_[b][d].m > 1; }
  int order(int b, int d) const { return directions_[b][d].order; }
  int cap(int b, int d) const { return directions_[b][d].cap; }
  // The global parameters of every data index of direction d of block b.
  const std::vector<double>& params(int b, int d) const { return directions_[b][d].params; }
  // Interior split points (ascending data indices).
  const std::vector<int>& splits(int b, int d) const { return directions_[b][d].splits; }
  // The classes of the segments of direction d of block b, in order.
  const std::vector<int>& segment_classes(int b, int d) const {
    return directions_[b][d].segment_class;
  }

  // The knot vector and the pins (one per interior split) of direction d of block b from the
  // current class knots. Errors from KnotVector::Create (knots too close).
  absl::StatusOr<std::pair<KnotVector, std::vector<Pin>>> DirectionKnots(int b, int d) const;
  // Control points direction d of block b has with the current class knots.
  int Controls(int b, int d) const;
  // Whether the data of every member of class c determine all free controls (Schoenberg-Whitney
  // and a full-rank factorisation) with the current class knots.
  bool WellPosed(int c) const;

  // Pairs of (block, control point index) that must hold the same control point: the
  // boundary controls of every matched face range, mapped through the match.
  std::vector<std::pair<std::pair<int, int64_t>, std::pair<int, int64_t>>> MatchedControls(
      const Connectivity& connectivity, const std::vector<Extents>& control_extents) const;

 private:
  struct Direction {
    int m = 1;
    int order = 1;
    int cap = 1;
    std::vector<int> splits;
    std::vector<int> segment_class;   // per segment
    std::vector<int> segment_member;  // index in that class's members
    std::vector<double> own_params;   // the block's own parameters
    std::vector<double> params;       // global parameters from the classes
  };

  // The control index pinned at data index r (0, m-1 or an interior split) of direction d.
  int PinnedControl(int b, int d, int r, const KnotVector& knots) const;

  // Steps of Build.
  // Point counts, orders, control caps and own parameters of every direction.
  void InitDirections(const MultiBlockGrid& grid,
                      const std::vector<std::array<std::vector<double>, 3>>& params, int order,
                      int max_controls);
  // Per direction: the class and member of each segment.
  void IndexSegmentClasses();
  // One order per linked set of directions: the smallest.
  void UnifyOrders();
  // Class parameters: the members' normalised own parameters, averaged in class coordinates.
  void AverageClassParams();
  // Global parameters of every direction: its own at the ends of each segment, the class's in
  // between.
  void SetGlobalParams();

  std::vector<std::array<Direction, 3>> directions_;
  std::vector<Class> classes_;
};

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_ADAPTIVE_SEGMENT_MODEL_H_
