#include "core/fit/adaptive/segment_model.h"

#include <algorithm>
#include <deque>
#include <optional>
#include <set>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/util/check.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

constexpr char kNames[] = "ijk";

// One tangential direction of a match: data range [a0, a1] of direction da of block ba
// coincides with [b0, b1] of direction db of block bb.
struct RangeLink {
  int ba, da, a0, a1;
  int bb, db, b0, b1;
  bool reversed;
  int step;
  int match;

  int MapAB(int r) const {
    const int offset = step * (r - a0);
    return reversed ? b1 - offset : b0 + offset;
  }
  // The a index of b index q, or -1 if q lies between two points of a (hanging node).
  int MapBA(int q) const {
    const int offset = reversed ? b1 - q : q - b0;
    return offset % step == 0 ? a0 + offset / step : -1;
  }
};

std::vector<RangeLink> RangeLinks(const Connectivity& connectivity) {
  std::vector<RangeLink> links;
  for (int i = 0; i < static_cast<int>(connectivity.matches.size()); ++i) {
    const BoundaryMatch& m = connectivity.matches[i];
    for (int d = 0; d < 3; ++d) {
      const int e = m.b_direction[d];
      if (e < 0) continue;
      links.push_back({m.a.face.block, d, m.a.begin[d], m.a.end[d], m.b.face.block, e, m.b.begin[e],
                       m.b.end[e], m.reversed[d], m.step, i});
    }
  }
  return links;
}

std::string DirectionName(int b, int d) {
  return absl::StrCat("block ", b, " direction ", std::string(1, kNames[d]));
}

// Split points (data indices) per block direction.
using SplitSets = std::vector<std::array<std::set<int>, 3>>;

// The splits the matches require: the interior ends of every matched range (where a partial
// match begins or ends).
SplitSets RequiredSplits(const MultiBlockGrid& grid, const std::vector<RangeLink>& links) {
  SplitSets required(grid.blocks.size());
  for (const RangeLink& l : links) {
    for (int r : {l.a0, l.a1}) {
      if (r > 0 && r < grid.blocks[l.ba].extent(l.da) - 1) required[l.ba][l.da].insert(r);
    }
    for (int q : {l.b0, l.b1}) {
      if (q > 0 && q < grid.blocks[l.bb].extent(l.db) - 1) required[l.bb][l.db].insert(q);
    }
  }
  return required;
}

// Propagate the required splits through the matches until every matched range is cut the
// same way. A split that falls between two points of a coarse side is dropped (a kink on a
// hanging node is kept smooth); FAILED_PRECONDITION, naming the match, if it is required.
absl::Status PropagateSplits(const std::vector<RangeLink>& links, const Connectivity& connectivity,
                             SplitSets& splits, SplitSets& required) {
  for (bool changed = true; changed;) {
    changed = false;
    for (const RangeLink& l : links) {
      for (int r : std::vector<int>(splits[l.ba][l.da].begin(), splits[l.ba][l.da].end())) {
        if (r <= l.a0 || r >= l.a1) continue;
        const int q = l.MapAB(r);
        if (splits[l.bb][l.db].insert(q).second) changed = true;
        if (required[l.ba][l.da].count(r)) required[l.bb][l.db].insert(q);
      }
      for (int q : std::vector<int>(splits[l.bb][l.db].begin(), splits[l.bb][l.db].end())) {
        if (q <= std::min(l.b0, l.b1) || q >= std::max(l.b0, l.b1)) continue;
        const int r = l.MapBA(q);
        if (r < 0) {
          if (required[l.bb][l.db].count(q)) {
            return absl::FailedPreconditionError(absl::StrCat(
                connectivity.matches[l.match].Describe(), ": ", DirectionName(l.bb, l.db),
                " is cut at ", q, ", between two points of the coarse side"));
          }
          splits[l.bb][l.db].erase(q);  // a kink on a hanging node: keep it smooth
          changed = true;
          continue;
        }
        if (splits[l.ba][l.da].insert(r).second) changed = true;
        if (required[l.bb][l.db].count(q)) required[l.ba][l.da].insert(r);
      }
    }
  }
  return absl::OkStatus();
}

// A feature point and its images through the matches: (block, direction, data index) each.
using Orbit = std::vector<std::array<int, 3>>;

