#include "core/grid/structured_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "core/util/check.h"
#include "core/util/status_macros.h"

namespace splinegrid {

int ActiveDirections(const Extents& extents) {
  int active = 0;
  for (int n : extents) active += n > 1 ? 1 : 0;
  return active;
}

StructuredBlock::StructuredBlock(const Extents& extents, int spatial_dim)
    : extents_(extents), spatial_dim_(spatial_dim) {
  SG_CHECK(spatial_dim == 2 || spatial_dim == 3);
  SG_CHECK(extents[0] >= 1 && extents[1] >= 1 && extents[2] >= 1);
  coords_.assign(static_cast<size_t>(spatial_dim * NumPoints(extents)), 0.0);
}

double LargestCoordinate(const MultiBlockGrid& grid) {
  double largest = 0.0;
  for (const StructuredBlock& block : grid.blocks) {
    for (double x : block.coords()) largest = std::max(largest, std::abs(x));
  }
  return largest;
}

absl::Status ValidateExtents(const Extents& extents, const std::string& what, int64_t max_points,
                             int max_extent) {
  static constexpr char kNames[] = "ijk";
  for (int d = 0; d < 3; ++d) {
    if (extents[d] < 1 || extents[d] > max_extent) {
      return absl::InvalidArgumentError(absl::StrCat(what, ": n", std::string(1, kNames[d]), " = ",
                                                     extents[d], " is outside [1, ", max_extent,
                                                     "]"));
    }
  }
  // Each extent is at most 2^24 here, so the product of the first two fits in int64; compare
  // the third by division so that the full product cannot overflow.
  const int64_t plane = int64_t{extents[0]} * extents[1];
  if (plane > max_points || extents[2] > max_points / plane) {
    return absl::InvalidArgumentError(absl::StrCat(what, ": ", extents[0], " x ", extents[1], " x ",
                                                   extents[2], " points exceeds the limit of ",
                                                   max_points));
  }
  return absl::OkStatus();
}

void ReverseDirection(StructuredBlock& block, int direction) {
  const Extents& n = block.extents();
  const int dim = block.spatial_dim();
  Extents x = {0, 0, 0};
  for (x[2] = 0; x[2] < n[2]; ++x[2]) {
    for (x[1] = 0; x[1] < n[1]; ++x[1]) {
      for (x[0] = 0; x[0] < n[0]; ++x[0]) {
        if (2 * x[direction] >= n[direction] - 1) continue;  // each pair once
        Extents y = x;
        y[direction] = n[direction] - 1 - x[direction];
        std::swap_ranges(block.Point(x[0], x[1], x[2]), block.Point(x[0], x[1], x[2]) + dim,
                         block.Point(y[0], y[1], y[2]));
      }
    }
  }
}

absl::Status ValidateFinite(const StructuredBlock& block, const std::string& what) {
  const auto coords = block.coords();
  const int s = block.spatial_dim();
  for (size_t c = 0; c < coords.size(); ++c) {
    if (!std::isfinite(coords[c])) {
      const int64_t p = static_cast<int64_t>(c) / s;
      const int64_t ni = block.extent(0), nj = block.extent(1);
      return absl::InvalidArgumentError(absl::StrCat(
          what, ": point (", p % ni, ", ", (p / ni) % nj, ", ", p / (ni * nj), ") coordinate ",
          std::string(1, "xyz"[c % s]), " is ", coords[c], "; coordinates must be finite"));
    }
  }
  return absl::OkStatus();
}

namespace {

// Relative size below which a length, area or volume counts as zero (of L, L^2, L^3).
constexpr double kDegenerate = 1e-12;

using Vec = std::array<double, 3>;

// (b - a) / scale, zero-padded to three coordinates.
Vec Difference(const double* a, const double* b, int s, double scale) {
  Vec v = {0.0, 0.0, 0.0};
  for (int c = 0; c < s; ++c) v[c] = (b[c] - a[c]) / scale;
  return v;
}

// |det| of the edge vectors `e` (count = active directions): length, area or volume.
double Measure(const std::array<Vec, 3>& e, int count) {
  switch (count) {
    case 1:
      return std::sqrt(e[0][0] * e[0][0] + e[0][1] * e[0][1] + e[0][2] * e[0][2]);
    case 2: {
      const Vec c = {e[0][1] * e[1][2] - e[0][2] * e[1][1], e[0][2] * e[1][0] - e[0][0] * e[1][2],
                     e[0][0] * e[1][1] - e[0][1] * e[1][0]};
      return std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    }
    default:
      return std::abs(e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                      e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                      e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]));
  }
}

}  // namespace

