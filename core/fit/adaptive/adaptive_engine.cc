#include "core/fit/adaptive/adaptive_engine.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <tuple>

#include "core/bspline/evaluation.h"
#include "core/fit/adaptive/refinement.h"
#include "core/util/status_macros.h"

namespace splinegrid::internal {
namespace {

// Quality of a set of blocks, ordered: fewer bad original cells first, then fewer folded
// (sub-)cells. (Folds first was tried for issue 13.3 and measured worse: the NACA 4412 O-grid
// at tolerance 1e-5 ended with 656 folded sub-cells instead of none.)
struct QualityScore {
  int64_t bad = 0;
  int64_t folded = 0;
  // The smallest Jacobian ratio (grid_quality.h); not part of the order.
  double min_ratio = std::numeric_limits<double>::infinity();
  // A repair's criterion: fewer folds, and the worst cell no worse (a fold count can drop
  // while the swing between the data grows).
  bool RepairedFrom(const QualityScore& before) const {
    return folded < before.folded && (folded == 0 || min_ratio >= before.min_ratio);
  }
  bool ok() const { return folded == 0 && bad == 0; }
  friend bool operator<(const QualityScore& a, const QualityScore& b) {
    return std::tie(a.bad, a.folded) < std::tie(b.bad, b.folded);
  }
  friend bool operator<=(const QualityScore& a, const QualityScore& b) { return !(b < a); }
};

// The fraction of the tolerances the knots are placed for when the fit is faired to tolerance.
constexpr double kFairingHeadroom = 0.5;

// The edge tolerance a quality round gives vertices of bad cells whose edges were not checked.
constexpr double kLocalEdgeTolerance = 0.5;

class Engine {
 public:
  Engine(const MultiBlockGrid& grid, SegmentModel& model,
         std::vector<std::vector<double>>& tolerances,
         std::vector<std::vector<double>>& edge_tolerances, const EngineOptions& options)
      : grid_(grid),
        model_(model),
        tolerances_(tolerances),
        edge_tolerances_(edge_tolerances),
        options_(options) {
    const int nb = static_cast<int>(grid.blocks.size());
    fits_.resize(nb);
    devs_.resize(nb);
    quality_.resize(nb);
    all_.resize(nb);
    for (int b = 0; b < nb; ++b) all_[b] = b;
    // Each class's share of the tolerance: 1 / the most active directions among its blocks.
    shares_.resize(model.num_classes());
    for (int c = 0; c < model.num_classes(); ++c) {
      int active = 1;
      for (const auto& mem : model.segment_class(c).members) {
        active = std::max(active, ActiveDirections(grid.blocks[mem.block].extents()));
      }
      shares_[c] = 1.0 / active;
    }
    if (options.fairing.mode == FairingMode::kWeight) lambda_ = options.fairing.weight;
    edge_tolerances_.resize(nb);
    for (int b = 0; b < nb; ++b) {
      if (edge_tolerances_[b].empty()) edge_tolerances_[b].assign(grid.blocks[b].num_points(), 0.0);
    }
  }

