#include "core/fit/grid_fit.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "core/fit/adaptive/multiblock_fit.h"
#include "core/fit/adaptive/segment_model.h"
#include "core/fit/report/fit_report.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

// The index in options.block_control_counts of block b's override, or -1.
int OverrideOf(const GridFitOptions& options, int b) {
  for (size_t q = 0; q < options.block_control_counts.size(); ++q) {
    if (options.block_control_counts[q].first == b) return static_cast<int>(q);
  }
  return -1;
}

// The control-count fit options of block b: its override if it has one, else the grid-wide
// counts, as given (Validate refuses counts that do not suit the block; nothing is clamped).
FitOptions BlockOptions(const GridFitOptions& options, int b) {
  FitOptions fit_options;
  fit_options.order = options.order;
  fit_options.parametrization = options.parametrization;
  if (options.fairing.mode == FairingMode::kWeight) fit_options.fairing = options.fairing.weight;
  const int q = OverrideOf(options, b);
  fit_options.control_counts =
      q >= 0 ? options.block_control_counts[q].second : options.control_counts;
  return fit_options;
}

// Control-count mode: every block on its own (`result` holds the kinds already).
// Every line of a direction is C0 at the kinks of the block's boundary lines, so that a spline
// through a corner (a blunt trailing edge's base) keeps it instead of swinging beside it: the
// interpolating fit of a generated NACA 0012 O-grid folded 101 sub-cells there without. Of the
// 30-degree turnings only tangent discontinuities count (kink_ratio 2; the spike rule stays): with
// its knots fixed by the counts, this mode has no tolerance to win back a coarse smooth bend made
// C0, which changes the curve between its points (RAE 2822 at 65 wall points: its nose folded a
// sub-cell far out).
absl::Status FitBlocks(const MultiBlockGrid& grid, const Connectivity& connectivity,
                       const GridFitOptions& options, const CancelCheck& cancel, GridFit& result) {
  FeatureOptions features = options.features;
  features.kink_ratio = std::max(features.kink_ratio, 2.0);
  for (int b = 0; b < static_cast<int>(grid.blocks.size()); ++b) {
    FitOptions fit_options = BlockOptions(options, b);
    fit_options.cancel = cancel;
    for (int d = 0; d < 3; ++d) {
      fit_options.breaks[d] = DetectFeatures(grid.blocks[b], d, features);
    }
    BlockFit block;
    SG_ASSIGN_OR_RETURN(block.fitted, FitBlock(grid.blocks[b], fit_options), "block ", b, ": ");
    result.blocks.push_back(std::move(block));
  }
  if (options.fairing.mode == FairingMode::kWeight) {
    result.report.fairing_weight = options.fairing.weight;
  }
  result.connectivity = connectivity;
  return absl::OkStatus();
}

}  // namespace

BoundaryTolerances GridFitOptions::Tolerances(double reference_length) const {
  if (boundary_tolerances) {
    return ScaleTolerances(*boundary_tolerances, relative_kinds, reference_length);
  }
  BoundaryTolerances t;
  if (tolerance) t.wall = t.interface = t.outer = t.interior = *tolerance;
  return t;
}