absl::Status ValidateFittable(const StructuredBlock& block, const std::string& what) {
  static constexpr char kNames[] = "ijk";
  SG_RETURN_IF_ERROR(ValidateFinite(block, what));
  const int s = block.spatial_dim();
  const Extents& n = block.extents();
  std::vector<int> active;
  for (int d = 0; d < 3; ++d) {
    if (n[d] > 1) active.push_back(d);
  }
  if (active.empty()) return absl::OkStatus();  // a single point: nothing to span
  const int dims = static_cast<int>(active.size());
  if (dims == 3 && s == 2) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": ", n[0], " x ", n[1], " x ", n[2],
                     " points with 2 coordinates: a volume block needs 3 (x, y, z) coordinates"));
  }
  // L: the diagonal of the bounding box.
  const auto coords = block.coords();
  Vec lo = {coords[0], coords[1], s == 3 ? coords[2] : 0.0}, hi = lo;
  for (size_t x = 0; x < coords.size(); ++x) {
    lo[x % s] = std::min(lo[x % s], coords[x]);
    hi[x % s] = std::max(hi[x % s], coords[x]);
  }
  double diagonal = 0.0, widest = 0.0;
  for (int c = 0; c < s; ++c) {
    diagonal += (hi[c] - lo[c]) * (hi[c] - lo[c]);
    widest = std::max(widest, hi[c] - lo[c]);
  }
  diagonal = std::sqrt(diagonal);
  // Lengths whose squares underflow (the fit's normal equations and distances square them): a
  // grid in units of 1e-300 read as "all points equal".
  if (widest > 0.0 && widest < std::sqrt(std::numeric_limits<double>::min())) {
    return absl::InvalidArgumentError(absl::StrCat(
        what, ": the coordinates are too small to measure the block (its bounding box spans ",
        widest, "; squares of lengths below ", std::sqrt(std::numeric_limits<double>::min()),
        " underflow): scale the grid to its length unit"));
  }
  if (!std::isfinite(diagonal)) {
    return absl::InvalidArgumentError(
        absl::StrCat(what,
                     ": the coordinates are too large to measure the block (the diagonal of its "
                     "bounding box from (",
                     absl::StrJoin(std::vector<double>(lo.begin(), lo.begin() + s), ", "), ") to (",
                     absl::StrJoin(std::vector<double>(hi.begin(), hi.begin() + s), ", "),
                     ") overflows a double): scale the grid to its length unit"));
  }
  if (!(diagonal > 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": all ", block.num_points(), " points are equal (",
                     absl::StrJoin(std::vector<double>(coords.begin(), coords.begin() + s), ", "),
                     "): a grid collapsed to a point cannot be fitted"));
  }
  // A direction of zero length: no two neighbours along it differ.
  for (int d : active) {
    bool spans = false;
    for (int k = 0; k < n[2] && !spans; ++k) {
      for (int j = 0; j < n[1] && !spans; ++j) {
        for (int i = 0; i < n[0] && !spans; ++i) {
          Extents q = {i, j, k};
          if (q[d] + 1 >= n[d]) continue;
          const double* a = block.Point(i, j, k);
          ++q[d];
          const Vec v = Difference(a, block.Point(q[0], q[1], q[2]), s, diagonal);
          spans = Measure({v, Vec{}, Vec{}}, 1) > kDegenerate;
        }
      }
    }
    if (!spans) {
      const std::string dir(1, kNames[d]);
      return absl::InvalidArgumentError(absl::StrCat(
          what, ": direction ", dir, " has zero length: each of its ", dir, "-lines of ", n[d],
          " points is a single repeated point (the block is collapsed in ", dir,
          "); give the direction one point or spread its points"));
    }
  }
  // The cells' measure: a corner's edge vectors along the active directions, at every corner.
  double total = 0.0;
  const double threshold = kDegenerate;  // in units of L^dims (vectors are scaled by 1 / L)
  Extents last = n;
  for (int d : active) --last[d];
  for (int k = 0; k < last[2] && total <= threshold; ++k) {
    for (int j = 0; j < last[1] && total <= threshold; ++j) {
      for (int i = 0; i < last[0] && total <= threshold; ++i) {
        for (int corner = 0; corner < (1 << dims); ++corner) {
          Extents c = {i, j, k};
          for (int a = 0; a < dims; ++a) c[active[a]] += (corner >> a) & 1;
          std::array<Vec, 3> edges;
          for (int a = 0; a < dims; ++a) {
            Extents o = c;
            o[active[a]] += ((corner >> a) & 1) ? -1 : 1;
            edges[a] = Difference(block.Point(c[0], c[1], c[2]), block.Point(o[0], o[1], o[2]), s,
                                  diagonal);
          }
          total += Measure(edges, dims);
        }
      }
    }
  }
  if (total <= threshold) {
    return absl::InvalidArgumentError(absl::StrCat(
        what, ": its points lie on ", dims == 2 ? "one line" : "one plane", ": the ",
        dims == 2 ? "surface" : "volume", " block of ", n[0], " x ", n[1], " x ", n[2],
        " points has cells of zero ", dims == 2 ? "area" : "volume", " and cannot be fitted"));
  }
  return absl::OkStatus();
}

}  // namespace splinegrid