  absl::StatusOr<EngineResult> Run() {
    EngineResult result;
    // Fairing to tolerance needs room: the knots are placed for a fraction of the tolerances,
    // and the fairing may use the rest.
    const bool fair = options_.fairing.mode == FairingMode::kToTolerance;
    if (fair) ScaleTolerances(kFairingHeadroom);
    SG_RETURN_IF_ERROR(FitBlocks(all_));
    SG_RETURN_IF_ERROR(Refine(result));
    if (options_.quality && Met()) SG_RETURN_IF_ERROR(ImproveQuality(result));
    if (options_.quality && Met()) SG_RETURN_IF_ERROR(RepairFolds(result));
    if (options_.remove_unneeded_knots && Met()) {
      SG_ASSIGN_OR_RETURN(result.knots_removed, RemoveKnots());
    }
    if (options_.quality && Met()) {
      const int repairs = result.repair_rounds;
      SG_RETURN_IF_ERROR(RepairRemainingFolds(result));
      // The repairs refine again; what they added beyond need goes as in step 3.
      if (options_.remove_unneeded_knots && result.repair_rounds > repairs && Met()) {
        SG_ASSIGN_OR_RETURN(const int removed, RemoveKnots());
        result.knots_removed += removed;
      }
    }
    if (fair) {
      const bool met = Met();
      ScaleTolerances(1.0 / kFairingHeadroom);
      SG_RETURN_IF_ERROR(FitBlocks(all_));
      if (met) {
        for (int b : all_) result.unfaired.push_back(Fitted(b));
        SG_RETURN_IF_ERROR(FairToTolerance());
      }
    }
    result.met = Met();
    result.fairing_weight = lambda_;
    if (options_.quality) {
      SG_ASSIGN_OR_RETURN(const QualityScore score, Score(all_));
      result.quality_met = score.ok();
    }
    for (int b : all_) {
      if (devs_[b].max_ratio >= result.worst_ratio) {
        result.worst_ratio = devs_[b].max_ratio;
        result.worst_block = b;
        result.worst_at = devs_[b].max_ratio_at;
      }
      result.blocks.push_back(Fitted(b));
      if (options_.quality) result.quality.push_back(*quality_[b]);
    }
    return result;
  }

 private:
  // Everything a step may have to undo.
  struct State {
    std::vector<std::vector<double>> class_knots;
    std::vector<std::vector<double>> tolerances;
    std::vector<std::vector<double>> edge_tolerances;
    std::vector<TensorSpline> fits;
    std::vector<Deviation> devs;
    std::vector<std::optional<CellQuality>> quality;
  };
  State Save() const {
    State s{{}, tolerances_, edge_tolerances_, fits_, devs_, quality_};
    for (int c = 0; c < model_.num_classes(); ++c)
      s.class_knots.push_back(model_.segment_class(c).knots);
    return s;
  }
  void Load(const State& s) {
    for (int c = 0; c < model_.num_classes(); ++c) model_.mutable_class(c).knots = s.class_knots[c];
    tolerances_ = s.tolerances;
    edge_tolerances_ = s.edge_tolerances;
    fits_ = s.fits;
    devs_ = s.devs;
    quality_ = s.quality;
  }

  // The fits of some blocks (knot removal changes nothing else).
  struct BlockState {
    std::vector<TensorSpline> fits;
    std::vector<Deviation> devs;
    std::vector<std::optional<CellQuality>> quality;
  };
  BlockState SaveBlocks(const std::vector<int>& blocks) const {
    BlockState s;
    for (int b : blocks) {
      s.fits.push_back(fits_[b]);
      s.devs.push_back(devs_[b]);
      s.quality.push_back(quality_[b]);
    }
    return s;
  }
  void LoadBlocks(const std::vector<int>& blocks, const BlockState& s) {
    for (size_t i = 0; i < blocks.size(); ++i) {
      fits_[blocks[i]] = s.fits[i];
      devs_[blocks[i]] = s.devs[i];
      quality_[blocks[i]] = s.quality[i];
    }
  }

  void ScaleTolerances(double factor) {
    for (std::vector<double>& t : tolerances_) {
      for (double& x : t) x *= factor;
    }
    for (std::vector<double>& t : edge_tolerances_) {
      for (double& x : t) x *= factor;
    }
  }

  bool EdgesOn(int b) const {
    const std::vector<double>& e = edge_tolerances_[b];
    return std::any_of(e.begin(), e.end(), [](double x) { return x > 0.0; });
  }
  std::span<const double> EdgeTolerances(int b) const {
    if (!EdgesOn(b)) return {};
    return edge_tolerances_[b];
  }

  double WorstRatio(const std::vector<int>& blocks) const {
    double worst = 0.0;
    for (int b : blocks) worst = std::max(worst, devs_[b].max_ratio);
    return worst;
  }
  bool Met() const { return WorstRatio(all_) <= 1.0; }