// Whether image i of `orbit` keeps order - 1 intervals to the ends of its direction, to the
// splits already there and to the orbit's earlier images in that direction, and stays within
// the direction's cap together with them.
bool ImageFits(const SegmentModel& model, const MultiBlockGrid& grid, const SplitSets& splits,
               const Orbit& orbit, size_t i) {
  const auto [ob, od, r] = orbit[i];
  const int order = model.order(ob, od), m = grid.blocks[ob].extent(od);
  bool fits = r >= order - 1 && r <= m - order;
  for (int s : splits[ob][od]) fits &= std::abs(r - s) >= order - 1;
  int cuts = static_cast<int>(splits[ob][od].size()) + 1;
  for (size_t o = 0; o < i; ++o) {
    if (orbit[o][0] != ob || orbit[o][1] != od || splits[ob][od].count(orbit[o][2])) continue;
    fits &= std::abs(r - orbit[o][2]) >= order - 1;
    ++cuts;
  }
  // Each split costs order - 1 controls.
  return fits && order + cuts * (order - 1) <= model.cap(ob, od);
}

// Appends the images of `point` through every link to `orbit` (those not in it yet); false if
// one falls between two points of a coarse side (the kink is then kept smooth).
bool AddImages(const std::vector<RangeLink>& links, const std::array<int, 3> point, Orbit& orbit) {
  const auto [ob, od, r] = point;
  auto add = [&](int ib, int id, int ir) {
    const std::array<int, 3> image = {ib, id, ir};
    if (std::find(orbit.begin(), orbit.end(), image) == orbit.end()) orbit.push_back(image);
  };
  for (const RangeLink& l : links) {
    if (l.ba == ob && l.da == od && r > l.a0 && r < l.a1) add(l.bb, l.db, l.MapAB(r));
    if (l.bb == ob && l.db == od && r > std::min(l.b0, l.b1) && r < std::max(l.b0, l.b1)) {
      const int q = l.MapBA(r);
      if (q < 0) return false;  // between two coarse points: keep the kink smooth
      add(l.ba, l.da, q);
    }
  }
  return true;
}

// The orbit of feature index f of direction d of block b, or nullopt when an image breaks the
// rules of AddFeatureSplits.
std::optional<Orbit> FeatureOrbit(const SegmentModel& model, const MultiBlockGrid& grid,
                                  const std::vector<RangeLink>& links, const SplitSets& splits,
                                  int b, int d, int f) {
  Orbit orbit = {{b, d, f}};
  for (size_t i = 0; i < orbit.size(); ++i) {
    const auto [ob, od, r] = orbit[i];
    if (splits[ob][od].count(r)) continue;  // already cut, with all its images
    if (!ImageFits(model, grid, splits, orbit, i) || !AddImages(links, orbit[i], orbit)) {
      return std::nullopt;
    }
  }
  return orbit;
}

// Features, each together with its images through the matches (its orbit) or not at all:
// every image must keep order - 1 intervals to the ends of its direction, to the splits
// already there and to the orbit's other points, must not fall between two points of a
// coarse side (a kink on a hanging node is kept smooth) and must stay within its direction's
// cap. A feature judged on its own direction only could cut the coarse side of a hanging-node
// match too short (fine index 4 is coarse index 2).
void AddFeatureSplits(const SegmentModel& model, const MultiBlockGrid& grid,
                      const std::vector<RangeLink>& links,
                      const std::vector<std::array<std::vector<int>, 3>>& features,
                      SplitSets& splits) {
  for (int b = 0; b < model.num_blocks(); ++b) {
    for (int d = 0; d < 3; ++d) {
      if (!model.active(b, d)) continue;
      for (int f : features[b][d]) {
        const std::optional<Orbit> orbit = FeatureOrbit(model, grid, links, splits, b, d, f);
        if (!orbit) continue;
        for (const auto& [ob, od, r] : *orbit) splits[ob][od].insert(r);
      }
    }
  }
}

// A segment of a block direction: data indices [r0, r1].
struct SegmentRef {
  int block, dir, r0, r1;
};
// The segments of every direction and their ids (indices into `all`).
struct Segments {
  std::vector<SegmentRef> all;
  std::vector<std::array<std::vector<int>, 3>> ids;  // per block direction, in order

  // The id of segment [lo, hi] of direction d of block b, or -1.
  int Find(int b, int d, int lo, int hi) const {
    for (int id : ids[b][d]) {
      if (all[id].r0 == lo && all[id].r1 == hi) return id;
    }
    return -1;
  }
};

