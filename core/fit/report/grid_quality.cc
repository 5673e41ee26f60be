#include "core/fit/report/grid_quality.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "core/grid/sampling.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

// A cell is skipped when |measure| <= kDegenerateRelTol * the block's median |measure| ...
constexpr double kDegenerateRelTol = 1e-12;
// ... or when one of its edges is at most kCollapsedEdgeRelTol * its longest edge.
constexpr double kCollapsedEdgeRelTol = 1e-9;

enum class CellKind { kPlanar, kSurface, kVolume };

// Doubles per point and per measure: planar (2, 1), surface (3, 3), volume (3, 1).
template <CellKind K>
constexpr int kStride = K == CellKind::kPlanar ? 2 : 3;
template <CellKind K>
constexpr int kWidth = K == CellKind::kSurface ? 3 : 1;
template <CellKind K>
constexpr int kCorners = K == CellKind::kVolume ? 8 : 4;

// Corner pointers of a cell in binary order.
using Corners = std::array<const double*, 8>;

// A point or vector; the measures are written with it once, for single cells (Measure) and for
// whole rows of cells (RowMeasures, where the compiler vectorises them across cells).
struct Vec {
  double x, y, z;
};
[[gnu::always_inline]] inline Vec operator-(const Vec& a, const Vec& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
[[gnu::always_inline]] inline Vec operator+(const Vec& a, const Vec& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
[[gnu::always_inline]] inline Vec Cross(const Vec& a, const Vec& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
[[gnu::always_inline]] inline double Dot(const Vec& a, const Vec& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

// Signed volume of the trilinear hexahedron (see the header): the 6-tetrahedra volume around the
// diagonal x0-x7 (Grandy's formula) plus, per face, half the tetrahedron between that face's two
// triangulations.
[[gnu::always_inline]] inline double HexVolume(const Vec (&x)[8]) {
  const Vec d70 = x[7] - x[0];
  const double six_tets =
      Dot(d70, Cross(x[1] - x[0], x[3] - x[5]) + Cross(x[4] - x[0], x[5] - x[6]) +
                   Cross(x[2] - x[0], x[6] - x[3]));
  // Faces a b c d in outward cyclic order, a-c the diagonal the six tetrahedra use.
  auto face = [&x](int a, int b, int c, int d) {
    return Dot(x[b] - x[a], Cross(x[c] - x[a], x[d] - x[a]));
  };
  const double warp = face(0, 2, 3, 1) + face(4, 5, 7, 6) + face(0, 4, 6, 2) + face(1, 3, 7, 5) +
                      face(0, 1, 5, 4) + face(2, 6, 7, 3);
  return six_tets / 6.0 + warp / 12.0;
}

// The signed measure of a cell from its corners in binary order (kWidth<K> doubles; planar
// corners have z = 0).
template <CellKind K>
[[gnu::always_inline]] inline void MeasureOf(const Vec (&x)[8], double* m) {
  if constexpr (K == CellKind::kVolume) {
    m[0] = HexVolume(x);
  } else {
    const Vec a = Cross(x[3] - x[0], x[2] - x[1]);
    if constexpr (K == CellKind::kPlanar) {
      m[0] = 0.5 * a.z;
    } else {
      m[0] = 0.5 * a.x;
      m[1] = 0.5 * a.y;
      m[2] = 0.5 * a.z;
    }
  }
}

// The signed measure of a cell (kWidth<K> doubles).
template <CellKind K>
void Measure(const Corners& corners, double* m) {
  Vec x[8] = {};
  for (int a = 0; a < kCorners<K>; ++a) {
    x[a] = {corners[a][0], corners[a][1], kStride<K> == 3 ? corners[a][2] : 0.0};
  }
  MeasureOf<K>(x, m);
}

template <int S>
void Diff(const double* a, const double* b, double* out) {
  for (int c = 0; c < S; ++c) out[c] = a[c] - b[c];
}

// Whether an edge of the cell is at most kCollapsedEdgeRelTol times its longest edge.
template <CellKind K>
bool HasCollapsedEdge(const Corners& x) {
  double shortest = std::numeric_limits<double>::infinity(), longest = 0.0;
  for (int a = 0; a < kCorners<K>; ++a) {
    for (int bit = 1; bit < kCorners<K>; bit <<= 1) {
      if (a & bit) continue;  // every edge once, from its lower corner
      double d[kStride<K>];
      Diff<kStride<K>>(x[a | bit], x[a], d);
      double length2 = 0.0;
      for (double v : d) length2 += v * v;
      shortest = std::min(shortest, length2);
      longest = std::max(longest, length2);
    }
  }
  return shortest <= kCollapsedEdgeRelTol * kCollapsedEdgeRelTol * longest;
}

// The cells of a block (or refined block) as rows of its slowest active direction.
struct RowLayout {
  int fast_points = 1;        // points per row in the fastest active direction
  int mid_points = 1;         // ... in the middle active direction (volumes; else 1)
  int rows = 1;               // points in the slowest active direction
  int64_t row_points = 1;     // fast_points * mid_points, contiguous in the block's order
  int64_t lines_per_row = 1;  // GridEvaluator lines per row
};

RowLayout MakeLayout(const Extents& points, const std::array<int, 3>& active, int num_active) {
  RowLayout layout;
  layout.fast_points = points[active[0]];
  if (num_active == 3) layout.mid_points = points[active[1]];
  const int slowest = active[num_active - 1];
  layout.rows = points[slowest];
  layout.row_points = int64_t{layout.fast_points} * layout.mid_points;
  // Rows along k span all j lines of a plane (one line when j is inactive); rows along j
  // (k inactive) are single lines.
  layout.lines_per_row = slowest == 2 ? points[1] : 1;
  return layout;
}

// Calls f(I, J, corners) for every cell between rows `lo` and `hi` (J = 0 for surfaces).
template <CellKind K, typename F>
void ForEachCell(const double* lo, const double* hi, const RowLayout& layout, F&& f) {
  constexpr int s = kStride<K>;
  const int64_t n0 = layout.fast_points;
  const int mid_cells = K == CellKind::kVolume ? layout.mid_points - 1 : 1;
  Corners x{};
  for (int J = 0; J < mid_cells; ++J) {
    for (int I = 0; I + 1 < n0; ++I) {
      const int64_t c = s * (I + n0 * J);
      x[0] = lo + c;
      x[1] = lo + c + s;
      if constexpr (K == CellKind::kVolume) {
        x[2] = lo + c + s * n0;
        x[3] = x[2] + s;
        x[4] = hi + c;
        x[5] = hi + c + s;
        x[6] = hi + c + s * n0;
        x[7] = x[6] + s;
      } else {
        x[2] = hi + c;
        x[3] = hi + c + s;
      }
      f(I, J, x);
    }
  }
}

// A row of points, kStride doubles each, rearranged component by component: coordinate c of
// point p goes to out[c * points + p].
template <int S>
void Deinterleave(const double* row, int64_t points, double* out) {
  for (int64_t p = 0; p < points; ++p) {
    for (int c = 0; c < S; ++c) out[c * points + p] = row[S * p + c];
  }
}

// The measures of the cells between two rows of points given component by component
// (Deinterleave), component-major: component c of cell I + (fast_points - 1) J goes to
// out[c * cells + I + (fast_points - 1) J], cells = the row's cells. The formulas of Measure, in
// loops over I that the compiler vectorises.
template <CellKind K>
void RowMeasures(const double* lo, const double* hi, const RowLayout& layout, double* out) {
  constexpr int s = kStride<K>;
  const int64_t n0 = layout.fast_points;
  const int64_t fast_cells = n0 - 1;
  const int mid_cells = K == CellKind::kVolume ? layout.mid_points - 1 : 1;
  const int64_t cells = fast_cells * mid_cells;
  for (int J = 0; J < mid_cells; ++J) {
    const double* corner[kCorners<K>][s];
    for (int a = 0; a < kCorners<K>; ++a) {
      const bool upper = (a & (K == CellKind::kVolume ? 4 : 2)) != 0;
      const bool next_line = K == CellKind::kVolume && (a & 2) != 0;
      const int64_t offset = n0 * J + (a & 1) + (next_line ? n0 : 0);
      for (int c = 0; c < s; ++c) corner[a][c] = (upper ? hi : lo) + c * layout.row_points + offset;
    }
    double* m = out + fast_cells * J;
#pragma GCC ivdep
    for (int64_t I = 0; I < fast_cells; ++I) {
      Vec x[8] = {};
      for (int a = 0; a < kCorners<K>; ++a) {
        x[a] = {corner[a][0][I], corner[a][1][I], s == 3 ? corner[a][s - 1][I] : 0.0};
      }
      double value[kWidth<K>];
      MeasureOf<K>(x, value);
      for (int c = 0; c < kWidth<K>; ++c) m[c * cells + I] = value[c];
    }
  }
}

// kFolded: some sub-cell folded (it is bad too); kBad: only out of size.
enum CellState : uint8_t { kChecked = 0, kSkipped = 1, kBad = 2, kFolded = 3 };

// Per original cell: weights w with ratio = <measure_fitted, w> / share, and its state.
struct Reference {
  std::vector<double> weight;  // kWidth doubles per cell
  std::vector<uint8_t> state;
  int fast_cells = 0, mid_cells = 1;
};

template <CellKind K>
Reference BuildReference(const StructuredBlock& original, const RowLayout& layout) {
  constexpr int width = kWidth<K>;
  Reference ref;
  ref.fast_cells = layout.fast_points - 1;
  ref.mid_cells = K == CellKind::kVolume ? layout.mid_points - 1 : 1;
  const int64_t cells = int64_t{ref.fast_cells} * ref.mid_cells * (layout.rows - 1);
  ref.weight.resize(width * cells);
  ref.state.assign(cells, kChecked);
  std::vector<double> size(cells);
  const double* coords = original.coords().data();
  const int64_t row_size = kStride<K> * layout.row_points;
  int64_t cell = 0;
  for (int r = 0; r + 1 < layout.rows; ++r) {
    const double* lo = coords + r * row_size;
    ForEachCell<K>(lo, lo + row_size, layout, [&](int, int, const Corners& x) {
      double* m = ref.weight.data() + width * cell;
      Measure<K>(x, m);
      double norm2 = 0.0;
      for (int c = 0; c < width; ++c) norm2 += m[c] * m[c];
      size[cell] = std::sqrt(norm2);
      if (HasCollapsedEdge<K>(x)) ref.state[cell] = kSkipped;
      ++cell;
    });
  }
  std::vector<double> sorted = size;
  std::nth_element(sorted.begin(), sorted.begin() + cells / 2, sorted.end());
  const double threshold = kDegenerateRelTol * sorted[cells / 2];
  for (int64_t q = 0; q < cells; ++q) {
    double* w = ref.weight.data() + width * q;
    const double norm2 = size[q] * size[q];
    if (size[q] <= threshold || !(1.0 / norm2 < std::numeric_limits<double>::infinity())) {
      ref.state[q] = kSkipped;
    }
    // w = m / |m|^2: 1 / m for one component, a / |a|^2 for area vectors.
    for (int c = 0; c < width; ++c) w[c] = ref.state[q] == kSkipped ? 0.0 : w[c] / norm2;
  }
  return ref;
}

// The share of its parent each refined interval at `level` gets: 1 / (du_sub / du_parent) per
// active direction (a = 0 fast, 1 mid for volumes, num_active - 1 slow), for the samples
// `params` of `distribution` at that level.
std::array<std::vector<double>, 3> InverseShares(const PointDistribution& distribution,
                                                 const std::array<std::vector<double>, 3>& params,
                                                 const std::array<int, 3>& active, int num_active,
                                                 int level) {
  std::array<std::vector<double>, 3> inverse_share;
  for (int a = 0; a < num_active; ++a) {
    const std::vector<double>& sub = params[active[a]];
    const std::vector<double>& u = distribution.params(active[a]);
    inverse_share[a].resize(sub.size() - 1);
    for (size_t I = 0; I + 1 < sub.size(); ++I) {
      const size_t p = I >> level;
      inverse_share[a][I] = (u[p + 1] - u[p]) / (sub[I + 1] - sub[I]);
    }
  }
  return inverse_share;
}

// The points per chunk of the fast direction. Chunks overlap by one point: GridEvaluator holds
// the control net contracted in u, kStride * (chunk points) * n_v * n_w doubles (`stride` is
// kStride), which the budget bounds (i fast only; otherwise that net is the control net itself).
int ChunkPoints(int stride, int fast, int fast_points, const Extents& controls,
                int64_t evaluator_budget) {
  if (fast != 0) return fast_points;
  const int64_t per_point = int64_t{stride} * controls[1] * controls[2];
  return static_cast<int>(std::clamp<int64_t>(evaluator_budget / per_point, 2, fast_points));
}

// The size-ratio check of a fitted block's cells against the original grid's (BuildReference)
// at refinement levels 0..max_level, one chunk of refined rows at a time; the state its steps
// share.
template <CellKind K>
class CellChecker {
 public:
  CellChecker(const FittedBlock& fitted, const Reference& ref, const std::array<int, 3>& active,
              int num_active, const CellQualityOptions& options)
      : fitted_(fitted),
        active_(active),
        num_active_(num_active),
        options_(options),
        ref_(ref),
        state_(ref.state),
        low_(1.0 / options.max_size_ratio),
        high_(options.max_size_ratio) {
    q_.folded_by_level.assign(options.max_level + 1, 0);
  }

  // Checks every sub-cell of refinement level `level`.
  absl::Status CheckLevel(int level) {
    Resolution resolution;
    resolution.level = level;
    SG_ASSIGN_OR_RETURN(const auto params, SampleParameters(fitted_.distribution, resolution));
    const std::array<std::vector<double>, 3> inverse_share =
        InverseShares(fitted_.distribution, params, active_, num_active_, level);
    const int fast = active_[0];
    const int fast_points = static_cast<int>(params[fast].size());
    const int chunk = ChunkPoints(kStride<K>, fast, fast_points, fitted_.spline.control_extents(),
                                  options_.evaluator_budget);
    std::array<std::vector<double>, 3> part = params;
    for (int first = 0; first + 1 < fast_points; first += chunk - 1) {
      const int last = std::min(fast_points - 1, first + chunk - 1);
      part[fast].assign(params[fast].begin() + first, params[fast].begin() + last + 1);
      SG_RETURN_IF_ERROR(CheckChunk(level, part, first, inverse_share));
    }
    return absl::OkStatus();
  }

  // The quality after the levels were checked: the worst cell and the bad and folded cells.
  CellQuality Finish() {
    if (q_.cells_checked > 0) q_.worst_cell = ToCell(worst_parent_);
    for (int64_t parent = 0; parent < static_cast<int64_t>(state_.size()); ++parent) {
      if (state_[parent] != kBad && state_[parent] != kFolded) continue;
      if (state_[parent] == kFolded) {
        ++q_.num_folded_cells;
        if (static_cast<int64_t>(q_.folded_cells.size()) < options_.max_reported_cells) {
          q_.folded_cells.push_back(ToCell(parent));
        }
      }
      ++q_.num_bad_cells;
      if (static_cast<int64_t>(q_.bad_cells.size()) < options_.max_reported_cells) {
        q_.bad_cells.push_back(ToCell(parent));
      }
    }
    return std::move(q_);
  }

 private:
  // Checks the sub-cells of level `level` in the chunk of fast points from `first` (the
  // parameters `part`), row by row of the slowest direction.
  absl::Status CheckChunk(int level, const std::array<std::vector<double>, 3>& part, int first,
                          const std::array<std::vector<double>, 3>& inverse_share) {
    constexpr int width = kWidth<K>;
    const std::vector<double>& slow_share = inverse_share[num_active_ - 1];
    GridEvaluator evaluator(fitted_.spline, part, /*first_derivatives=*/false);
    const RowLayout layout = MakeLayout(evaluator.extents(), active_, num_active_);
    const int64_t row_size = kStride<K> * layout.row_points;
    const int64_t fast_cells = layout.fast_points - 1;
    const int mid_cells = K == CellKind::kVolume ? layout.mid_points - 1 : 1;
    const int64_t row_cells = fast_cells * mid_cells;
    // A row as evaluated, and the lower and upper rows of the cells component by component.
    std::vector<double> row(row_size), lo(row_size), hi(row_size), measures(width * row_cells);
    evaluator.EvaluateLines(0, layout.lines_per_row, row.data());
    Deinterleave<kStride<K>>(row.data(), layout.row_points, lo.data());
    for (int r = 0; r + 1 < layout.rows; ++r) {
      SG_RETURN_IF_ERROR(PollCancel(options_.cancel));
      evaluator.EvaluateLines((r + 1) * layout.lines_per_row, (r + 2) * layout.lines_per_row,
                              row.data());
      Deinterleave<kStride<K>>(row.data(), layout.row_points, hi.data());
      RowMeasures<K>(lo.data(), hi.data(), layout, measures.data());
      const int64_t parent_row = int64_t{ref_.fast_cells} * ref_.mid_cells * (r >> level);
      for (int J = 0; J < mid_cells; ++J) {
        const int64_t parent_line = parent_row + int64_t{ref_.fast_cells} * (J >> level);
        double line_share = slow_share[r];
        if constexpr (K == CellKind::kVolume) line_share *= inverse_share[1][J];
        const double* m = measures.data() + fast_cells * J;
        for (int64_t I = 0; I < fast_cells; ++I) {
          const int64_t parent = parent_line + ((first + I) >> level);
          uint8_t& state = state_[parent];
          if (state == kSkipped) {
            ++q_.cells_skipped;
            continue;
          }
          const double* w = ref_.weight.data() + width * parent;
          double ratio = 0.0;
          for (int c = 0; c < width; ++c) ratio += m[c * row_cells + I] * w[c];
          Tally(ratio * (inverse_share[0][first + I] * line_share), level, parent, state);
        }
      }
      std::swap(lo, hi);
    }
    return absl::OkStatus();
  }

  // Counts a checked sub-cell of `parent` with Jacobian ratio `ratio`: the worst so far, folded
  // (ratio <= 0) or out of size, and marks the parent's `state`.
  void Tally(double ratio, int level, int64_t parent, uint8_t& state) {
    ++q_.cells_checked;
    if (ratio < q_.min_ratio) {
      q_.min_ratio = ratio;
      q_.worst_level = level;
      worst_parent_ = parent;
    }
    q_.max_ratio = std::max(q_.max_ratio, std::abs(ratio));
    if (ratio <= 0.0) {
      ++q_.folded;
      ++q_.folded_by_level[level];
      state = kFolded;
    } else if (ratio < low_ || ratio > high_) {
      ++q_.out_of_size;
      if (state != kFolded) state = kBad;
    }
  }

  // Parent index -> original-grid cell (lower corner).
  Extents ToCell(int64_t parent) const {
    Extents cell = {0, 0, 0};
    const int64_t per_row = int64_t{ref_.fast_cells} * ref_.mid_cells;
    cell[active_[0]] = static_cast<int>(parent % ref_.fast_cells);
    if (num_active_ == 3) {
      cell[active_[1]] = static_cast<int>(parent / ref_.fast_cells % ref_.mid_cells);
    }
    cell[active_[num_active_ - 1]] = static_cast<int>(parent / per_row);
    return cell;
  }

  const FittedBlock& fitted_;
  const std::array<int, 3> active_;
  const int num_active_;
  const CellQualityOptions& options_;
  const Reference& ref_;
  std::vector<uint8_t> state_;  // ref_.state, then marked bad or folded by this check
  const double low_, high_;     // the size ratios allowed
  CellQuality q_;
  int64_t worst_parent_ = 0;
};

// The cell quality of `fitted` against `ref` (CheckCellQuality after its checks).
template <CellKind K>
absl::StatusOr<CellQuality> Check(const FittedBlock& fitted, const Reference& ref,
                                  const std::array<int, 3>& active, int num_active,
                                  const CellQualityOptions& options) {
  CellChecker<K> checker(fitted, ref, active, num_active, options);
  for (int level = 0; level <= options.max_level; ++level) {
    SG_RETURN_IF_ERROR(checker.CheckLevel(level));
  }
  return checker.Finish();
}

std::string ExtentsString(const Extents& e) { return absl::StrCat(e[0], " x ", e[1], " x ", e[2]); }

}  // namespace

std::string DescribeFolds(int block, const CellQuality& quality, int max_listed) {
  if (quality.folded == 0) return "";
  std::vector<std::string> levels;
  for (size_t l = 0; l < quality.folded_by_level.size(); ++l) {
    if (quality.folded_by_level[l] > 0) {
      levels.push_back(absl::StrCat(quality.folded_by_level[l], " at level ", l));
    }
  }
  auto cell = [](const Extents& c) { return absl::StrCat("(", c[0], ", ", c[1], ", ", c[2], ")"); };
  std::string out = absl::StrCat("block ", block, ": ", quality.folded, " folded sub-cells (",
                                 absl::StrJoin(levels, ", "), ") in ", quality.num_folded_cells,
                                 " cells; the worst at cell ", cell(quality.worst_cell), ", level ",
                                 quality.worst_level, ", Jacobian ratio ", quality.min_ratio);
  const size_t listed = std::min<size_t>(quality.folded_cells.size(), std::max(max_listed, 0));
  if (listed > 0) {
    absl::StrAppend(&out, "; cells");
    for (size_t q = 0; q < listed; ++q) {
      absl::StrAppend(&out, q ? ", " : " ", cell(quality.folded_cells[q]));
    }
    if (static_cast<int64_t>(listed) < quality.num_folded_cells) absl::StrAppend(&out, ", ...");
  }
  return out;
}

absl::Status CellQualityOptions::Validate() const {
  if (max_level < 0 || max_level > kMaxRefinementLevel) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_level = ", max_level, " is not in [0, ", kMaxRefinementLevel, "]"));
  }
  if (!(max_size_ratio >= 1.0 && std::isfinite(max_size_ratio))) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_size_ratio = ", max_size_ratio, " is not a finite number >= 1"));
  }
  if (max_reported_cells < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_reported_cells = ", max_reported_cells, " is negative"));
  }
  if (evaluator_budget < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("evaluator_budget = ", evaluator_budget, " is not positive"));
  }
  return absl::OkStatus();
}

