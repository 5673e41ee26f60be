// A grid around a profile, from its coordinates: the tool chain of issue 6 in one call.
//
//   1. the outline is fitted and faired (airfoil_fit.h): the profile spline, its trailing-edge
//      corner (sharp) or base corners (blunt) kept as feature points;
//   2. the wall loop is distributed along it by curvature and corners (wall_loop.h);
//   3. the layers are built outward from the wall loop, either
//      - kOffsets: marched by curvature-controlled offsets, each refitted and faired
//        (offset_march.h), or
//      - kTransfinite: interpolated between the wall and a circle `distance` out, the lines
//        optionally bent to leave the wall orthogonally (transfinite.h); past a cove the lines
//        would cross, and they start from an offset layer instead (cove_completion.h);
//      - kElliptic: that grid to an evenly spaced circle, smoothed by the elliptic equations
//        coarse to fine above the boundary layer and the offset layers (elliptic.h);
//   4. the result is measured (MeasureOGrid).
// The grid is an O-grid, i along the loop (clockwise, the first line repeated as the last: the
// seam leaves the trailing edge), j outward from the wall, every cell's signed area positive.
#ifndef SPLINEGRID_CORE_GENERATE_PROFILE_GRID_H_
#define SPLINEGRID_CORE_GENERATE_PROFILE_GRID_H_

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/fit/airfoil/airfoil_fit.h"
#include "core/generate/cove_completion.h"
#include "core/generate/transfinite.h"
#include "core/generate/wall_loop.h"
#include "core/grid/structured_grid.h"
#include "core/util/cancellation.h"

namespace splinegrid {

enum class LayerMethod {
  kOffsets,      // curvature-controlled offset curves (default)
  kTransfinite,  // transfinite interpolation between the wall and an outer circle
  kElliptic,     // transfinite, then elliptic smoothing coarse to fine
};

// "offsets", "transfinite" or "elliptic".
std::string_view LayerMethodName(LayerMethod method);

// The most points a generated grid may have (2^24: 256 MiB of coordinates).
inline constexpr int64_t kMaxProfileGridPoints = int64_t{1} << 24;

// The defaults of a profile's grid that are lengths, as fractions of its chord (ProfileChord),
// so that a file in millimetres gets the grid a file in chords gets, scaled: the fit tolerance,
// the first layer's height and the outer boundary's distance from the wall.
inline constexpr double kDefaultProfileFitTolerance = 1e-4;
inline constexpr double kDefaultFirstHeight = 1e-5;
inline constexpr double kDefaultFarDistance = 50.0;

// The lengths of the completion and of elliptic smoothing, as fractions of the profile's chord
// (so that a profile in millimetres gets the grid it gets in chords, scaled): how far the
// orthogonalised lines bend (CompletionOptions::orthogonal_reach) and how thick the boundary
// layer is that elliptic smoothing holds as the algebraic grid has it (elliptic.h LayersWithin).
inline constexpr double kOrthogonalReach = 0.2;
inline constexpr double kHeldBoundaryLayer = 0.01;

// The layers of `algebraic` (the layer stack `completion`, around a profile of chord `chord`)
// that elliptic smoothing holds: the boundary layer within kHeldBoundaryLayer chords of the
// wall, and the offset layers the grid starts from.
int HeldLayers(const CompletionOptions& completion, const AlgebraicGrid& algebraic, double chord);

// The chord of an outline in Selig order (n x 1 x 1, spatial_dim 2): the largest distance of a
// point from the first, the trailing edge. O(n).
double ProfileChord(const StructuredBlock& coordinates);

struct ProfileGridOptions {
  LayerMethod method = LayerMethod::kOffsets;
  int wall_points = 257;  // points around the loop, the first repeated as the last, >= 9
  int layers = 128;       // cells across, >= 1 (the grid has layers + 1 lines)
  // Of the first layer and of the outermost layer from the wall, in the profile's unit; unset:
  // kDefaultFirstHeight and kDefaultFarDistance of the profile's chord.
  std::optional<double> first_height;
  std::optional<double> distance;
  bool orthogonalize = true;  // kTransfinite, kElliptic: lines leave the wall along its normals
  // Of the profile spline to the coordinates (AirfoilFitOptions), in their unit; unset:
  // kDefaultProfileFitTolerance of the profile's chord (ProfileChord), so that a file in
  // millimetres is fitted as one in chords.
  std::optional<double> fit_tolerance;
  CancelCheck cancel;