// The segments between the splits of every active direction; FAILED_PRECONDITION when one has
// fewer points than the direction's order.
absl::StatusOr<Segments> CutSegments(const SegmentModel& model, const MultiBlockGrid& grid,
                                     const SplitSets& splits) {
  Segments segments;
  segments.ids.resize(grid.blocks.size());
  for (int b = 0; b < model.num_blocks(); ++b) {
    for (int d = 0; d < 3; ++d) {
      if (!model.active(b, d)) continue;
      const int order = model.order(b, d);
      std::vector<int> bounds = {0};
      bounds.insert(bounds.end(), splits[b][d].begin(), splits[b][d].end());
      bounds.push_back(grid.blocks[b].extent(d) - 1);
      for (size_t s = 0; s + 1 < bounds.size(); ++s) {
        if (bounds[s + 1] - bounds[s] < order - 1) {
          return absl::FailedPreconditionError(
              absl::StrCat(DirectionName(b, d), ": the matches cut a segment [", bounds[s], ", ",
                           bounds[s + 1], "] with fewer points than the spline order ", order));
        }
        segments.ids[b][d].push_back(static_cast<int>(segments.all.size()));
        segments.all.push_back({b, d, bounds[s], bounds[s + 1]});
      }
    }
  }
  return segments;
}

// Segment links: (other segment, reversed, length ratio other / this as (num, den), match).
struct Edge {
  int to;
  bool reversed;
  int num, den;
  int match;
};

// The links of every segment to the segments it is matched with, both ways.
std::vector<std::vector<Edge>> SegmentEdges(const Segments& segments,
                                            const std::vector<RangeLink>& links) {
  std::vector<std::vector<Edge>> edges(segments.all.size());
  for (const RangeLink& l : links) {
    for (int id : segments.ids[l.ba][l.da]) {
      const SegmentRef& sa = segments.all[id];
      if (sa.r0 < l.a0 || sa.r1 > l.a1) continue;
      const int q0 = l.MapAB(sa.r0), q1 = l.MapAB(sa.r1);
      const int other = segments.Find(l.bb, l.db, std::min(q0, q1), std::max(q0, q1));
      SG_CHECK(other >= 0);
      if (other == id) continue;
      edges[id].push_back({other, l.reversed, l.step, 1, l.match});
      edges[other].push_back({id, l.reversed, 1, l.step, l.match});
    }
  }
  return edges;
}

// The segments linked to `root` (itself first), by breadth-first search: marks them class c
// in `class_of` with their orientation relative to root in `reversed`, checking that every
// cycle of matches agrees (FAILED_PRECONDITION naming the match otherwise).
absl::StatusOr<std::vector<int>> LinkedSegments(int root, int c, const Segments& segments,
                                                const std::vector<std::vector<Edge>>& edges,
                                                const Connectivity& connectivity,
                                                std::vector<int>& class_of,
                                                std::vector<bool>& reversed) {
  std::vector<int> members = {root};
  class_of[root] = c;
  std::deque<int> queue = {root};
  while (!queue.empty()) {
    const int u = queue.front();
    queue.pop_front();
    for (const Edge& e : edges[u]) {
      const bool rev = reversed[u] != e.reversed;
      const SegmentRef &su = segments.all[u], &sv = segments.all[e.to];
      const int lu = su.r1 - su.r0, lv = sv.r1 - sv.r0;
      if (lu * e.num != lv * e.den) {
        return absl::FailedPreconditionError(
            absl::StrCat(connectivity.matches[e.match].Describe(),
                         ": the matched segments have inconsistent point counts"));
      }
      if (class_of[e.to] < 0) {
        class_of[e.to] = c;
        reversed[e.to] = rev;
        members.push_back(e.to);
        queue.push_back(e.to);
      } else if (reversed[e.to] != rev) {
        return absl::FailedPreconditionError(
            absl::StrCat(connectivity.matches[e.match].Describe(),
                         " contradicts the other matches: a segment would run both ways"));
      }
    }
  }
  return members;
}

