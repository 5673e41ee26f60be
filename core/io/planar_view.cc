#include "core/io/planar_view.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

constexpr char kDirectionNames[] = "ijk";
constexpr char kCoordinateNames[] = "xyz";

// What, if anything, keeps a block from being a two-plane block along one direction.
enum class PlaneProblem {
  kNone,
  kCoincide,        // no coordinate differs between the planes at their first point
  kSeveralDiffer,   // more than one coordinate differs at their first point
  kInPlaneDiffers,  // an in-plane coordinate differs between the planes at some point
  kNotConstant,     // the normal coordinate varies on one plane
};

// The outcome of checking one direction.
struct PlaneCheck {
  PlaneProblem problem = PlaneProblem::kNone;
  int coordinate = 0;       // coordinate at fault (or the normal coordinate when kNone)
  int plane = 0;            // plane at fault (kNotConstant)
  int a_index = 0;          // first remaining index of the point at fault
  int b_index = 0;          // second remaining index of the point at fault
  double difference = 0.0;  // the offending difference
  TwoPlaneLayout layout;    // valid when problem == kNone
};

// The two index directions other than `d`, in increasing order.
std::pair<int, int> OtherDirections(int d) { return {d == 0 ? 1 : 0, d == 2 ? 1 : 2}; }

// Absolute tolerance for `block`: options.relative_tolerance times its bounding-box diagonal.
double Tolerance(const StructuredBlock& block, const PlanarViewOptions& options) {
  double low[3], high[3];
  std::fill(low, low + 3, std::numeric_limits<double>::infinity());
  std::fill(high, high + 3, -std::numeric_limits<double>::infinity());
  const std::span<const double> coords = block.coords();
  for (size_t c = 0; c < coords.size(); c += 3) {
    for (int s = 0; s < 3; ++s) {
      low[s] = std::min(low[s], coords[c + s]);
      high[s] = std::max(high[s], coords[c + s]);
    }
  }
  double diagonal2 = 0.0;
  for (int s = 0; s < 3; ++s) diagonal2 += (high[s] - low[s]) * (high[s] - low[s]);
  return options.relative_tolerance * std::sqrt(diagonal2);
}

// True when |difference| <= tol (false for NaN).
bool Within(double difference, double tol) { return std::abs(difference) <= tol; }

// Checks whether the planes 0 and 1 along direction `d` (extent 2) of 3D `block` form a
// two-plane block with tolerance `tol`.
PlaneCheck CheckPlanes(const StructuredBlock& block, int d, double tol) {
  // Plain variables, not a structured binding: lambdas capture those portably.
  const auto others = OtherDirections(d);
  const int a = others.first, b = others.second;
  auto point = [&](int plane, int ia, int ib) {
    int index[3];
    index[d] = plane;
    index[a] = ia;
    index[b] = ib;
    return block.Point(index[0], index[1], index[2]);
  };
  PlaneCheck check;
  const double* first0 = point(0, 0, 0);
  const double* first1 = point(1, 0, 0);
  int normal = -1;
  for (int s = 0; s < 3; ++s) {
    if (Within(first1[s] - first0[s], tol)) continue;
    if (normal >= 0) {
      check.problem = PlaneProblem::kSeveralDiffer;
      check.coordinate = s;
      check.difference = first1[s] - first0[s];
      return check;
    }
    normal = s;
  }
  if (normal < 0) {
    check.problem = PlaneProblem::kCoincide;
    return check;
  }
  const double values[2] = {first0[normal], first1[normal]};
  for (int ib = 0; ib < block.extent(b); ++ib) {
    for (int ia = 0; ia < block.extent(a); ++ia) {
      const double* p[2] = {point(0, ia, ib), point(1, ia, ib)};
      check.a_index = ia;
      check.b_index = ib;
      for (int s = 0; s < 3; ++s) {
        if (s != normal && !Within(p[1][s] - p[0][s], tol)) {
          check.problem = PlaneProblem::kInPlaneDiffers;
          check.coordinate = s;
          check.difference = p[1][s] - p[0][s];
          return check;
        }
      }
      for (int plane = 0; plane < 2; ++plane) {
        if (!Within(p[plane][normal] - values[plane], tol)) {
          check.problem = PlaneProblem::kNotConstant;
          check.coordinate = normal;
          check.plane = plane;
          check.difference = p[plane][normal] - values[plane];
          return check;
        }
      }
    }
  }
  check.coordinate = normal;
  check.layout = TwoPlaneLayout{d, normal, {values[0], values[1]}};
  return check;
}

