// The curvature judgement of a fitted airfoil profile (airfoil_fit.h, file comment): where the
// curvature of a fit peaks, how many extrema it has per piece, and how many of them the data do
// not ask for. Internal to the airfoil fit.
//
// Curvature is judged per piece: the curve is cut at the anchors (the trailing edge and the
// feature points) and at the nose (the sample of largest |kappa| within two data intervals of
// the leading-edge point), so a profile without features has an upper and a lower surface. Each
// piece is sampled at 2^level points per data interval, with the signed curvature
//   kappa = (x' y'' - y' x'') / |C'|^3;
// extrema are interior samples where kappa turns (wall_curvature.h, AccumulateCurvature).
// An extremum is spurious when the data do not ask for it. The reference is the fairest curve
// within the same tolerance that the kernel builds, a smoothing spline with a knot at every
// second data point faired to tolerance (C. H. Reinsch, "Smoothing by spline functions", Numer.
// Math. 10, 1967; P. Dierckx, "Curve and Surface Fitting with Splines", 1993, ch. 5), whose
// significant extrema are counted with a persistence of 10%: an extremum counts once the
// curvature has moved away from it by more than 10% of the larger magnitude (so the dense
// spline's ripples between knots do not count, and a swing through zero always does). Per
// piece, spurious = max(0, extrema - reference significant extrema).
// Cost: O(k^2) per sample, 2^level samples per data interval.
#ifndef SPLINEGRID_CORE_FIT_AIRFOIL_PROFILE_CURVATURE_H_
#define SPLINEGRID_CORE_FIT_AIRFOIL_PROFILE_CURVATURE_H_

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "core/fit/airfoil/airfoil_fit.h"
#include "core/fit/airfoil/profile_fitter.h"
#include "core/fit/report/wall_curvature.h"

namespace splinegrid {

// Sample parameters of a piece with data parameters `params` (at least two): 2^level per data
// interval and the end, kOneSidedOffset (1e-12) inside when the piece ends at a feature knot, so
// its last sample has the piece's own one-sided derivatives.
std::vector<double> PieceSamples(std::span<const double> params, int level, bool one_sided_end);

// The curvature samples of `curve` at `u` (ascending): points, signed curvature and the chord
// sum of the samples as arc length.
std::vector<CurvatureSample> SampleCurvature(const Curve& curve, std::span<const double> u);

// The largest |curvature| of `fitted` over its samples (every piece between `anchors` at
// `level`) and the parameter where it is; {0, 0} for a straight curve.
std::pair<double, double> CurvaturePeak(const Fitted& fitted, const std::vector<int>& anchors,
                                        int level);

// The interior extrema of the curvature along `samples` (not empty) that stand out by more than
// kSignificantSwing (10%): a zigzag with hysteresis (the persistence of an extremum), where a
// maximum or minimum counts once the curvature has moved away from it by more than
// kSignificantSwing max(|extremum|, |curvature|). Ripples of a dense spline between its knots
// (a few per cent) do not count; a swing through zero (an inflection) always does.
int64_t SignificantExtrema(std::span<const CurvatureSample> samples);

// The curvature of `fitted` per piece: cut at the anchors and at the nose (the sample of
// largest |kappa| within kNoseWindow (2) data intervals of `leading_edge`), sampled at `level`.
// Fills everything but the spurious extrema (CountSpurious).
ProfileCurvature MeasureCurvature(const Fitted& fitted, const std::vector<int>& anchors,
                                  int leading_edge, int level);

// Spurious extrema of `c`: piece by piece, the extrema beyond the reference's significant ones
// (all of them without a reference). `reference` may be `c` itself.
void CountSpurious(const ProfileCurvature& reference, ProfileCurvature& c);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_FIT_AIRFOIL_PROFILE_CURVATURE_H_
