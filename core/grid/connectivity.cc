#include "core/grid/connectivity.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "absl/container/flat_hash_map.h"
#include "absl/container/flat_hash_set.h"
#include "absl/strings/str_cat.h"
#include "core/grid/poles.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

constexpr char kNames[] = "ijk";

// The tangential (active, non-normal) directions of a face.
std::vector<int> Tangents(const StructuredBlock& block, const Face& face) {
  std::vector<int> t;
  for (int d = 0; d < 3; ++d) {
    if (d != face.normal && block.extent(d) > 1) t.push_back(d);
  }
  return t;
}

// Boundary points of all faces, hashed by position.
class BoundaryIndex {
 public:
  // Hashes every boundary point; stops early (incomplete) once `poller` fires.
  BoundaryIndex(const MultiBlockGrid& grid, const ConnectivityOptions& options, double abs_tol,
                CancelPoller& poller)
      : grid_(grid), rel_tol_(options.relative_tolerance), abs_tol_(abs_tol) {
    for (int b = 0; b < static_cast<int>(grid.blocks.size()); ++b) {
      for (const Face& face : BlockFaces(grid.blocks[b], b)) {
        if (!AddFace(face, poller)) return;
      }
    }
  }

  struct Entry {
    int face;  // index into faces_
    Extents index;
  };

  const std::vector<Entry>& entries() const { return entries_; }
  const Face& face(int f) const { return faces_[f]; }