// The class of the segments `members`: its length is the longest member's, and every member
// must divide it (its stride); FAILED_PRECONDITION naming the segment otherwise.
absl::StatusOr<SegmentModel::Class> MakeClass(const std::vector<int>& members,
                                              const Segments& segments,
                                              const std::vector<bool>& reversed) {
  SegmentModel::Class cls;
  for (int id : members)
    cls.length = std::max(cls.length, segments.all[id].r1 - segments.all[id].r0);
  for (int id : members) {
    const SegmentRef& s = segments.all[id];
    const int len = s.r1 - s.r0;
    if (cls.length % len != 0) {
      return absl::FailedPreconditionError(
          absl::StrCat(DirectionName(s.block, s.dir), ": segment [", s.r0, ", ", s.r1,
                       "] does not divide its matched segments evenly"));
    }
    cls.members.push_back({s.block, s.dir, s.r0, s.r1, reversed[id], cls.length / len});
  }
  return cls;
}

// Classes by breadth-first search, checking that every cycle of matches agrees.
absl::StatusOr<std::vector<SegmentModel::Class>> SegmentClasses(
    const Segments& segments, const std::vector<std::vector<Edge>>& edges,
    const Connectivity& connectivity) {
  std::vector<SegmentModel::Class> classes;
  std::vector<int> class_of(segments.all.size(), -1);
  std::vector<bool> reversed(segments.all.size(), false);
  for (int root = 0; root < static_cast<int>(segments.all.size()); ++root) {
    if (class_of[root] >= 0) continue;
    const int c = static_cast<int>(classes.size());
    SG_ASSIGN_OR_RETURN(const std::vector<int> members,
                        LinkedSegments(root, c, segments, edges, connectivity, class_of, reversed));
    SG_ASSIGN_OR_RETURN(SegmentModel::Class cls, MakeClass(members, segments, reversed));
    classes.push_back(std::move(cls));
  }
  return classes;
}

}  // namespace

int SegmentModel::Member::ClassCoord(int r) const {
  const int offset = stride * (r - r0);
  return reversed ? stride * (r1 - r0) - offset : offset;
}

absl::Status ValidateControlCap(int max_controls, int order) {
  if (max_controls < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_controls_per_direction = ", max_controls, " is negative"));
  }
  if (max_controls > 0 && max_controls < order) {
    return absl::InvalidArgumentError(absl::StrCat(
        "max_controls_per_direction = ", max_controls, " is below order = ", order,
        ": a direction of order k starts with k control points; give at least ", order,
        ", or 0 for no cap",
        max_controls >= 2 ? absl::StrCat(", or order <= ", max_controls) : std::string()));
  }
  return absl::OkStatus();
}

absl::StatusOr<SegmentModel> SegmentModel::Build(
    const MultiBlockGrid& grid, const std::vector<std::array<std::vector<double>, 3>>& params,
    const Connectivity& connectivity, const std::vector<std::array<std::vector<int>, 3>>& features,
    int order, int max_controls) {
  SegmentModel model;
  model.InitDirections(grid, params, order, max_controls);
  const std::vector<RangeLink> links = RangeLinks(connectivity);
  SplitSets required = RequiredSplits(grid, links);
  SplitSets splits = required;
  SG_RETURN_IF_ERROR(PropagateSplits(links, connectivity, splits, required));
  AddFeatureSplits(model, grid, links, features, splits);
  // The splits of every active direction, ascending.
  for (int b = 0; b < model.num_blocks(); ++b) {
    for (int d = 0; d < 3; ++d) {
      Direction& dir = model.directions_[b][d];
      if (dir.m > 1) dir.splits.assign(splits[b][d].begin(), splits[b][d].end());
    }
  }
  SG_ASSIGN_OR_RETURN(const Segments segments, CutSegments(model, grid, splits));
  SG_ASSIGN_OR_RETURN(model.classes_,
                      SegmentClasses(segments, SegmentEdges(segments, links), connectivity));
  model.IndexSegmentClasses();
  model.UnifyOrders();
  model.AverageClassParams();
  model.SetGlobalParams();
  return model;
}

void SegmentModel::InitDirections(const MultiBlockGrid& grid,
                                  const std::vector<std::array<std::vector<double>, 3>>& params,
                                  int order, int max_controls) {
  const int nb = static_cast<int>(grid.blocks.size());
  directions_.resize(nb);
  for (int b = 0; b < nb; ++b) {
    for (int d = 0; d < 3; ++d) {
      Direction& dir = directions_[b][d];
      dir.m = grid.blocks[b].extent(d);
      dir.order = dir.m == 1 ? 1 : std::min(order, dir.m);
      dir.cap = max_controls > 0 ? std::min(dir.m, std::max(max_controls, dir.order)) : dir.m;
      dir.own_params = params[b][d];
    }
  }
}