  // The quality of `blocks`, checking the fits not checked yet (the check evaluates every cell
  // at levels 0..2, so it waits until a step needs it: most trial fits fail their tolerances).
  absl::StatusOr<QualityScore> Score(const std::vector<int>& blocks) {
    QualityScore s;
    for (int b : blocks) {
      if (!quality_[b]) {
        SG_ASSIGN_OR_RETURN(quality_[b], options_.quality(b, Fitted(b)));
      }
      s.bad += quality_[b]->num_bad_cells;
      s.folded += quality_[b]->folded;
      s.min_ratio = std::min(s.min_ratio, quality_[b]->min_ratio);
    }
    return s;
  }

  FittedBlock Fitted(int b) const {
    std::array<std::vector<double>, 3> params;
    std::array<std::vector<int>, 3> breaks;
    for (int d = 0; d < 3; ++d) {
      params[d] = model_.params(b, d);
      breaks[d] = model_.splits(b, d);
    }
    FittedBlock fitted{fits_[b], PointDistribution::Create(params, breaks).value(), {}};
    fitted.summary.deviation = devs_[b];
    fitted.summary.num_points = grid_.blocks[b].num_points();
    fitted.summary.num_control_points = fits_[b].num_control_points();
    fitted.summary.compression_ratio =
        static_cast<double>(fitted.summary.num_points) / fitted.summary.num_control_points;
    return fitted;
  }

  // Fits block b with the current knots and weight and measures its deviation.
  absl::Status FitBlock(int b) {
    std::array<std::vector<double>, 3> params;
    std::array<KnotVector, 3> knots;
    DirectionPins pins;
    for (int d = 0; d < 3; ++d) {
      params[d] = model_.params(b, d);
      SG_ASSIGN_OR_RETURN(auto kp, model_.DirectionKnots(b, d));
      knots[d] = std::move(kp.first);
      pins[d] = std::move(kp.second);
    }
    SG_ASSIGN_OR_RETURN(fits_[b],
                        FitTensor(grid_.blocks[b], params, knots, EndCondition::kInterpolate,
                                  options_.cancel, pins, lambda_));
    SG_ASSIGN_OR_RETURN(devs_[b], MeasureDeviation(fits_[b], params, grid_.blocks[b],
                                                   options_.cancel, tolerances_[b]));
    if (EdgesOn(b)) {
      const StructuredBlock fitted = EvaluateGrid(fits_[b], params);
      const ErrorAssessment a = AssessErrors(grid_.blocks[b], fitted.coords().data(),
                                             tolerances_[b], edge_tolerances_[b]);
      devs_[b].max_ratio = a.max_ratio;
      devs_[b].max_ratio_at = a.max_at;
    }
    quality_[b].reset();
    return absl::OkStatus();
  }

  absl::Status FitBlocks(const std::vector<int>& blocks) {
    for (int b : blocks) SG_RETURN_IF_ERROR(FitBlock(b));
    return absl::OkStatus();
  }

  // Step 1: knot insertion until every point is within its tolerance (or no room is left).
  absl::Status Refine(EngineResult& result) {
    for (int round = 0; !Met() && round < options_.max_iterations; ++round, ++result.iterations) {
      SG_RETURN_IF_ERROR(PollCancel(options_.cancel));
      SG_ASSIGN_OR_RETURN(const int added, RefineOnce());
      if (added < 0) break;  // no room anywhere
      if (added == 0) continue;
      result.knots_inserted += added;
      SG_RETURN_IF_ERROR(FitBlocks(all_));
    }
    return absl::OkStatus();
  }