  // Entries whose points coincide with entry e's point (excluding the same grid point).
  std::vector<int> Partners(int e) const {
    std::vector<int> out;
    const Entry& entry = entries_[e];
    const double* p = Point(entry);
    const auto key = Key(p);
    const int s = grid_.blocks.front().spatial_dim();
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = (s == 3 ? -1 : 0); dz <= (s == 3 ? 1 : 0); ++dz) {
          const auto it = cells_.find(CellHash({key[0] + dx, key[1] + dy, key[2] + dz}));
          if (it == cells_.end()) continue;
          for (int other : it->second) {
            const Entry& o = entries_[other];
            if (faces_[o.face].block == faces_[entry.face].block && o.index == entry.index)
              continue;
            if (Coincide(faces_[entry.face].block, entry.index, faces_[o.face].block, o.index)) {
              out.push_back(other);
            }
          }
        }
      }
    }
    return out;
  }

  // Whether point x of block a and point y of block b are the same point (see the options).
  bool Coincide(int a, const Extents& x, int b, const Extents& y) const {
    const StructuredBlock& ba = grid_.blocks[a];
    const StructuredBlock& bb = grid_.blocks[b];
    const double* p = ba.Point(x[0], x[1], x[2]);
    const double* q = bb.Point(y[0], y[1], y[2]);
    double d2 = 0.0;
    for (int c = 0; c < ba.spatial_dim(); ++c) d2 += (p[c] - q[c]) * (p[c] - q[c]);
    const double d = std::sqrt(d2);
    if (d > abs_tol_) return false;
    const double h = std::min(Spacing(ba, x), Spacing(bb, y));
    return d <= std::max(rel_tol_ * h, 1e-7 * abs_tol_);
  }

  // The entry of face f at index x, or -1.
  int EntryAt(int f, const Extents& x) const {
    const auto it = face_entries_.find(FaceIndexKey(f, x));
    return it == face_entries_.end() ? -1 : it->second;
  }

  int FaceId(const Face& face) const {
    for (int f = 0; f < static_cast<int>(faces_.size()); ++f) {
      if (faces_[f] == face) return f;
    }
    return -1;
  }

 private:
  // False once `poller` fires (polled once per row of the face).
  bool AddFace(const Face& face, CancelPoller& poller) {
    const int f = static_cast<int>(faces_.size());
    faces_.push_back(face);
    const StructuredBlock& block = grid_.blocks[face.block];
    Extents lo = {0, 0, 0}, hi = {block.extent(0) - 1, block.extent(1) - 1, block.extent(2) - 1};
    lo[face.normal] = hi[face.normal] = face.upper ? block.extent(face.normal) - 1 : 0;
    for (int k = lo[2]; k <= hi[2]; ++k) {
      for (int j = lo[1]; j <= hi[1]; ++j) {
        for (int i = lo[0]; i <= hi[0]; ++i) {
          const int e = static_cast<int>(entries_.size());
          entries_.push_back({f, {i, j, k}});
          cells_[CellHash(Key(Point(entries_.back())))].push_back(e);
          face_entries_[FaceIndexKey(f, {i, j, k})] = e;
        }
        if (poller.Tick(hi[0] - lo[0] + 1)) return false;
      }
    }
    return true;
  }

  const double* Point(const Entry& e) const {
    return grid_.blocks[faces_[e.face].block].Point(e.index[0], e.index[1], e.index[2]);
  }

  std::array<int64_t, 3> Key(const double* p) const {
    const int s = grid_.blocks.front().spatial_dim();
    std::array<int64_t, 3> key = {0, 0, 0};
    for (int c = 0; c < s; ++c) key[c] = static_cast<int64_t>(std::floor(p[c] / abs_tol_));
    return key;
  }

  static uint64_t CellHash(const std::array<int64_t, 3>& key) {
    uint64_t h = 1469598103934665603ull;
    for (int64_t v : key) h = (h ^ static_cast<uint64_t>(v)) * 1099511628211ull;
    return h;
  }

  // (face, point) -> a unique key: the face in the high 32 bits, the point's linear index in
  // its block (< 2^31, see ValidateExtents) in the low ones.
  uint64_t FaceIndexKey(int f, const Extents& x) const {
    const StructuredBlock& block = grid_.blocks[faces_[f].block];
    return (static_cast<uint64_t>(f) << 32) | static_cast<uint64_t>(block.Index(x[0], x[1], x[2]));
  }

  // Smallest distance from point x to its grid neighbours (0 for a collapsed point).
  static double Spacing(const StructuredBlock& block, const Extents& x) {
    double h = INFINITY;
    const double* p = block.Point(x[0], x[1], x[2]);
    for (int d = 0; d < 3; ++d) {
      for (int step : {-1, 1}) {
        Extents y = x;
        y[d] += step;
        if (y[d] < 0 || y[d] >= block.extent(d)) continue;
        const double* q = block.Point(y[0], y[1], y[2]);
        double d2 = 0.0;
        for (int c = 0; c < block.spatial_dim(); ++c) d2 += (p[c] - q[c]) * (p[c] - q[c]);
        h = std::min(h, std::sqrt(d2));
      }
    }
    return std::isfinite(h) ? h : 0.0;
  }

  const MultiBlockGrid& grid_;
  double rel_tol_, abs_tol_;
  std::vector<Face> faces_;
  std::vector<Entry> entries_;
  absl::flat_hash_map<uint64_t, std::vector<int>> cells_;  // position cell -> entries
  absl::flat_hash_map<uint64_t, int> face_entries_;        // (face, index) -> entry
};

// Grows a match from a seed pair of coinciding points of faces fa and fb.
class MatchGrower {
 public:
  MatchGrower(const MultiBlockGrid& grid, const BoundaryIndex& index)
      : grid_(grid), index_(index) {}