namespace {

// OK if `fitted` is a fit of a block of `extents` and `spatial_dim`; INVALID_ARGUMENT naming both.
absl::Status CheckFitOf(const FittedBlock& fitted, const Extents& extents, int spatial_dim) {
  Extents fitted_extents;
  for (int d = 0; d < 3; ++d) fitted_extents[d] = fitted.distribution.num_points(d);
  if (fitted_extents != extents) {
    return absl::InvalidArgumentError(
        absl::StrCat("fitted block has extents ", ExtentsString(fitted_extents),
                     " but the original block has ", ExtentsString(extents)));
  }
  if (fitted.spline.spatial_dim() != spatial_dim) {
    return absl::InvalidArgumentError(
        absl::StrCat("fitted block has spatial_dim ", fitted.spline.spatial_dim(),
                     " but the original block has spatial_dim ", spatial_dim));
  }
  return absl::OkStatus();
}

}  // namespace

// The reference cells and how a block's directions map onto them.
struct CellReference::Cells {
  Extents extents;
  int spatial_dim = 0;
  std::array<int, 3> active = {0, 0, 0};
  int num_active = 0;
  CellKind kind = CellKind::kPlanar;
  Reference ref;  // empty for points and curves (no cells)
};

absl::StatusOr<CellReference> CellReference::Build(const StructuredBlock& original) {
  SG_RETURN_IF_ERROR(ValidateFinite(original, "original block"));
  auto cells = std::make_shared<Cells>();
  cells->extents = original.extents();
  cells->spatial_dim = original.spatial_dim();
  for (int d = 0; d < 3; ++d) {
    if (original.extent(d) > 1) cells->active[cells->num_active++] = d;
  }
  const std::array<int, 3>& active = cells->active;
  const int num_active = cells->num_active;
  if (num_active < 2) return CellReference(std::move(cells));  // points and curves: no cells
  const RowLayout layout = MakeLayout(original.extents(), active, num_active);
  if (num_active == 3) {
    if (original.spatial_dim() != 3) {
      return absl::InvalidArgumentError(
          absl::StrCat("block of ", ExtentsString(original.extents()),
                       " points has three active directions but spatial_dim 2; volumes need 3"));
    }
    cells->kind = CellKind::kVolume;
    cells->ref = BuildReference<CellKind::kVolume>(original, layout);
  } else if (original.spatial_dim() == 2) {
    cells->kind = CellKind::kPlanar;
    cells->ref = BuildReference<CellKind::kPlanar>(original, layout);
  } else {
    cells->kind = CellKind::kSurface;
    cells->ref = BuildReference<CellKind::kSurface>(original, layout);
  }
  return CellReference(std::move(cells));
}