  // One refinement round; the number of knots added, or -1 if no class has room.
  absl::StatusOr<int> RefineOnce() {
    std::map<std::pair<int, int>, std::vector<double>> residuals;  // (block, dir) -> ratio
    int added = 0;
    bool any_room = false;
    for (int c = 0; c < model_.num_classes(); ++c) {
      SegmentModel::Class& cls = model_.mutable_class(c);
      // A class knot adds a control to every member: a direction holding several segments of
      // the class (the two wake segments of a C-grid) gains several per knot.
      std::map<std::pair<int, int>, int> per_direction;
      for (const auto& mem : cls.members) ++per_direction[{mem.block, mem.dir}];
      int room = std::numeric_limits<int>::max();
      for (const auto& [key, count] : per_direction) {
        const auto [b, d] = key;
        room = std::min(room, (model_.cap(b, d) - model_.Controls(b, d)) / count);
      }
      if (room <= 0) continue;
      any_room = true;
      // The members' line-fit residual ratios, in class coordinates.
      std::vector<double> ratio(cls.length + 1, 0.0);
      for (const auto& mem : cls.members) {
        const auto key = std::make_pair(mem.block, mem.dir);
        if (!residuals.count(key)) {
          SG_ASSIGN_OR_RETURN(auto kp, model_.DirectionKnots(mem.block, mem.dir));
          SG_ASSIGN_OR_RETURN(residuals[key],
                              DirectionResidualRatio(grid_.blocks[mem.block], mem.dir,
                                                     model_.params(mem.block, mem.dir), kp.first,
                                                     kp.second, tolerances_[mem.block],
                                                     EdgeTolerances(mem.block), options_.cancel));
        }
        const std::vector<double>& res = residuals[key];
        for (int r = mem.r0; r <= mem.r1; ++r) {
          double& x = ratio[mem.ClassCoord(r)];
          x = std::max(x, res[r]);
        }
      }
      added += SplitSpans(
          cls.params, ratio, shares_[c], room, cls.knots, [&] { return model_.WellPosed(c); },
          max_single_run_);
      if (interpolate_with_averaged_knots_) UseInterpolationKnots(c);
    }
    if (!any_room) return -1;
    if (added == 0) {
      bool all_tiny = true;
      for (double& share : shares_) {
        share *= 0.6;
        all_tiny &= share < 1e-6;
      }
      if (all_tiny) return -1;
    }
    return added;
  }

  // Knot averaging for class c if it has a control per datum (step 3b).
  void UseInterpolationKnots(int c) {
    SegmentModel::Class& cls = model_.mutable_class(c);
    const SegmentModel::Member& first = cls.members.front();
    const int order = model_.order(first.block, first.dir);
    const int interior = cls.length + 1 - order;
    if (interior <= 0 || static_cast<int>(cls.knots.size()) < interior) return;
    const absl::StatusOr<KnotVector> averaged =
        KnotVector::Averaged(order, cls.length + 1, cls.params);
    if (!averaged.ok()) return;
    const std::span<const double> all = averaged->knots();
    std::vector<double> knots(all.begin() + order, all.end() - order);
    std::swap(cls.knots, knots);
    if (!model_.WellPosed(c)) std::swap(cls.knots, knots);
  }

  // Step 2: rounds of local refinement; the best state is kept, and the rounds stop after
  // max_quality_rounds or two rounds in a row that do not improve on it.
  absl::Status ImproveQuality(EngineResult& result) {
    State best = Save();
    SG_ASSIGN_OR_RETURN(QualityScore best_score, Score(all_));
    int futile = 0;
    while (!best_score.ok() && futile < 2 && result.quality_rounds < options_.max_quality_rounds) {
      SG_RETURN_IF_ERROR(PollCancel(options_.cancel));
      ++result.quality_rounds;
      TightenAroundBadCells();
      SG_RETURN_IF_ERROR(FitBlocks(all_));
      SG_RETURN_IF_ERROR(Refine(result));
      if (!Met()) break;
      SG_ASSIGN_OR_RETURN(const QualityScore score, Score(all_));
      if (score < best_score) {
        best = Save();
        best_score = score;
        futile = 0;
      } else {
        ++futile;
      }
    }
    Load(best);
    return absl::OkStatus();
  }