void SegmentModel::IndexSegmentClasses() {
  for (int c = 0; c < num_classes(); ++c) {
    const Class& cls = classes_[c];
    for (int i = 0; i < static_cast<int>(cls.members.size()); ++i) {
      const Member& mem = cls.members[i];
      Direction& dir = directions_[mem.block][mem.dir];
      dir.segment_class.resize(dir.splits.size() + 1, -1);
      dir.segment_member.resize(dir.splits.size() + 1, -1);
      const auto it = std::lower_bound(dir.splits.begin(), dir.splits.end(), mem.r1);
      const int s = static_cast<int>(it - dir.splits.begin());
      dir.segment_class[s] = c;
      dir.segment_member[s] = i;
    }
  }
}

void SegmentModel::UnifyOrders() {
  for (bool changed = true; changed;) {
    changed = false;
    for (const Class& cls : classes_) {
      int o = kMaxOrder;
      for (const Member& mem : cls.members) o = std::min(o, directions_[mem.block][mem.dir].order);
      for (const Member& mem : cls.members) {
        int& mo = directions_[mem.block][mem.dir].order;
        if (mo != o) {
          mo = o;
          changed = true;
        }
      }
    }
  }
}

void SegmentModel::AverageClassParams() {
  for (Class& cls : classes_) {
    std::vector<double> sum(cls.length + 1, 0.0);
    std::vector<int> count(cls.length + 1, 0);
    for (const Member& mem : cls.members) {
      const std::vector<double>& own = directions_[mem.block][mem.dir].own_params;
      const double u0 = own[mem.r0], u1 = own[mem.r1];
      for (int r = mem.r0; r <= mem.r1; ++r) {
        const double q = (own[r] - u0) / (u1 - u0);
        const int c = mem.ClassCoord(r);
        sum[c] += mem.reversed ? 1.0 - q : q;
        ++count[c];
      }
    }
    cls.params.resize(cls.length + 1);
    for (int c = 0; c <= cls.length; ++c) cls.params[c] = sum[c] / count[c];
    cls.params.front() = 0.0;
    cls.params.back() = 1.0;
  }
}

void SegmentModel::SetGlobalParams() {
  for (std::array<Direction, 3>& block : directions_) {
    for (Direction& dir : block) {
      dir.params = dir.own_params;
      if (dir.m == 1) continue;
      for (size_t s = 0; s < dir.segment_class.size(); ++s) {
        const Member& mem = classes_[dir.segment_class[s]].members[dir.segment_member[s]];
        const Class& cls = classes_[dir.segment_class[s]];
        const double u0 = dir.own_params[mem.r0], u1 = dir.own_params[mem.r1];
        for (int r = mem.r0 + 1; r < mem.r1; ++r) {
          const double p = cls.params[mem.ClassCoord(r)];
          dir.params[r] = u0 + (u1 - u0) * (mem.reversed ? 1.0 - p : p);
        }
      }
    }
  }
}

absl::StatusOr<std::pair<KnotVector, std::vector<Pin>>> SegmentModel::DirectionKnots(int b,
                                                                                     int d) const {
  const Direction& dir = directions_[b][d];
  if (dir.m == 1) return std::make_pair(KnotVector(), std::vector<Pin>());
  const int k = dir.order;
  std::vector<double> knots(k, 0.0);
  for (size_t s = 0; s < dir.segment_class.size(); ++s) {
    const Class& cls = classes_[dir.segment_class[s]];
    const Member& mem = cls.members[dir.segment_member[s]];
    const double u0 = dir.params[mem.r0], u1 = dir.params[mem.r1];
    std::vector<double> t = cls.knots;
    if (mem.reversed) {
      for (double& x : t) x = 1.0 - x;
      std::reverse(t.begin(), t.end());
    }
    for (double x : t) knots.push_back(u0 + (u1 - u0) * x);
    if (s + 1 < dir.segment_class.size()) knots.insert(knots.end(), k - 1, u1);
  }
  knots.insert(knots.end(), k, 1.0);
  SG_ASSIGN_OR_RETURN(KnotVector kv, KnotVector::Create(k, std::move(knots)));
  std::vector<Pin> pins;
  for (int r : dir.splits) pins.push_back({PinnedControl(b, d, r, kv), r});
  return std::make_pair(std::move(kv), std::move(pins));
}

