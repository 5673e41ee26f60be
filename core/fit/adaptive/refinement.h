// Building blocks of knot refinement: where a direction's own line fits miss their tolerance,
// where grid lines have kinks, and how knot spans are split.
#ifndef SPLINEGRID_CORE_FIT_ADAPTIVE_REFINEMENT_H_
#define SPLINEGRID_CORE_FIT_ADAPTIVE_REFINEMENT_H_

#include <functional>
#include <span>
#include <vector>

#include "absl/status/statusor.h"
#include "core/bspline/knot_vector.h"
#include "core/fit/solve/direction_fit.h"
#include "core/grid/structured_grid.h"
#include "core/util/cancellation.h"

namespace splinegrid {

// How far an approximation F of the block's points X is from them, as ratios to what is
// allowed (1 = at the limit):
//  - at every point p: |F(p) - X(p)| / tolerance[p];
//  - on every grid edge (p, q) with |X(q) - X(p)| > 0: the error of the edge vector,
//    |(F(q) - F(p)) - (X(q) - X(p))| / (e |X(q) - X(p)|), e the looser of the two points'
//    edge tolerances (none if either is 0). This keeps the grid's spacing and shape where no
//    absolute tolerance binds (inside a block) without asking for absolute accuracy: an error
//    shared by neighbouring points costs nothing.
// `fitted` has the layout of block.coords(). `tolerance` and `edge_tolerance` have one value
// per point or a single one (tolerance infinity: no point tolerance; edge tolerance <= 0: no
// edge ratio); an empty edge_tolerance switches the edge ratios off.
struct ErrorAssessment {
  double max_ratio = 0.0;
  Extents max_at = {0, 0, 0};
  bool max_is_edge = false;  // the largest ratio is an edge's (else a point's)
};
// With `per_index_direction` >= 0, per_index receives for every index r of that direction the
// largest ratio of the points (and edges touching points) with that index.
ErrorAssessment AssessErrors(const StructuredBlock& block, const double* fitted,
                             std::span<const double> tolerance,
                             std::span<const double> edge_tolerance, int per_index_direction = -1,
                             std::vector<double>* per_index = nullptr);

// For every data index r of direction d of `block`: the largest ratio of AssessErrors for the
// approximation F = P_d X, where P_d fits each grid line of d alone with `knots` (interpolated
// ends, `pins`). Cost: one fit and one evaluation pass over the block.
absl::StatusOr<std::vector<double>> DirectionResidualRatio(
    const StructuredBlock& block, int d, const std::vector<double>& params, const KnotVector& knots,
    const std::vector<Pin>& pins, std::span<const double> tolerance,
    std::span<const double> edge_tolerance, const CancelCheck& cancel);

// Kink detection: a grid index r (0 < r < m - 1) of direction d is a feature point when some
// grid line of d on the block's boundary turns there by at least `angle_degrees` (and by
// `kink_ratio` times the turning at both neighbouring points of that line), or by at least
// `spike_degrees` and `spike_ratio` times the turning at both neighbours.
// Interior lines are not looked at: a feature makes every line of the direction C0 there, which
// only pays off for kinks of the boundary (a trailing edge, a corner of the far field). Two
// features next to each other leave no data between them: only the first is kept.
struct FeatureOptions {
  bool detect = true;
  double angle_degrees = 30.0;
  double spike_degrees = 4.0;
  double spike_ratio = 4.0;
  // 0: every turning of angle_degrees is a feature. 2 asks for a tangent discontinuity: a bend
  // sampled coarsely (a nose at 65 points turns by 45 degrees at two points in a row) turns by
  // about as much at the neighbours, a corner by far more.
  double kink_ratio = 0.0;

  // INVALID_ARGUMENT naming the field unless the angles are in [0, 180] and spike_ratio >= 1.
  absl::Status Validate() const;
};
std::vector<int> DetectFeatures(const StructuredBlock& block, int d, const FeatureOptions& options);

// Splits the knot spans of a direction (interior simple knots `knots` on [0, 1], data at the
// strictly increasing `params`) whose largest `ratio` (one per data point) exceeds `limit`, each
// at the middle of its data, worst span first. Only spans with at least two data points strictly
// inside are split, so each half keeps one. A split is kept only if `well_posed()` holds
// afterwards; at most `max_new` are kept. Returns the number of knots added.
// With `max_single_run` > 0, a split is also refused when it leaves more than that many knot
// spans in a row holding fewer than two data (SingleDatumRun).
int SplitSpans(const std::vector<double>& params, const std::vector<double>& ratio, double limit,
               int max_new, std::vector<double>& knots, const std::function<bool()>& well_posed,
               int max_single_run = 0);

// Runs of "single-datum" knot spans: spans of the interior knots `knots` on [0, 1] that hold
// fewer than two of the ascending data `params` (span [t_s, t_s+1), the last one closed).
//
// Why they matter: on a run of L such spans a spline of order k has L + k - 1 controls against
// L data, so k - 1 of its degrees of freedom are not fixed by the data there; only the spans
// holding two or more data at the ends of the run pin them. The splines that vanish at the
// run's data form a (k - 1)-dimensional family whose members are carried from span to span by a
// transfer matrix with eigenvalues of modulus near 1 (for cubics: an alternating mode of
// constant size besides a growing and a decaying one, cf. the cardinal spline eigenvalues
// -(2 +- sqrt 3) of de Boor, "A Practical Guide to Splines", ch. XIII). The least-squares problem
// stays solvable (Schoenberg-Whitney holds) but its smallest singular value falls with the run's
// length, and the fit picks up a large multiple of that mode: a spline that meets every datum to
// the tolerance and swings between them. At refinement levels 1 and 2 this is a checkerboard of
// folded sub-cells (measured: control points 1e9 away between data 500 apart on the NACA 0012
// C-grid at tolerance 5e-5, where 168 of 196 i-spans held one datum). Bounding the runs bounds
// the amplification; interpolation (one datum per span, no surplus at all) is the exception
// that is well posed on its own and has no surplus to pin with.
//
// The longest run.
int SingleDatumRun(const std::vector<double>& params, const std::vector<double>& knots);
// `knots` with knots removed so that no run is longer than `max_run` (>= 1): walking the spans,
// a single-datum span that would extend a run beyond max_run is merged with the span before it
// (its left knot removed), which gives a span of two data that pins the mode. Removes about one
// knot in max_run + 1 along a run, none elsewhere.
std::vector<double> BreakSingleDatumRuns(const std::vector<double>& params,
                                         const std::vector<double>& knots, int max_run);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_ADAPTIVE_REFINEMENT_H_