  // Step 2b: a repair of the folds that remain, tried on the whole fit and kept only if it
  // helps (TryRepair), run only while folds remain.
  absl::Status RepairFolds(EngineResult& result) {
    SG_ASSIGN_OR_RETURN(QualityScore score, Score(all_));
    // Fewer knots where more made it worse. A fit that meets a tight tolerance with nearly
    // a control point per datum has long runs of knot spans that hold one datum each; on such a
    // run the data leave k - 1 degrees of freedom of the spline to the far ends, the
    // least-squares problem is nearly singular, and the fit swings between its data
    // (SingleDatumRun in refinement.h has the math). Step 2 adds knots and makes it worse. This
    // bounds the runs in every class that has a member in a block with folds: it removes about
    // one knot in R + 1 along each run longer than R (BreakSingleDatumRuns: two data in the
    // merged span pin the mode), and refines again with splits that keep the bound
    // (SplitSpans' max_single_run); R = 4, then 2, then 1.
    for (const int run : {4, 2, 1}) {
      SG_RETURN_IF_ERROR(TryRepair(result, score, [&] {
        int removed = 0;
        for (int c = 0; c < model_.num_classes(); ++c) {
          SegmentModel::Class& cls = model_.mutable_class(c);
          if (!HasFolds(cls)) continue;
          std::vector<double> knots = BreakSingleDatumRuns(cls.params, cls.knots, run);
          if (knots.size() == cls.knots.size()) continue;
          std::swap(cls.knots, knots);
          if (model_.WellPosed(c)) {
            removed += static_cast<int>(knots.size() - cls.knots.size());
          } else {
            std::swap(cls.knots, knots);
          }
        }
        max_single_run_ = run;
        result.knots_removed += removed;
        return removed > 0;
      }));
    }
    return absl::OkStatus();
  }

  // Step 3b: repairs of the folds that knot removal left, which change every fit they touch
  // (so only where folds remain: the fits steps 1-3 complete keep their knots).
  absl::Status RepairRemainingFolds(EngineResult& result) {
    SG_ASSIGN_OR_RETURN(QualityScore score, Score(all_));
    // (i) A class that refinement took to a control per datum interpolates with its split knots
    // midway between data, which for even orders is the nearly singular placement (de Boor, "A
    // Practical Guide to Splines", ch. XIII: the interpolant swings between its data). Knot
    // averaging (P&T eq. 9.8) is the well-posed placement; from here on such classes take it.
    // (Not the default: on fits without folds the split knots compress better, e.g. the NACA
    // 0012 225 x 65 by kinds 6.5x instead of 3.5x.)
    SG_RETURN_IF_ERROR(TryRepair(result, score, [&] {
      interpolate_with_averaged_knots_ = true;
      for (int c = 0; c < model_.num_classes(); ++c) UseInterpolationKnots(c);
      return true;
    }));
    // (ii) A jump penalty far too weak to move a fit the data determine (fairing.h; lambda
    // 1e-12 .. 1e-6 of the squared residuals) removes the swing they leave free: on a run of
    // single-datum spans the free mode alternates from span to span, so its (k - 1)-th
    // derivative jumps are its largest feature. Not with a fairing the caller chose; the fit
    // reports the weight (fairing_weight).
    if (options_.fairing.mode == FairingMode::kOff) {
      for (const double lambda : {1e-12, 1e-10, 1e-8, 1e-6}) {
        SG_RETURN_IF_ERROR(TryRepair(result, score, [&] {
          lambda_ = lambda;
          return true;
        }));
      }
    }
    return absl::OkStatus();
  }