  // A match through the seed with the given orientation, or none (also once `poller` fires,
  // polled once per row tried).
  std::optional<BoundaryMatch> Grow(int fa, const Extents& xa, int fb, const Extents& xb,
                                    CancelPoller& poller) const {
    const Face& a = index_.face(fa);
    const Face& b = index_.face(fb);
    const StructuredBlock& ba = grid_.blocks[a.block];
    const StructuredBlock& bb = grid_.blocks[b.block];
    const std::vector<int> ta = Tangents(ba, a), tb = Tangents(bb, b);
    if (ta.size() != tb.size() || ta.empty()) return std::nullopt;
    BoundaryMatch match;
    match.a.face = a;
    match.b.face = b;
    // The orientation: for each tangential direction of a, the direction of b (and sign, step)
    // along which the neighbouring points also coincide.
    std::vector<int> used;
    for (int d : ta) {
      bool found = false;
      for (int step : {1, 2}) {
        if (step == 2 && ta.size() > 1) continue;  // hanging nodes only on edges
        for (int e : tb) {
          if (std::find(used.begin(), used.end(), e) != used.end()) continue;
          for (int sign : {1, -1}) {
            if (NeighbourCoincides(a.block, xa, d, b.block, xb, e, sign * step)) {
              match.b_direction[d] = e;
              match.reversed[d] = sign < 0;
              match.step = step;
              used.push_back(e);
              found = true;
              break;
            }
          }
          if (found) break;
        }
        if (found) break;
      }
      if (!found) return std::nullopt;
    }
    // Grow the rectangle [lo, hi] of a's face around the seed while whole rows coincide.
    Extents lo = xa, hi = xa;
    bool grew = true;
    while (grew) {
      grew = false;
      for (int d : ta) {
        for (int side : {-1, 1}) {
          Extents nlo = lo, nhi = hi;
          if (side < 0) {
            if (lo[d] == 0) continue;
            nlo[d] = nhi[d] = lo[d] - 1;
          } else {
            if (hi[d] == ba.extent(d) - 1) continue;
            nlo[d] = nhi[d] = hi[d] + 1;
          }
          for (int o : ta) {
            if (o != d) {
              nlo[o] = lo[o];
              nhi[o] = hi[o];
            }
          }
          if (poller.Tick(
                  NumPoints({nhi[0] - nlo[0] + 1, nhi[1] - nlo[1] + 1, nhi[2] - nlo[2] + 1}))) {
            return std::nullopt;
          }
          Extents glo = lo, ghi = hi;  // the grown range
          (side < 0 ? glo[d] : ghi[d]) += side;
          if (RowCoincides(match, xa, xb, nlo, nhi) && !OverlapsItsImage(match, xa, xb, glo, ghi)) {
            lo = glo;
            hi = ghi;
            grew = true;
          }
        }
      }
    }
    match.a.begin = lo;
    match.a.end = hi;
    // b's range from the images of the corners.
    const Extents ylo = Map(match, xa, xb, lo), yhi = Map(match, xa, xb, hi);
    for (int d = 0; d < 3; ++d) {
      match.b.begin[d] = std::min(ylo[d], yhi[d]);
      match.b.end[d] = std::max(ylo[d], yhi[d]);
    }
    if (match.step == 2 && !MidpointsOnEdge(match)) return std::nullopt;
    return match;
  }

  // The index of b that the seed orientation maps x of a to.
  static Extents Map(const BoundaryMatch& m, const Extents& xa, const Extents& xb,
                     const Extents& x) {
    Extents y = xb;
    for (int d = 0; d < 3; ++d) {
      if (m.b_direction[d] < 0) continue;
      const int delta = (x[d] - xa[d]) * m.step * (m.reversed[d] ? -1 : 1);
      y[m.b_direction[d]] = xb[m.b_direction[d]] + delta;
    }
    return y;
  }

 private:
  bool Inside(const StructuredBlock& block, const Extents& x) const {
    for (int d = 0; d < 3; ++d) {
      if (x[d] < 0 || x[d] >= block.extent(d)) return false;
    }
    return true;
  }

  bool NeighbourCoincides(int a, const Extents& xa, int d, int b, const Extents& xb, int e,
                          int delta) const {
    for (int dir : {1, -1}) {
      Extents na = xa, nb = xb;
      na[d] += dir;
      nb[e] += dir * delta;
      if (!Inside(grid_.blocks[a], na)) continue;
      if (!Inside(grid_.blocks[b], nb)) return false;
      return index_.Coincide(a, na, b, nb);
    }
    return false;
  }