const Extents& CellReference::extents() const { return cells_->extents; }
int CellReference::spatial_dim() const { return cells_->spatial_dim; }
int64_t CellReference::num_cells() const { return cells_->ref.state.size(); }
int64_t CellReference::bytes() const {
  return static_cast<int64_t>(sizeof(Cells) + cells_->ref.weight.size() * sizeof(double) +
                              cells_->ref.state.size());
}

absl::StatusOr<CellQuality> CheckCellQuality(const FittedBlock& fitted,
                                             const CellReference& reference,
                                             const CellQualityOptions& options) {
  SG_RETURN_IF_ERROR(options.Validate());
  SG_RETURN_IF_ERROR(CheckFitOf(fitted, reference.extents(), reference.spatial_dim()));
  const CellReference::Cells& cells = *reference.cells_;
  if (cells.num_active < 2) return CellQuality{};  // points and curves have no cells
  switch (cells.kind) {
    case CellKind::kVolume:
      return Check<CellKind::kVolume>(fitted, cells.ref, cells.active, cells.num_active, options);
    case CellKind::kPlanar:
      return Check<CellKind::kPlanar>(fitted, cells.ref, cells.active, cells.num_active, options);
    case CellKind::kSurface:
      break;
  }
  return Check<CellKind::kSurface>(fitted, cells.ref, cells.active, cells.num_active, options);
}