  // INVALID_ARGUMENT naming the field and its value (kElliptic: wall_points odd, layers even).
  absl::Status Validate() const;
};

// What a generated O-grid measures (MeasureOGrid).
struct OGridQuality {
  int64_t negative_cells = 0;   // cells whose signed area is <= 0
  double min_cell_area = 0.0;   // smallest signed cell area
  double first_height_min = 0;  // |X(i, 1) - X(i, 0)| over the wall points
  double first_height_max = 0;
  // Largest deviation from 90 degrees of the angle between the first grid line and the wall,
  // over the wall points that are not corners (a corner has no tangent).
  double wall_orthogonality_degrees = 0.0;
  double outer_distance_min = 0.0;  // distance of the outer points from the wall polyline
  double outer_distance_max = 0.0;
  int self_intersecting_layers = 0;  // layers j >= 1 whose polyline crosses itself
  int first_self_intersecting_layer = -1;
};

// Measures `grid` (ni x nj x 1, spatial_dim 2, periodic in i, j = 0 the wall) whose wall
// corners are the indices `corners`. O(ni^2 nj) for the self-intersection test.
OGridQuality MeasureOGrid(const StructuredBlock& grid, const std::vector<int>& corners);

struct ProfileGrid {
  StructuredBlock block;     // wall_points x (layers + 1), spatial_dim 2
  AirfoilFit profile;        // the fitted outline
  double fit_tolerance = 0;  // the tolerance it was fitted to (options' or the default)
  double first_height = 0;   // the layer stack built (options' or the defaults)
  double distance = 0;
  WallLoop wall;             // its distributed loop (block's j = 0, maybe reversed: offset_march.h)
  std::vector<int> corners;  // the wall's corners as i indices of `block`
  double growth_ratio = 1.0;
  int retries = 0;  // kOffsets: extra normal smoothing rounds over all layers
  // kTransfinite, kElliptic: the offset layers the interpolation starts from (cove_completion.h;
  // 0: from the wall).
  int marched_layers = 0;
  // kElliptic: sweeps and seconds of the coarse level (from the algebraic grid) and of the
  // fine level (its multigrid cycles: fine sweeps, and the seconds of all levels); whether the
  // fine level converged; the restarts of both levels after a stall and the fine level's omega
  // at the end (EllipticResult).
  int coarse_sweeps = 0, fine_sweeps = 0;
  double coarse_seconds = 0.0, fine_seconds = 0.0;
  bool elliptic_converged = false;
  int elliptic_restarts = 0;
  double elliptic_relaxation = 0.0;
  OGridQuality quality;
  // Seconds of each stage.
  double fit_seconds = 0.0, wall_seconds = 0.0, layer_seconds = 0.0, measure_seconds = 0.0;
};

// The grid of the file comment around the outline `coordinates` (n x 1 x 1, spatial_dim 2,
// Selig order: from the trailing edge over the upper surface to the leading edge and back).
// Errors: INVALID_ARGUMENT naming the field and value for bad options or coordinates (too few
// points, non-finite values, an outline that crosses itself: FitAirfoil), or a profile whose
// fit misses fit_tolerance; FAILED_PRECONDITION when the layers cannot be kept from folding
// (naming the layer); CANCELLED.
absl::StatusOr<ProfileGrid> GenerateProfileGrid(const StructuredBlock& coordinates,
                                                const ProfileGridOptions& options);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_GENERATE_PROFILE_GRID_H_