  // Whether range [lo, hi] of a self-match on one face (a C-grid's wake cut) overlaps its own
  // image by more than one layer of points. The two sides of a wake cut may share the point
  // where the wall line folds back (the trailing edge of a zero-thickness body) but no more:
  // grown past it, the range would cover the whole line, mapped onto itself.
  static bool OverlapsItsImage(const BoundaryMatch& m, const Extents& xa, const Extents& xb,
                               const Extents& lo, const Extents& hi) {
    if (!(m.a.face == m.b.face)) return false;
    const Extents ylo = Map(m, xa, xb, lo), yhi = Map(m, xa, xb, hi);
    for (int d = 0; d < 3; ++d) {
      if (m.b_direction[d] < 0) continue;
      const int e = m.b_direction[d];  // a tangential direction of the face, as is d
      const int shared =
          std::min(hi[e], std::max(ylo[e], yhi[e])) - std::max(lo[e], std::min(ylo[e], yhi[e]));
      if (shared <= 0) return false;  // at most one layer in common along e
    }
    return true;
  }

  bool RowCoincides(const BoundaryMatch& m, const Extents& xa, const Extents& xb, const Extents& lo,
                    const Extents& hi) const {
    const StructuredBlock& bb = grid_.blocks[m.b.face.block];
    for (int k = lo[2]; k <= hi[2]; ++k) {
      for (int j = lo[1]; j <= hi[1]; ++j) {
        for (int i = lo[0]; i <= hi[0]; ++i) {
          const Extents y = Map(m, xa, xb, {i, j, k});
          if (!Inside(bb, y) || !index_.Coincide(m.a.face.block, {i, j, k}, m.b.face.block, y)) {
            return false;
          }
        }
      }
    }
    return true;
  }

  // Hanging nodes: every odd point of the fine edge lies close to the segment between the two
  // coarse points around it (closer than a quarter of that segment's length).
  bool MidpointsOnEdge(const BoundaryMatch& m) const {
    const StructuredBlock& ba = grid_.blocks[m.a.face.block];
    const StructuredBlock& bb = grid_.blocks[m.b.face.block];
    int d = -1;
    for (int t = 0; t < 3; ++t) {
      if (m.b_direction[t] >= 0) d = t;
    }
    for (int x = m.a.begin[d]; x < m.a.end[d]; ++x) {
      Extents p0 = m.a.begin, p1 = m.a.begin;
      p0[d] = x;
      p1[d] = x + 1;
      const Extents y0 = m.MapToB(p0), y1 = m.MapToB(p1);
      Extents mid = y0;
      mid[m.b_direction[d]] = (y0[m.b_direction[d]] + y1[m.b_direction[d]]) / 2;
      const double* a0 = ba.Point(p0[0], p0[1], p0[2]);
      const double* a1 = ba.Point(p1[0], p1[1], p1[2]);
      const double* q = bb.Point(mid[0], mid[1], mid[2]);
      double seg2 = 0.0, t_num = 0.0;
      const int s = ba.spatial_dim();
      for (int c = 0; c < s; ++c) {
        seg2 += (a1[c] - a0[c]) * (a1[c] - a0[c]);
        t_num += (q[c] - a0[c]) * (a1[c] - a0[c]);
      }
      if (!(seg2 > 0.0)) return false;
      const double t = std::clamp(t_num / seg2, 0.0, 1.0);
      double dist2 = 0.0;
      for (int c = 0; c < s; ++c) {
        const double foot = a0[c] + t * (a1[c] - a0[c]);
        dist2 += (q[c] - foot) * (q[c] - foot);
      }
      if (dist2 > 0.0625 * seg2) return false;
    }
    return true;
  }

  const MultiBlockGrid& grid_;
  const BoundaryIndex& index_;
};