  // While `score` has folds: applies `change` (false: nothing changed), refits, refines to the
  // tolerances and keeps the outcome only if every tolerance holds and the folds decrease
  // (QualityScore::RepairedFrom, which then becomes `score`); otherwise everything the change
  // and the refinement touched is restored. Each try is bounded by max_iterations rounds.
  absl::Status TryRepair(EngineResult& result, QualityScore& score,
                         const std::function<bool()>& change) {
    if (score.folded == 0) return absl::OkStatus();
    SG_RETURN_IF_ERROR(PollCancel(options_.cancel));
    const State saved = Save();
    const EngineResult saved_counts = result;
    const int saved_run = max_single_run_;
    const bool saved_averaging = interpolate_with_averaged_knots_;
    const double saved_lambda = lambda_;
    bool keep = false;
    if (change()) {
      if (const absl::Status fit = FitBlocks(all_); fit.ok()) {
        SG_RETURN_IF_ERROR(Refine(result));
        if (Met()) {
          SG_ASSIGN_OR_RETURN(const QualityScore after, Score(all_));
          keep = after.RepairedFrom(score);
          if (keep) score = after;
        }
      } else if (fit.code() == absl::StatusCode::kCancelled) {
        return fit;
      }
    }
    if (keep) {
      ++result.repair_rounds;
    } else {
      Load(saved);
      result = saved_counts;
      max_single_run_ = saved_run;
      interpolate_with_averaged_knots_ = saved_averaging;
      lambda_ = saved_lambda;
    }
    return absl::OkStatus();
  }

  // Whether a member of `cls` lies in a block whose last quality check found folds.
  bool HasFolds(const SegmentModel::Class& cls) const {
    return std::any_of(cls.members.begin(), cls.members.end(), [&](const auto& mem) {
      return quality_[mem.block] && quality_[mem.block]->folded > 0;
    });
  }

  // Refines locally around every rejected cell: halves the point tolerance (if bounded) and the
  // edge tolerance of its vertices; where edges were not checked, they are from now on, to
  // kLocalEdgeTolerance.
  void TightenAroundBadCells() {
    for (int b : all_) {
      const StructuredBlock& block = grid_.blocks[b];
      for (const Extents& cell : quality_[b]->bad_cells) {
        for (int dk = 0; dk <= (block.extent(2) > 1 ? 1 : 0); ++dk) {
          for (int dj = 0; dj <= (block.extent(1) > 1 ? 1 : 0); ++dj) {
            for (int di = 0; di <= (block.extent(0) > 1 ? 1 : 0); ++di) {
              const int64_t p = block.Index(std::min(cell[0] + di, block.extent(0) - 1),
                                            std::min(cell[1] + dj, block.extent(1) - 1),
                                            std::min(cell[2] + dk, block.extent(2) - 1));
              tolerances_[b][p] *= 0.5;
              double& e = edge_tolerances_[b][p];
              e = e > 0.0 ? 0.5 * e : kLocalEdgeTolerance;
            }
          }
        }
      }
    }
  }

  // Whether `blocks` meet their tolerances and are no worse in quality than `before` (the
  // quality is only checked when the tolerances hold).
  absl::StatusOr<bool> Acceptable(const std::vector<int>& blocks, const QualityScore& before) {
    if (WorstRatio(blocks) > 1.0) return false;
    if (!options_.quality) return true;
    SG_ASSIGN_OR_RETURN(const QualityScore score, Score(blocks));
    return score <= before;
  }

  // The quality score of `blocks`, or a zero score without a quality check.
  absl::StatusOr<QualityScore> ScoreIfChecked(const std::vector<int>& blocks) {
    if (!options_.quality) return QualityScore{};
    return Score(blocks);
  }