// Runs CheckPlanes on every direction with extent 2 of 3D `block`; the first success, else the
// first failure. `*found` is false when no direction has extent 2.
PlaneCheck CheckBlock(const StructuredBlock& block, double tol, int* direction, bool* found) {
  PlaneCheck first_failure;
  *found = false;
  for (int d = 0; d < 3; ++d) {
    if (block.extent(d) != 2) continue;
    PlaneCheck check = CheckPlanes(block, d, tol);
    if (check.problem == PlaneProblem::kNone || !*found) {
      first_failure = check;
      *direction = d;
    }
    *found = true;
    if (check.problem == PlaneProblem::kNone) break;
  }
  return first_failure;
}

// The message for failed `check` along direction `d` with tolerance `tol`.
std::string ProblemMessage(const PlaneCheck& check, int d, double tol,
                           const PlanarViewOptions& options) {
  const auto [a, b] = OtherDirections(d);
  const std::string planes = absl::StrCat("planes ", std::string(1, kDirectionNames[d]),
                                          " = 0 and ", std::string(1, kDirectionNames[d]), " = 1");
  const std::string at = absl::StrCat(" at (", std::string(1, kDirectionNames[a]), ", ",
                                      std::string(1, kDirectionNames[b]), ") = (", check.a_index,
                                      ", ", check.b_index, ")");
  const std::string tolerance = absl::StrCat(" (tolerance ", tol, " = ", options.relative_tolerance,
                                             " x bounding-box diagonal)");
  const std::string coordinate(1, kCoordinateNames[check.coordinate]);
  switch (check.problem) {
    case PlaneProblem::kCoincide:
      return absl::StrCat(planes, " coincide at their first point", tolerance);
    case PlaneProblem::kSeveralDiffer:
      return absl::StrCat(planes, " differ in more than one coordinate at their first point (",
                          coordinate, " by ", check.difference, ")", tolerance);
    case PlaneProblem::kInPlaneDiffers:
      return absl::StrCat(planes, " differ in ", coordinate, " by ", check.difference, at,
                          tolerance);
    case PlaneProblem::kNotConstant:
      return absl::StrCat(coordinate, " is not constant on plane ",
                          std::string(1, kDirectionNames[d]), " = ", check.plane,
                          ": it differs from its value at the first point by ", check.difference,
                          at, tolerance);
    case PlaneProblem::kNone:
      break;
  }
  return "";
}

}  // namespace

absl::StatusOr<TwoPlaneLayout> DetectTwoPlaneBlock(const StructuredBlock& block,
                                                   const PlanarViewOptions& options) {
  const std::string prefix = "not a two-plane block: ";
  if (block.spatial_dim() != 3) {
    return absl::InvalidArgumentError(
        absl::StrCat(prefix, "it has spatial_dim ", block.spatial_dim(),
                     "; only 3D blocks hold two planes (AsPlanarGrid passes 2D blocks through)"));
  }
  const double tol = Tolerance(block, options);
  int direction = 0;
  bool found = false;
  const PlaneCheck check = CheckBlock(block, tol, &direction, &found);
  if (!found) {
    return absl::InvalidArgumentError(absl::StrCat(prefix, "no index direction of ",
                                                   block.extent(0), " x ", block.extent(1), " x ",
                                                   block.extent(2), " has exactly 2 points"));
  }
  if (check.problem != PlaneProblem::kNone) {
    return absl::InvalidArgumentError(
        absl::StrCat(prefix, ProblemMessage(check, direction, tol, options)));
  }
  return check.layout;
}

bool IsTwoPlaneBlock(const StructuredBlock& block, const PlanarViewOptions& options) {
  if (block.spatial_dim() != 3) return false;
  int direction = 0;
  bool found = false;
  const PlaneCheck check = CheckBlock(block, Tolerance(block, options), &direction, &found);
  return found && check.problem == PlaneProblem::kNone;
}

bool IsTwoPlaneGrid(const MultiBlockGrid& grid, const PlanarViewOptions& options) {
  return !grid.blocks.empty() &&
         std::all_of(grid.blocks.begin(), grid.blocks.end(),
                     [&](const StructuredBlock& block) { return IsTwoPlaneBlock(block, options); });
}