// Whether `range` lies on a pole: for some tangential direction d of its face, every line along
// d through its points is collapsed, over the range (the range is part of a collapsed edge) or
// over the whole face (a range one point wide along d on a face collapsed along d: a line of a
// polar axis "matched" to itself through another angle).
bool OnPole(const StructuredBlock& block, const FaceRange& range, double tolerance) {
  for (int d = 0; d < 3; ++d) {
    if (d == range.face.normal || block.extent(d) == 1) continue;
    Extents lo = range.begin, hi = range.end;
    if (lo[d] < hi[d] && BoxCollapsedAlong(block, lo, hi, d, tolerance)) return true;
    lo[d] = 0;
    hi[d] = block.extent(d) - 1;
    if (BoxCollapsedAlong(block, lo, hi, d, tolerance)) return true;
  }
  return false;
}

}  // namespace

Extents BoundaryMatch::MapToB(const Extents& x) const {
  Extents y = b.begin;
  for (int d = 0; d < 3; ++d) {
    if (b_direction[d] < 0) continue;
    const int e = b_direction[d];
    const int offset = step * (x[d] - a.begin[d]);
    y[e] = reversed[d] ? b.end[e] - offset : b.begin[e] + offset;
  }
  return y;
}

std::string FaceName(const Face& face) {
  return absl::StrCat(std::string(1, kNames[face.normal]), face.upper ? "=max" : "=0");
}

std::string BoundaryMatch::Describe() const {
  auto range = [](const FaceRange& r) {
    std::string s = absl::StrCat("block ", r.face.block, " ", FaceName(r.face));
    for (int d = 0; d < 3; ++d) {
      if (d != r.face.normal && r.end[d] > r.begin[d]) {
        absl::StrAppend(&s, " ", std::string(1, kNames[d]), "[", r.begin[d], "..", r.end[d], "]");
      }
    }
    return s;
  };
  std::string s = absl::StrCat(range(a), " ~ ", range(b));
  for (int d = 0; d < 3; ++d) {
    if (b_direction[d] >= 0) {
      absl::StrAppend(&s, " ", std::string(1, kNames[d]), "->",
                      std::string(1, kNames[b_direction[d]]), reversed[d] ? " reversed" : "");
    }
  }
  if (step == 2) absl::StrAppend(&s, " (hanging nodes)");
  return s;
}

std::vector<Face> BlockFaces(const StructuredBlock& block, int b) {
  std::vector<Face> faces;
  for (int d = 0; d < 3; ++d) {
    if (block.extent(d) > 1) {
      faces.push_back({b, d, false});
      faces.push_back({b, d, true});
    }
  }
  return faces;
}

absl::Status ConnectivityOptions::Validate() const {
  if (!std::isfinite(absolute_tolerance)) {
    return absl::InvalidArgumentError(
        absl::StrCat("connectivity.absolute_tolerance = ", absolute_tolerance, " is not finite"));
  }
  if (!(relative_tolerance > 0.0) || !std::isfinite(relative_tolerance)) {
    return absl::InvalidArgumentError(
        absl::StrCat("connectivity.relative_tolerance = ", relative_tolerance,
                     " is not a positive finite number"));
  }
  if (min_points < 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("connectivity.min_points = ", min_points, " is below 2"));
  }
  return absl::OkStatus();
}