  // Step 3: tries each class knot; keeps a removal when every affected block still meets its
  // tolerances and its quality is no worse.
  absl::StatusOr<int> RemoveKnots() {
    int removed = 0;
    for (int c = 0; c < model_.num_classes(); ++c) {
      SegmentModel::Class& cls = model_.mutable_class(c);
      std::set<int> affected;
      for (const auto& mem : cls.members) affected.insert(mem.block);
      const std::vector<int> blocks(affected.begin(), affected.end());
      for (size_t i = 0; i < cls.knots.size();) {
        SG_RETURN_IF_ERROR(PollCancel(options_.cancel));
        const double knot = cls.knots[i];
        SG_ASSIGN_OR_RETURN(const QualityScore before, ScoreIfChecked(blocks));
        const BlockState saved = SaveBlocks(blocks);
        cls.knots.erase(cls.knots.begin() + i);
        bool keep = model_.WellPosed(c);
        if (keep) {
          const absl::Status fit = FitBlocks(blocks);
          if (fit.code() == absl::StatusCode::kCancelled) return fit;
          if (fit.ok()) {
            SG_ASSIGN_OR_RETURN(keep, Acceptable(blocks, before));
          } else {
            keep = false;
          }
        }
        if (keep) {
          ++removed;
        } else {
          LoadBlocks(blocks, saved);
          cls.knots.insert(cls.knots.begin() + i, knot);
          ++i;
        }
      }
    }
    return removed;
  }

  // Step 4: the largest lambda <= options.fairing.weight whose fits stay acceptable: decades
  // downwards from the weight to 1e-14 of it, then four bisections of the last decade on a log
  // scale (a factor 10^(1/16) = 1.15).
  absl::Status FairToTolerance() {
    SG_ASSIGN_OR_RETURN(const QualityScore before, ScoreIfChecked(all_));
    const State unfaired = Save();
    auto acceptable_at = [&](double lambda) -> absl::StatusOr<bool> {
      lambda_ = lambda;
      const absl::Status fit = FitBlocks(all_);
      if (fit.code() == absl::StatusCode::kCancelled) return fit;
      if (!fit.ok()) return false;
      return Acceptable(all_, before);
    };
    double good = 0.0, bad = 0.0;
    for (int e = 0; e <= 14; ++e) {
      const double lambda = options_.fairing.weight * std::pow(10.0, -e);
      SG_ASSIGN_OR_RETURN(const bool ok, acceptable_at(lambda));
      if (ok) {
        good = lambda;
        break;
      }
      bad = lambda;
    }
    if (good > 0.0 && bad > 0.0) {
      for (int step = 0; step < 4; ++step) {
        const double mid = std::sqrt(good * bad);
        SG_ASSIGN_OR_RETURN(const bool ok, acceptable_at(mid));
        (ok ? good : bad) = mid;
      }
    }
    if (good == 0.0) {
      Load(unfaired);
      lambda_ = 0.0;
      return absl::OkStatus();
    }
    lambda_ = good;
    return FitBlocks(all_);
  }

  const MultiBlockGrid& grid_;
  SegmentModel& model_;
  std::vector<std::vector<double>>& tolerances_;
  std::vector<std::vector<double>>& edge_tolerances_;  // per block, per point; 0: off
  const EngineOptions& options_;
  std::vector<int> all_;
  std::vector<TensorSpline> fits_;
  std::vector<Deviation> devs_;
  std::vector<std::optional<CellQuality>> quality_;  // unset: not checked since the fit
  std::vector<double> shares_;
  double lambda_ = 0.0;
  // Refinement keeps runs of single-datum spans within this (0: unbounded); set by RepairFolds.
  int max_single_run_ = 0;
  // Refinement gives a class that reaches a control per datum averaged knots (step 3b).
  bool interpolate_with_averaged_knots_ = false;
};

}  // namespace

absl::StatusOr<EngineResult> RunAdaptiveFit(const MultiBlockGrid& grid, SegmentModel& model,
                                            std::vector<std::vector<double>>& tolerances,
                                            std::vector<std::vector<double>>& edge_tolerances,
                                            const EngineOptions& options) {
  Engine engine(grid, model, tolerances, edge_tolerances, options);
  return engine.Run();
}

}  // namespace splinegrid::internal