int SegmentModel::Controls(int b, int d) const {
  const Direction& dir = directions_[b][d];
  if (dir.m == 1) return 1;
  int n = dir.order + static_cast<int>(dir.splits.size()) * (dir.order - 1);
  for (int c : dir.segment_class) n += static_cast<int>(classes_[c].knots.size());
  return n;
}

int SegmentModel::PinnedControl(int b, int d, int r, const KnotVector& knots) const {
  const Direction& dir = directions_[b][d];
  if (r == 0) return 0;
  if (r == dir.m - 1) return knots.num_controls() - 1;
  return knots.FindSpan(dir.params[r]) - knots.order() + 1;
}

bool SegmentModel::WellPosed(int c) const {
  std::set<std::pair<int, int>> seen;
  for (const Member& mem : classes_[c].members) {
    if (!seen.insert({mem.block, mem.dir}).second) continue;
    absl::StatusOr<std::pair<KnotVector, std::vector<Pin>>> kp = DirectionKnots(mem.block, mem.dir);
    if (!kp.ok()) return false;
    const auto& [knots, pins] = *kp;
    std::vector<int> pinned = {0, knots.num_controls() - 1};
    for (const Pin& pin : pins) pinned.push_back(pin.control);
    const std::vector<double>& params = directions_[mem.block][mem.dir].params;
    if (!SchoenbergWhitneyHolds(knots, params, pinned)) return false;
    if (!DirectionFit::Create(knots, params, EndCondition::kInterpolate, pins).ok()) return false;
  }
  return true;
}

std::vector<std::pair<std::pair<int, int64_t>, std::pair<int, int64_t>>>
SegmentModel::MatchedControls(const Connectivity& connectivity,
                              const std::vector<Extents>& control_extents) const {
  std::vector<std::pair<std::pair<int, int64_t>, std::pair<int, int64_t>>> pairs;
  for (const BoundaryMatch& m : connectivity.matches) {
    const int ba = m.a.face.block, bb = m.b.face.block;
    Extents lo, hi;  // control index box of a
    std::array<int, 3> b_lo = {0, 0, 0}, b_hi = {0, 0, 0};
    bool ok = true;
    for (int d = 0; d < 3; ++d) {
      const int na = control_extents[ba][d];
      if (d == m.a.face.normal) {
        lo[d] = hi[d] = m.a.face.upper ? na - 1 : 0;
      } else if (m.b_direction[d] < 0) {
        lo[d] = hi[d] = 0;
      } else {
        const int e = m.b_direction[d];
        auto kpa = DirectionKnots(ba, d);
        auto kpb = DirectionKnots(bb, e);
        if (!kpa.ok() || !kpb.ok()) {
          ok = false;
          break;
        }
        lo[d] = PinnedControl(ba, d, m.a.begin[d], kpa->first);
        hi[d] = PinnedControl(ba, d, m.a.end[d], kpa->first);
        b_lo[e] = PinnedControl(bb, e, m.b.begin[e], kpb->first);
        b_hi[e] = PinnedControl(bb, e, m.b.end[e], kpb->first);
        if (hi[d] - lo[d] != b_hi[e] - b_lo[e]) ok = false;
      }
    }
    if (!ok) continue;
    const int nbn = m.b.face.normal;
    const int b_normal = m.b.face.upper ? control_extents[bb][nbn] - 1 : 0;
    for (int z = lo[2]; z <= hi[2]; ++z) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        for (int x = lo[0]; x <= hi[0]; ++x) {
          const Extents ca = {x, y, z};
          Extents cb = {0, 0, 0};
          cb[nbn] = b_normal;
          for (int d = 0; d < 3; ++d) {
            const int e = m.b_direction[d];
            if (e < 0) continue;
            cb[e] = m.reversed[d] ? b_hi[e] - (ca[d] - lo[d]) : b_lo[e] + (ca[d] - lo[d]);
          }
          const Extents& na = control_extents[ba];
          const Extents& nbb = control_extents[bb];
          pairs.push_back({{ba, ca[0] + int64_t{na[0]} * (ca[1] + int64_t{na[1]} * ca[2])},
                           {bb, cb[0] + int64_t{nbb[0]} * (cb[1] + int64_t{nbb[1]} * cb[2])}});
        }
      }
    }
  }
  return pairs;
}

}  // namespace splinegrid