absl::StatusOr<CellQuality> CheckCellQuality(const FittedBlock& fitted,
                                             const StructuredBlock& original,
                                             const CellQualityOptions& options) {
  // The checks of the options and shapes come first, as before the reference is built.
  SG_RETURN_IF_ERROR(options.Validate());
  SG_RETURN_IF_ERROR(CheckFitOf(fitted, original.extents(), original.spatial_dim()));
  SG_ASSIGN_OR_RETURN(const CellReference reference, CellReference::Build(original));
  return CheckCellQuality(fitted, reference, options);
}

double PlanarCellArea(const std::array<Point3, 4>& corners) {
  const Corners x = {corners[0].data(), corners[1].data(), corners[2].data(), corners[3].data()};
  double m;
  Measure<CellKind::kPlanar>(x, &m);
  return m;
}

Point3 CellAreaVector(const std::array<Point3, 4>& corners) {
  const Corners x = {corners[0].data(), corners[1].data(), corners[2].data(), corners[3].data()};
  Point3 a;
  Measure<CellKind::kSurface>(x, a.data());
  return a;
}

double HexahedronVolume(const std::array<Point3, 8>& corners) {
  Vec x[8];
  for (int n = 0; n < 8; ++n) x[n] = {corners[n][0], corners[n][1], corners[n][2]};
  return HexVolume(x);
}

}  // namespace splinegrid