absl::Status GridFitOptions::Validate(const MultiBlockGrid& grid) const {
  if (grid.blocks.empty()) return absl::InvalidArgumentError("the grid has no blocks");
  if (order < 2 || order > kMaxOrder) {
    return absl::InvalidArgumentError(
        absl::StrCat("order = ", order, " is outside [2, ", kMaxOrder, "]"));
  }
  SG_RETURN_IF_ERROR(fairing.Validate());
  SG_RETURN_IF_ERROR(ValidateParametrization(parametrization));
  if (max_iterations < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_iterations = ", max_iterations, " is negative"));
  }
  SG_RETURN_IF_ERROR(features.Validate());
  SG_RETURN_IF_ERROR(quality.Validate());
  SG_RETURN_IF_ERROR(connectivity.Validate());
  const int num_blocks = static_cast<int>(grid.blocks.size());
  for (const FaceKindOverride& o : face_kinds) {
    if (o.face.block < 0 || o.face.block >= num_blocks) {
      return absl::InvalidArgumentError(absl::StrCat("face_kinds: block ", o.face.block,
                                                     " is outside [0, ", num_blocks - 1, "]"));
    }
  }
  if (tolerance_mode()) {
    if (tolerance && boundary_tolerances) {
      return absl::InvalidArgumentError(
          "tolerance and boundary_tolerances cannot both be given; use one");
    }
    if (tolerance && (!(*tolerance > 0.0) || !std::isfinite(*tolerance))) {
      return absl::InvalidArgumentError(
          absl::StrCat("tolerance = ", *tolerance, "; must be positive and finite"));
    }
    if (boundary_tolerances) SG_RETURN_IF_ERROR(boundary_tolerances->Validate());
    if (reference_length && !boundary_tolerances) {
      return absl::InvalidArgumentError(absl::StrCat(
          "reference_length = ", *reference_length,
          " applies to the tolerances by kind; tolerance is a length in the grid's unit"));
    }
    if (reference_length && (!(*reference_length > 0.0) || !std::isfinite(*reference_length))) {
      return absl::InvalidArgumentError(
          absl::StrCat("reference_length = ", *reference_length, "; must be positive and finite"));
    }
    SG_RETURN_IF_ERROR(ValidateControlCap(max_controls_per_direction, order));
    if (!block_control_counts.empty()) {
      return absl::InvalidArgumentError("block_control_counts cannot be combined with a tolerance");
    }
    return absl::OkStatus();
  }
  if (fairing.mode == FairingMode::kToTolerance) {
    return absl::InvalidArgumentError(
        "fairing to tolerance needs a tolerance; with control counts give a fairing weight");
  }
  if (reference_length) {
    return absl::InvalidArgumentError(
        absl::StrCat("reference_length = ", *reference_length,
                     " applies to the tolerances by kind; a fit to control counts has none"));
  }
  for (size_t q = 0; q < block_control_counts.size(); ++q) {
    const int block = block_control_counts[q].first;
    const std::string field = absl::StrCat("block_control_counts[", q, "].block = ", block);
    if (block < 0 || block >= num_blocks) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, " is outside [0, ", num_blocks - 1, "]"));
    }
    if (const int first = OverrideOf(*this, block); first != static_cast<int>(q)) {
      return absl::InvalidArgumentError(absl::StrCat(field, " repeats block_control_counts[", first,
                                                     "]; give one entry per block"));
    }
  }
  // Every block against the counts it gets, named as the request names them.
  for (int b = 0; b < num_blocks; ++b) {
    const int q = OverrideOf(*this, b);
    const std::string field = q >= 0 ? absl::StrCat("block_control_counts[", q, "].control_counts")
                                     : std::string("control_counts");
    const Extents& counts = q >= 0 ? block_control_counts[q].second : control_counts;
    SG_RETURN_IF_ERROR(ValidateControlCounts(counts, order, grid.blocks[b].extents(), field,
                                             absl::StrCat("block ", b)));
  }
  return absl::OkStatus();
}