absl::StatusOr<StructuredBlock> PlanarBlock(const StructuredBlock& block,
                                            const PlanarViewOptions& options) {
  SG_ASSIGN_OR_RETURN(const TwoPlaneLayout layout, DetectTwoPlaneBlock(block, options));
  const int d = layout.plane_direction;
  const auto [a, b] = OtherDirections(d);
  const int kept[2] = {layout.normal_coordinate == 0 ? 1 : 0,
                       layout.normal_coordinate == 2 ? 1 : 2};
  StructuredBlock planar({block.extent(a), block.extent(b), 1}, 2);
  const bool has_iblank = block.iblank().size() == static_cast<size_t>(block.num_points());
  if (has_iblank) planar.iblank().resize(static_cast<size_t>(planar.num_points()));
  for (int ib = 0; ib < block.extent(b); ++ib) {
    for (int ia = 0; ia < block.extent(a); ++ia) {
      int index[3];
      index[d] = 0;
      index[a] = ia;
      index[b] = ib;
      const double* from = block.Point(index[0], index[1], index[2]);
      double* to = planar.Point(ia, ib, 0);
      to[0] = from[kept[0]];
      to[1] = from[kept[1]];
      if (has_iblank) {
        planar.iblank()[planar.Index(ia, ib, 0)] =
            block.iblank()[block.Index(index[0], index[1], index[2])];
      }
    }
  }
  return planar;
}

namespace {

// PlanarView, or with `pass_2d_blocks` AsPlanarGrid; the layouts of the 3D blocks into
// `*layouts` when not null.
absl::StatusOr<MultiBlockGrid> Planarize(const MultiBlockGrid& grid,
                                         const PlanarViewOptions& options, bool pass_2d_blocks,
                                         std::vector<TwoPlaneLayout>* layouts = nullptr) {
  MultiBlockGrid planar;
  planar.blocks.reserve(grid.blocks.size());
  for (size_t b = 0; b < grid.blocks.size(); ++b) {
    if (pass_2d_blocks && grid.blocks[b].spatial_dim() == 2) {
      planar.blocks.push_back(grid.blocks[b]);
      continue;
    }
    absl::StatusOr<StructuredBlock> block = PlanarBlock(grid.blocks[b], options);
    if (!block.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("block ", b, ": ", block.status().message()));
    }
    if (layouts != nullptr) {
      SG_ASSIGN_OR_RETURN(TwoPlaneLayout layout, DetectTwoPlaneBlock(grid.blocks[b], options));
      layouts->push_back(layout);
    }
    planar.blocks.push_back(*std::move(block));
  }
  return planar;
}

}  // namespace

absl::StatusOr<MultiBlockGrid> PlanarView(const MultiBlockGrid& grid,
                                          const PlanarViewOptions& options) {
  return Planarize(grid, options, /*pass_2d_blocks=*/false);
}

absl::StatusOr<MultiBlockGrid> PlanarView(const MultiBlockGrid& grid,
                                          const PlanarViewOptions& options,
                                          std::vector<TwoPlaneLayout>* layouts) {
  layouts->clear();
  return Planarize(grid, options, /*pass_2d_blocks=*/false, layouts);
}

absl::StatusOr<StructuredBlock> TwoPlaneBlock(const StructuredBlock& planar,
                                              const TwoPlaneLayout& layout) {
  if (planar.spatial_dim() != 2 || planar.extent(2) != 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("restoring two planes: the block must be 2D with nk = 1, not spatial_dim ",
                     planar.spatial_dim(), " and nk = ", planar.extent(2)));
  }
  const int d = layout.plane_direction;
  const int c = layout.normal_coordinate;
  if (d < 0 || d > 2 || c < 0 || c > 2) {
    return absl::InvalidArgumentError(absl::StrCat("restoring two planes: plane_direction ", d,
                                                   " and normal_coordinate ", c,
                                                   " must be from 0 to 2"));
  }
  const auto [a, b] = OtherDirections(d);
  const int kept[2] = {c == 0 ? 1 : 0, c == 2 ? 1 : 2};
  Extents extents;
  extents[d] = 2;
  extents[a] = planar.extent(0);
  extents[b] = planar.extent(1);
  StructuredBlock block(extents, 3);
  const bool has_iblank = planar.iblank().size() == static_cast<size_t>(planar.num_points());
  if (has_iblank) block.iblank().resize(static_cast<size_t>(block.num_points()));
  for (int plane = 0; plane < 2; ++plane) {
    for (int ib = 0; ib < planar.extent(1); ++ib) {
      for (int ia = 0; ia < planar.extent(0); ++ia) {
        int index[3];
        index[d] = plane;
        index[a] = ia;
        index[b] = ib;
        const double* from = planar.Point(ia, ib, 0);
        double* to = block.Point(index[0], index[1], index[2]);
        to[kept[0]] = from[0];
        to[kept[1]] = from[1];
        to[c] = layout.plane_values[plane];
        if (has_iblank) {
          block.iblank()[block.Index(index[0], index[1], index[2])] =
              planar.iblank()[planar.Index(ia, ib, 0)];
        }
      }
    }
  }
  return block;
}

absl::StatusOr<MultiBlockGrid> AsPlanarGrid(const MultiBlockGrid& grid,
                                            const PlanarViewOptions& options) {
  return Planarize(grid, options, /*pass_2d_blocks=*/true);
}

}  // namespace splinegrid