absl::StatusOr<Connectivity> FindConnectivity(const MultiBlockGrid& grid,
                                              const ConnectivityOptions& options,
                                              const CancelCheck& cancel) {
  SG_RETURN_IF_ERROR(options.Validate());
  Connectivity connectivity;
  if (grid.blocks.empty()) return connectivity;
  const int s = grid.blocks.front().spatial_dim();
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t b = 0; b < grid.blocks.size(); ++b) {
    const StructuredBlock& block = grid.blocks[b];
    if (block.spatial_dim() != s) {
      return absl::InvalidArgumentError(absl::StrCat("block ", b, " has ", block.spatial_dim(),
                                                     " coordinates per point, block 0 has ", s));
    }
    SG_RETURN_IF_ERROR(ValidateFinite(block, absl::StrCat("block ", b)));
    const auto c = block.coords();
    for (size_t x = 0; x < c.size(); ++x) {
      lo[x % s] = std::min(lo[x % s], c[x]);
      hi[x % s] = std::max(hi[x % s], c[x]);
    }
  }
  double diag2 = 0.0;
  for (int c = 0; c < s; ++c) diag2 += (hi[c] - lo[c]) * (hi[c] - lo[c]);
  double abs_tol =
      options.absolute_tolerance > 0.0 ? options.absolute_tolerance : 1e-7 * std::sqrt(diag2);
  if (!(abs_tol > 0.0)) abs_tol = 1e-12;  // all points in one place

  // Collapsed boundary lines (poles.h) are found at this distance.
  const double pole_tol = kPoleRelativeTolerance * std::sqrt(diag2);

  // Hashing, visiting and growing are polled once per 2^16 points' work: six stacked blocks of
  // 5 x 5 x 100,001 points (15 million) take 28 s here (77 s with std::unordered_map), and a
  // cancelled search returns within 0.5-0.6 s, most of it freeing the index.
  CancelPoller poller(cancel);
  const BoundaryIndex index(grid, options, abs_tol, poller);
  SG_RETURN_IF_ERROR(poller.status());
  const MatchGrower grower(grid, index);
  // Pairs of entries already explained by a recorded match (both orders).
  absl::flat_hash_set<uint64_t> covered;
  auto pair_key = [](int x, int y) {
    return (static_cast<uint64_t>(x) << 32) | static_cast<uint32_t>(y);
  };
  const auto& entries = index.entries();
  for (int e = 0; e < static_cast<int>(entries.size()); ++e) {
    // A visit looks up to 27 hash cells: counted as 27 points' work.
    if (poller.Tick(27)) return poller.status();
    for (int p : index.Partners(e)) {
      if (p < e || covered.contains(pair_key(e, p))) continue;
      // e as the first range; with hanging nodes the coarse side comes first, so if e is the
      // fine side only the swapped attempt succeeds.
      std::optional<BoundaryMatch> match =
          grower.Grow(entries[e].face, entries[e].index, entries[p].face, entries[p].index, poller);
      if (!match) {
        match = grower.Grow(entries[p].face, entries[p].index, entries[e].face, entries[e].index,
                            poller);
      }
      if (poller.cancelled()) return poller.status();
      if (!match) continue;
      // Mark every point pair of the match.
      int count = 0;
      const BoundaryMatch& m = *match;
      const int fa = index.FaceId(m.a.face), fb = index.FaceId(m.b.face);
      for (int k = m.a.begin[2]; k <= m.a.end[2]; ++k) {
        for (int j = m.a.begin[1]; j <= m.a.end[1]; ++j) {
          for (int i = m.a.begin[0]; i <= m.a.end[0]; ++i) {
            const int ea = index.EntryAt(fa, {i, j, k});
            const int eb = index.EntryAt(fb, m.MapToB({i, j, k}));
            if (ea >= 0 && eb >= 0) {
              covered.insert(pair_key(ea, eb));
              covered.insert(pair_key(eb, ea));
            }
            ++count;
          }
          if (poller.Tick(m.a.end[0] - m.a.begin[0] + 1)) return poller.status();
        }
      }
      // A self-match of a face onto itself must not map points onto themselves. A range
      // collapsed along one of its directions (a pole: the centre of a polar disk, a polar axis)
      // coincides with itself and with every other collapsed range there in any order and
      // shift, so its "matches" say nothing about which points belong together: drop them. The
      // blocks around a pole still share it through the faces that meet there (the radial
      // edges of a polar disk's blocks), and the fit keeps it collapsed (multiblock_fit.cc).
      if (count >= options.min_points &&
          !(m.a.face == m.b.face && m.a.begin == m.b.begin && m.a.end == m.b.end) &&
          !OnPole(grid.blocks[m.a.face.block], m.a, pole_tol) &&
          !OnPole(grid.blocks[m.b.face.block], m.b, pole_tol)) {
        connectivity.matches.push_back(m);
      }
    }
  }
  return connectivity;
}

}  // namespace splinegrid