namespace {

// OK for options and a grid FitGrid can start on: INVALID_ARGUMENT for the options,
// FAILED_PRECONDITION for a block that cannot be fitted.
absl::Status ValidateGridFit(const MultiBlockGrid& grid, const GridFitOptions& options) {
  SG_RETURN_IF_ERROR(options.Validate(grid));
  if (absl::Status s = ValidateFittableBlocks(grid); !s.ok()) {
    return absl::FailedPreconditionError(s.message());
  }
  return absl::OkStatus();
}

// The source cells of no thickness along a direction (every edge of the cell along it has zero
// length: a grid line repeated), which any spline through the points folds, so that the fold
// refusal blames the data, not the fit: "" when there are none, else a sentence naming the count
// and the first. (A pole, a grid edge collapsed to a point, is no such cell: the edges across
// it have length.) O(points).
std::string RepeatedLines(const MultiBlockGrid& grid) {
  int64_t count = 0;
  std::string first;
  for (size_t b = 0; b < grid.blocks.size(); ++b) {
    const StructuredBlock& block = grid.blocks[b];
    const Extents n = block.extents();
    const int s = block.spatial_dim();
    // Whether the cell at `cell` has no edge of length along d: the points at both ends of each
    // of its edges along d (2 in a surface, 4 in a volume) coincide.
    auto flat_along = [&](const Extents& cell, int d) {
      const int e1 = (d + 1) % 3, e2 = (d + 2) % 3;
      for (int a = 0; a <= (n[e1] > 1); ++a) {
        for (int c = 0; c <= (n[e2] > 1); ++c) {
          Extents p = cell;
          p[e1] += a;
          p[e2] += c;
          const double* x = block.Point(p[0], p[1], p[2]);
          ++p[d];
          if (!std::equal(x, x + s, block.Point(p[0], p[1], p[2]))) return false;
        }
      }
      return true;
    };
    for (int k = 0; k < std::max(n[2] - 1, 1); ++k) {
      for (int j = 0; j < std::max(n[1] - 1, 1); ++j) {
        for (int i = 0; i < std::max(n[0] - 1, 1); ++i) {
          bool flat = false;
          for (int d = 0; d < 3 && !flat; ++d) flat = n[d] > 1 && flat_along({i, j, k}, d);
          if (flat && count++ == 0) {
            first = absl::StrCat("block ", b, " cell (", i, ", ", j, ", ", k, ")");
          }
        }
      }
    }
  }
  if (count == 0) return "";
  return absl::StrCat(". The points themselves have ", count,
                      " cells of no thickness (a grid line repeated), the first ", first,
                      ": no spline through them can avoid folding there; remove the repeated "
                      "lines");
}

// What a caller can do about a fit of `options` that folds (it is not repaired unless in the
// tolerance mode: repairing would change the counts, or what is interpolated, silently).
std::string FoldAdvice(const GridFitOptions& options) {
  if (options.tolerance.has_value()) {
    // One tolerance for every point holds a far field to the wall's accuracy: nearly a control
    // per datum there. Tolerances by kind leave the interior to the edge criterion.
    return ". Local refinement, knot removal, averaged knots and a weak fairing did not repair "
           "it; try a looser tolerance, or tolerances by boundary kind (they hold the interior "
           "to each cell's size, not to one length)";
  }
  if (options.tolerance_mode()) {
    return ". Local refinement, knot removal, averaged knots and a weak fairing did not repair "
           "it; try a looser tolerance";
  }
  if (options.control_counts == Extents{0, 0, 0} && options.block_control_counts.empty()) {
    return ". An interpolating fit (a control point per grid point: neither counts nor a "
           "tolerance were given) is not repaired (that would change what it interpolates); "
           "try a tolerance or control counts";
  }
  return ". A fit to control counts is not repaired (that would change the counts); try other "
         "counts or a tolerance";
}

// Tolerances below kResolvableUlps units in the last place of the grid's largest coordinate
// cannot be met or measured: a fit to 1e-300 was stored with every tolerance missed ("inf times
// its tolerance"). INVALID_ARGUMENT naming the field (and the reference length it came from).
absl::Status CheckResolvable(const MultiBlockGrid& grid, const GridFitOptions& options,
                             const BoundaryTolerances& tolerances,
                             const ReferenceLength& reference) {
  const double largest = LargestCoordinate(grid);
  const double floor = kResolvableUlps * std::numeric_limits<double>::epsilon() * largest;
  const std::pair<const char*, double> kinds[] = {{"wall", tolerances.wall},
                                                  {"interface", tolerances.interface},
                                                  {"outer", tolerances.outer},
                                                  {"interior", tolerances.interior}};
  for (const auto& [kind, value] : kinds) {
    if (!(value < floor)) continue;
    const std::string field =
        options.tolerance ? std::string("tolerance") : absl::StrCat("boundary_tolerances.", kind);
    const std::string scaled =
        !options.tolerance && options.relative_kinds != 0
            ? absl::StrCat(" (with the reference length ", reference.length, ")")
            : std::string();
    return absl::InvalidArgumentError(absl::StrCat(
        field, " = ", value, scaled, " is below what double precision resolves in this grid ",
        "(coordinates up to ", largest, "): give at least ", floor));
  }
  return absl::OkStatus();
}

// FitGrid once the options are valid and every block fittable (ValidateGridFit, or a
// FittableGrid).
absl::StatusOr<GridFit> FitValidated(const MultiBlockGrid& grid, const Connectivity& connectivity,
                                     const GridFitOptions& options, const CancelCheck& cancel) {
  const auto start = std::chrono::steady_clock::now();
  GridFit result;
  // The kinds of every boundary point (both modes), then the reference length: given, or
  // detected from the walls.
  SG_ASSIGN_OR_RETURN(result.kinds, ClassifyBoundaries(grid, connectivity, options.face_kinds));
  const ReferenceLength reference =
      options.reference_length
          ? ReferenceLength{*options.reference_length, ReferenceLengthSource::kGiven,
                            absl::StrCat("given: reference_length = ", *options.reference_length)}
          : DetectReferenceLength(grid, result.kinds);
  CellQualityOptions quality = options.quality;
  quality.cancel = cancel;
  if (options.tolerance_mode()) {
    const BoundaryTolerances tolerances = options.Tolerances(reference.length);
    SG_RETURN_IF_ERROR(CheckResolvable(grid, options, tolerances, reference));
    SG_ASSIGN_OR_RETURN(
        internal::MultiBlockRun run,
        internal::FitMultiBlock(grid, connectivity, result.kinds, options, tolerances, cancel));
    result = std::move(run.fit);
  } else {
    SG_RETURN_IF_ERROR(FitBlocks(grid, connectivity, options, cancel, result));
    SG_RETURN_IF_ERROR(internal::ReportFit(grid, quality, nullptr, {}, result));
  }
  result.report.num_matches = static_cast<int>(result.connectivity.matches.size());
  result.report.reference = reference;
  for (size_t b = 0; b < result.blocks.size(); ++b) {
    const Extents points = grid.blocks[b].extents();
    for (int d = 0; d < 3; ++d) {
      const int order = result.blocks[b].fitted.spline.knots(d).order();
      if (points[d] > 1 && order < options.order) {
        result.report.adjustments.push_back(absl::StrCat(
            "block ", b, " direction ", std::string(1, "ijk"[d]), ": ", points[d],
            " points, fitted through them at order ", order, " instead of ", options.order));
      }
    }
  }
  result.report.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Never a folded grid unless asked for: the tolerance mode has already tried to repair the
  // folds (adaptive_engine.h, steps 2, 2b and 3b); a fit to control counts cannot be repaired
  // without changing the counts it was given, which would be a silent change.
  if (!options.allow_folds) {
    std::vector<std::string> folds;
    for (size_t b = 0; b < result.blocks.size(); ++b) {
      std::string d = DescribeFolds(static_cast<int>(b), result.blocks[b].quality);
      if (!d.empty()) folds.push_back(std::move(d));
    }
    if (!folds.empty()) {
      const std::string repeated = RepeatedLines(grid);
      return absl::FailedPreconditionError(
          absl::StrCat("the fitted grid folds at refinement levels 0..", quality.max_level, ": ",
                       absl::StrJoin(folds, "; "),
                       // Repeated lines fold any fit: no other fit to suggest.
                       repeated.empty() ? FoldAdvice(options) : repeated,
                       ", or set allow_folds to accept the folded grid"));
    }
  }
  return result;
}

}  // namespace

absl::StatusOr<GridFit> FitGrid(const MultiBlockGrid& grid, const GridFitOptions& options,
                                const CancelCheck& cancel) {
  SG_RETURN_IF_ERROR(ValidateGridFit(grid, options));
  SG_ASSIGN_OR_RETURN(const Connectivity connectivity,
                      FindConnectivity(grid, options.connectivity, cancel));
  return FitValidated(grid, connectivity, options, cancel);
}

absl::StatusOr<GridFit> FitGrid(const FittableGrid& grid, const GridFitOptions& options,
                                const CancelCheck& cancel) {
  SG_RETURN_IF_ERROR(options.Validate(grid.grid()));
  return FitValidated(grid.grid(), grid.connectivity(), options, cancel);
}

}  // namespace splinegrid
