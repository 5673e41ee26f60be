#include "core/fit/adaptive/multiblock_fit.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <tuple>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/fit/adaptive/adaptive_engine.h"
#include "core/fit/adaptive/segment_model.h"
#include "core/fit/report/fit_report.h"
#include "core/grid/boundary_kinds.h"
#include "core/util/status_macros.h"
#include "core/util/union_find.h"

namespace splinegrid::internal {
namespace {

// Union-find over (block, control index) pairs: a control's id is its block's offset plus its
// index, so the first block in order owns a shared boundary (UnionFind keeps the smaller id).
class ControlSets : public UnionFind {
 public:
  explicit ControlSets(const std::vector<FittedBlock>& blocks) : ControlSets(Offsets(blocks)) {}
  int64_t Id(int b, int64_t c) const { return offsets_[b] + c; }
  std::pair<int, int64_t> Locate(int64_t id) const {
    const int b = static_cast<int>(std::upper_bound(offsets_.begin(), offsets_.end(), id) -
                                   offsets_.begin()) -
                  1;
    return {b, id - offsets_[b]};
  }

 private:
  explicit ControlSets(std::vector<int64_t> offsets)
      : UnionFind(offsets.back()), offsets_(std::move(offsets)) {}
  // 0, then the running totals of the blocks' controls.
  static std::vector<int64_t> Offsets(const std::vector<FittedBlock>& blocks) {
    std::vector<int64_t> offsets = {0};
    for (const FittedBlock& b : blocks) {
      offsets.push_back(offsets.back() + b.spline.num_control_points());
    }
    return offsets;
  }
  std::vector<int64_t> offsets_;
};

// The control index box of pole p in a spline with `n` controls per direction: every control
// along p.d, and in each other direction the first or last control where the pole is on that
// end of the block (the control a clamped end interpolates), else all of them.
std::pair<Extents, Extents> PoleControlBox(const Pole& p, const StructuredBlock& block,
                                           const Extents& n) {
  Extents lo = {0, 0, 0}, hi = {n[0] - 1, n[1] - 1, n[2] - 1};
  for (int e = 0; e < 3; ++e) {
    if (e == p.d || p.lo[e] != p.hi[e] || block.extent(e) == 1) continue;
    lo[e] = hi[e] = p.lo[e] == 0 ? 0 : n[e] - 1;
  }
  return {lo, hi};
}

// Calls f(line_start, d) for every line of controls along p.d in the pole's control box.
template <typename F>
void ForEachPoleLine(const Pole& p, const StructuredBlock& block, const Extents& n, F f) {
  const auto [lo, hi] = PoleControlBox(p, block, n);
  const int e1 = p.d == 0 ? 1 : 0, e2 = p.d == 2 ? 1 : 2;
  for (int y = lo[e2]; y <= hi[e2]; ++y) {
    for (int x = lo[e1]; x <= hi[e1]; ++x) {
      Extents at = {0, 0, 0};
      at[e1] = x;
      at[e2] = y;
      f(at);
    }
  }
}

// Keeps every pole collapsed: each line of controls along a pole's collapsed direction takes
// the mean of its controls.
//
// Why the mean is the constrained least-squares fit, not an approximation of it. Take a surface
// block whose edge v = 0 is collapsed to the point c (the data X_{r,0} = c for all r), fitted
// with clamped knots and interpolated ends: the controls of the edge, P_{a,0}, are then the fit
// of the edge data alone along u, P_{.,0} = A^+ X_{.,0} (A the collocation matrix along u,
// A^+ its least-squares solution operator, with the pins of the segment model), because along v
// the first control is pinned to the first datum of every line. The data are c 1, and B-splines
// reproduce constants (A 1 = 1, partition of unity): the net c 1 satisfies every pin (end and
// split pins take data values, all c) with zero residual, and A has full column rank, so it is
// the unique minimiser, P_{.,0} = c 1, in exact arithmetic. Fairing rows (differences of
// neighbouring controls) vanish on it too. So the unconstrained fit already satisfies
// the constraint P_{a,0} = P_{0,0}, so it is also the constrained fit (the minimiser over a set
// that contains the unconstrained minimiser). The same holds for a volume's face collapsed along
// u to a line (X_{r,s,0} = Y_s): P_{.,.,0} = (A_u^+ (x) A_v^+) (1 Y^T) = 1 (A_v^+ Y)^T, every line
// along u constant and the axis fitted as a curve along v. In floating point the controls of a
// line differ by rounding (about 1e-16 of the coordinates), which would leave a pole not quite a
// point and blocks meeting at it a hair apart; the mean removes that (it is the orthogonal
// projection onto {P_a = P_0}, so it also picks the closest collapsed net when the data are only
// collapsed to within kPoleRelativeTolerance), and CopySharedControls then makes the poles of
// all blocks bitwise one point.
void CollapsePoles(const std::vector<Pole>& poles, const MultiBlockGrid& grid,
                   std::vector<FittedBlock>& blocks) {
  if (blocks.empty()) return;  // no unfaired fit
  for (const Pole& p : poles) {
    TensorSpline& spline = blocks[p.block].spline;
    const Extents n = spline.control_extents();
    const int s = spline.spatial_dim();
    std::span<double> control = spline.mutable_control();
    const int64_t stride = p.d == 0 ? 1 : (p.d == 1 ? n[0] : int64_t{n[0]} * n[1]);
    ForEachPoleLine(p, grid.blocks[p.block], n, [&](const Extents& at) {
      const int64_t first = at[0] + int64_t{n[0]} * (at[1] + int64_t{n[1]} * at[2]);
      double mean[3] = {0.0, 0.0, 0.0};
      for (int a = 0; a < n[p.d]; ++a) {
        for (int c = 0; c < s; ++c) mean[c] += control[s * (first + a * stride) + c];
      }
      for (int a = 0; a < n[p.d]; ++a) {
        for (int c = 0; c < s; ++c) control[s * (first + a * stride) + c] = mean[c] / n[p.d];
      }
    });
  }
}

// Makes the controls of every matched boundary bitwise identical, and those of every line of a
// pole: each set takes the value of its first member. Returns the largest change (rounding only
// when the model is consistent).
double CopySharedControls(const SegmentModel& model, const Connectivity& connectivity,
                          const std::vector<Pole>& poles, const MultiBlockGrid& grid,
                          std::vector<FittedBlock>& blocks) {
  std::vector<Extents> extents;
  for (const FittedBlock& b : blocks) extents.push_back(b.spline.control_extents());
  ControlSets sets(blocks);
  for (const auto& [x, y] : model.MatchedControls(connectivity, extents)) {
    sets.Join(sets.Id(x.first, x.second), sets.Id(y.first, y.second));
  }
  for (const Pole& p : poles) {
    const Extents& n = extents[p.block];
    const int64_t stride = p.d == 0 ? 1 : (p.d == 1 ? n[0] : int64_t{n[0]} * n[1]);
    ForEachPoleLine(p, grid.blocks[p.block], n, [&](const Extents& at) {
      const int64_t first = at[0] + int64_t{n[0]} * (at[1] + int64_t{n[1]} * at[2]);
      for (int a = 1; a < n[p.d]; ++a) {
        sets.Join(sets.Id(p.block, first), sets.Id(p.block, first + a * stride));
      }
    });
  }
  double largest = 0.0;
  for (int64_t id = 0; id < sets.size(); ++id) {
    const int64_t root = sets.Find(id);
    if (root == id) continue;
    const auto [b, c] = sets.Locate(id);
    const auto [rb, rc] = sets.Locate(root);
    const int s = blocks[b].spline.spatial_dim();
    double* dst = blocks[b].spline.mutable_control().data() + s * c;
    const double* src = blocks[rb].spline.control().data() + s * rc;
    for (int x = 0; x < s; ++x) {
      largest = std::max(largest, std::abs(dst[x] - src[x]));
      dst[x] = src[x];
    }
  }
  return largest;
}

// The grid lines along direction d of `block` (by their index with 0 in direction d) that hold
// at least three wall points: the lines whose shape the wall tolerance binds.
std::vector<Extents> LinesWithWall(const StructuredBlock& block, const std::vector<uint8_t>& kinds,
                                   int d) {
  std::vector<Extents> lines;
  const int m = block.extent(d);
  if (m < 3) return lines;
  const auto wall = static_cast<uint8_t>(BoundaryKind::kWall);
  const int e1 = d == 0 ? 1 : 0;
  const int e2 = d == 2 ? 1 : 2;
  for (int y = 0; y < block.extent(e2); ++y) {
    for (int x = 0; x < block.extent(e1); ++x) {
      Extents at{};
      at[e1] = x;
      at[e2] = y;
      int count = 0;
      for (int t = 0; t < m && count < 3; ++t) {
        at[d] = t;
        count += (kinds[block.Index(at[0], at[1], at[2])] & wall) ? 1 : 0;
      }
      at[d] = 0;
      if (count >= 3) lines.push_back(at);
    }
  }
  return lines;
}

// Parameters of every block: averaged over all grid lines of each direction, or (walls) over
// the lines that lie on walls where a direction has any. Sets *any_wall if some direction
// differs.
std::vector<std::array<std::vector<double>, 3>> BlockParameters(const MultiBlockGrid& grid,
                                                                const BoundaryKinds& kinds,
                                                                Parametrization parametrization,
                                                                bool walls, bool* any_wall) {
  std::vector<std::array<std::vector<double>, 3>> params;
  for (size_t b = 0; b < grid.blocks.size(); ++b) {
    params.push_back(ParametrizeBlock(grid.blocks[b], parametrization));
    if (!walls) continue;
    for (int d = 0; d < 3; ++d) {
      const std::vector<Extents> lines = LinesWithWall(grid.blocks[b], kinds.point_kinds[b], d);
      const int64_t all = grid.blocks[b].num_points() / grid.blocks[b].extent(d);
      if (lines.empty() || static_cast<int64_t>(lines.size()) == all) continue;
      params.back()[d] = ParametrizeLines(grid.blocks[b], d, lines, parametrization);
      *any_wall = true;
    }
  }
  return params;
}

// What every point of a block is fitted to, and where each direction may be cut.
struct PointTargets {
  std::vector<std::vector<double>> tolerances;       // per block, per point
  std::vector<std::vector<double>> edge_tolerances;  // per block, per point (refinement.h)
  std::vector<std::array<std::vector<int>, 3>> features;
};

// The point and edge tolerances of every block by `kinds`, and the feature points of every
// direction.
PointTargets TargetsAndFeatures(const MultiBlockGrid& grid, const BoundaryKinds& kinds,
                                const BoundaryTolerances& tolerances,
                                const FeatureOptions& features) {
  const int nb = static_cast<int>(grid.blocks.size());
  PointTargets targets;
  targets.tolerances.resize(nb);
  targets.edge_tolerances.resize(nb);
  targets.features.resize(nb);
  for (int b = 0; b < nb; ++b) {
    targets.tolerances[b] = PointTolerances(kinds, b, tolerances);
    targets.edge_tolerances[b] = PointEdgeTolerances(grid.blocks[b], kinds, b, tolerances);
    for (int d = 0; d < 3; ++d)
      targets.features[b][d] = DetectFeatures(grid.blocks[b], d, features);
  }
  return targets;
}

// No edge ratio (refinement.h) at the points of a pole: the edges along a collapsed line have
// no length to be relative to (within kPoleRelativeTolerance of 0, not always exactly 0, so a
// ratio of rounding noise would refine every class it touches down to interpolation), and
// the fit keeps them collapsed exactly (CollapsePoles). An edge ratio of 0 at one end switches
// the edge off, so the edges from the pole to the first ring go too; the ring's own points and
// edges still bind it.
void SwitchOffPoleEdges(const MultiBlockGrid& grid, const std::vector<Pole>& poles,
                        std::vector<std::vector<double>>& edge_tolerances) {
  const std::vector<std::vector<uint8_t>> on_pole = PointsOnPoles(grid, poles);
  for (size_t b = 0; b < on_pole.size(); ++b) {
    if (edge_tolerances[b].size() != on_pole[b].size()) continue;  // none, or one for all
    for (size_t p = 0; p < on_pole[b].size(); ++p) {
      if (on_pole[b][p]) edge_tolerances[b][p] = 0.0;
    }
  }
}

// The adaptive engine's settings, from `options` once; the quality check (when on) uses
// `quality`, which must outlive the engine's run.
EngineOptions EngineOptionsFor(const MultiBlockGrid& grid, const GridFitOptions& options,
                               const CellQualityOptions& quality) {
  EngineOptions engine;
  engine.max_iterations = options.max_iterations;
  engine.remove_unneeded_knots = options.remove_unneeded_knots;
  engine.fairing = options.fairing;
  engine.cancel = quality.cancel;
  if (options.check_quality) {
    // Each block's reference cells are built at its first check and kept for the later ones
    // (the engine checks a block again after every accepted change).
    auto references =
        std::make_shared<std::vector<std::optional<CellReference>>>(grid.blocks.size());
    engine.quality = [&grid, &quality, references](
                         int b, const FittedBlock& fitted) -> absl::StatusOr<CellQuality> {
      std::optional<CellReference>& reference = (*references)[b];
      if (!reference) {
        SG_ASSIGN_OR_RETURN(reference, CellReference::Build(grid.blocks[b]));
      }
      return CheckCellQuality(fitted, *reference, quality);
    };
  }
  return engine;
}

// Takes the blocks and counts of the engine's `run` into `result`, then makes them watertight:
// poles first (each line to its mean), then the shared controls and the pole lines made one
// value across blocks.
void TakeRun(EngineResult run, const MultiBlockGrid& grid, const SegmentModel& model,
             const Connectivity& shared, bool watertight, MultiBlockRun& result) {
  CollapsePoles(result.poles, grid, run.blocks);
  CollapsePoles(result.poles, grid, run.unfaired);
  if (watertight || !result.poles.empty()) {
    CopySharedControls(model, shared, result.poles, grid, run.blocks);
    if (!run.unfaired.empty()) CopySharedControls(model, shared, result.poles, grid, run.unfaired);
  }
  result.fit.blocks.clear();
  for (FittedBlock& fitted : run.blocks)
    result.fit.blocks.emplace_back().fitted = std::move(fitted);
  result.unfaired = std::move(run.unfaired);
  GridFitReport& report = result.fit.report;
  report.iterations = run.iterations;
  report.knots_inserted = run.knots_inserted;
  report.knots_removed = run.knots_removed;
  report.quality_rounds = run.quality_rounds;
  report.fairing_weight = run.fairing_weight;
}

// The fit with the given parameters; `result` holds the connectivity, kinds and poles already.
absl::Status FitWithParameters(const MultiBlockGrid& grid, const GridFitOptions& options,
                               const BoundaryTolerances& tolerances,
                               const CellQualityOptions& quality,
                               const std::vector<std::array<std::vector<double>, 3>>& params,
                               MultiBlockRun& result) {
  PointTargets targets = TargetsAndFeatures(grid, result.fit.kinds, tolerances, options.features);
  SwitchOffPoleEdges(grid, result.poles, targets.edge_tolerances);
  const Connectivity none;
  const Connectivity& shared = options.watertight ? result.fit.connectivity : none;
  SG_ASSIGN_OR_RETURN(SegmentModel model,
                      SegmentModel::Build(grid, params, shared, targets.features, options.order,
                                          options.max_controls_per_direction));
  SG_ASSIGN_OR_RETURN(EngineResult run,
                      RunAdaptiveFit(grid, model, targets.tolerances, targets.edge_tolerances,
                                     EngineOptionsFor(grid, options, quality)));
  TakeRun(std::move(run), grid, model, shared, options.watertight, result);
  return ReportFit(grid, quality, &tolerances, result.unfaired, result.fit);
}

// Whether fit a is better than b: tolerances met, then fewer bad cells, fewer folded
// sub-cells, then a smoother wall (smaller sum of squared curvature differences).
bool Better(const GridFit& a, const GridFit& b) {
  auto key = [](const GridFit& f) {
    int64_t bad = 0, folded = 0;
    for (const BlockFit& block : f.blocks) {
      bad += block.quality.num_bad_cells;
      folded += block.quality.folded;
    }
    return std::make_tuple(!f.report.tolerance_met, bad, folded,
                           f.report.wall_curvature.sum_squared_differences);
  };
  return key(a) < key(b);
}

// Whether some block of `grid` has a first-layer edge the fit holds under `kinds`
// (boundary_kinds.h ForEachHeldFirstLayerEdge).
bool HasFirstLayerEdgesOffPoles(const MultiBlockGrid& grid, const BoundaryKinds& kinds,
                                const std::vector<Pole>& poles) {
  const std::vector<std::vector<uint8_t>> on_pole = PointsOnPoles(grid, poles);
  bool any = false;
  for (size_t b = 0; b < grid.blocks.size() && !any; ++b) {
    ForEachHeldFirstLayerEdge(grid.blocks[b], kinds.point_kinds[b], on_pole[b],
                              [&any](int64_t, int64_t) { any = true; });
  }
  return any;
}

}  // namespace

absl::StatusOr<MultiBlockRun> FitMultiBlock(const MultiBlockGrid& grid,
                                            const Connectivity& connectivity,
                                            const BoundaryKinds& kinds,
                                            const GridFitOptions& options,
                                            const BoundaryTolerances& tolerances,
                                            const CancelCheck& cancel) {
  const auto start = std::chrono::steady_clock::now();
  CellQualityOptions quality = options.quality;
  quality.cancel = cancel;
  MultiBlockRun result;
  result.fit.connectivity = connectivity;
  result.fit.report.tolerances = tolerances;
  result.poles = FindPoles(grid, PoleTolerance(grid));
  // A first layer asked for on a grid without walls (or whose walls are all poles) would be met
  // by nothing, and the report would read as if it were held.
  if (tolerances.first_layer > 0.0 && !HasFirstLayerEdgesOffPoles(grid, kinds, result.poles)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "boundary_tolerances.first_layer = ", tolerances.first_layer,
        " holds nothing: no wall of the grid has a first layer off a pole (walls are the faces "
        "towards which the grid is clustered; name them by FitSpec.face_kinds, CLI --face "
        "0:jmin=wall)"));
  }
  result.fit.kinds = kinds;
  bool any_wall = false;
  const bool walls_first = options.wall_parameters != WallParametrization::kAverage;
  SG_RETURN_IF_ERROR(FitWithParameters(
      grid, options, tolerances, quality,
      BlockParameters(grid, result.fit.kinds, options.parametrization, walls_first, &any_wall),
      result));
  if (options.wall_parameters == WallParametrization::kAuto && any_wall) {
    MultiBlockRun averaged;
    averaged.fit.connectivity = result.fit.connectivity;
    averaged.fit.kinds = result.fit.kinds;
    averaged.fit.report.tolerances = tolerances;
    averaged.poles = result.poles;
    SG_RETURN_IF_ERROR(FitWithParameters(
        grid, options, tolerances, quality,
        BlockParameters(grid, result.fit.kinds, options.parametrization, false, &any_wall),
        averaged));
    if (Better(averaged.fit, result.fit)) result = std::move(averaged);
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (BlockFit& block : result.fit.blocks)
    block.fitted.summary.seconds = seconds / grid.blocks.size();
  return result;
}

}  // namespace splinegrid::internal
