#include "core/io/vtk_fields.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/io/vtk.h"

namespace splinegrid {
namespace {

using Vec3 = std::array<double, 3>;

Vec3 Sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 Cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double Dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double Norm(const Vec3& a) { return std::sqrt(Dot(a, a)); }

// Point (i, j, k) of `block` as a 3-vector (z = 0 in 2D).
Vec3 At(const StructuredBlock& block, int i, int j, int k) {
  const double* p = block.Point(i, j, k);
  return {p[0], p[1], block.spatial_dim() == 3 ? p[2] : 0.0};
}

// Vector `p` of a derivative array with `dim` components, as a 3-vector.
Vec3 Tangent(std::span<const double> d, int64_t p, int dim) {
  return {d[p * dim], d[p * dim + 1], dim == 3 ? d[p * dim + 2] : 0.0};
}

// det(a, b, c) / (|a| |b| |c|), or 0 when an edge has no length.
double Scaled3(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double lengths = Norm(a) * Norm(b) * Norm(c);
  return lengths > 0 ? Dot(Cross(a, b), c) / lengths : 0.0;
}

// (a x b) . n / (|a| |b|) for unit n, or 0 when an edge has no length.
double Scaled2(const Vec3& a, const Vec3& b, const Vec3& n) {
  const double lengths = Norm(a) * Norm(b);
  return lengths > 0 ? Dot(Cross(a, b), n) / lengths : 0.0;
}

}  // namespace

absl::StatusOr<std::vector<double>> JacobianField(const StructuredBlock& block,
                                                  std::span<const double> du,
                                                  std::span<const double> dv,
                                                  std::span<const double> dw, int parametric_dim) {
  const int dim = block.spatial_dim();
  const size_t size = static_cast<size_t>(block.num_points() * dim);
  if (parametric_dim < 1 || parametric_dim > dim) {
    return absl::InvalidArgumentError(absl::StrCat("Jacobian: parametric_dim ", parametric_dim,
                                                   " must be from 1 to the spatial_dim ", dim));
  }
  const std::span<const double> needed[] = {du, dv, dw};
  for (int d = 0; d < parametric_dim; ++d) {
    if (needed[d].size() != size) {
      static constexpr const char* kNames[] = {"du", "dv", "dw"};
      return absl::InvalidArgumentError(absl::StrCat("Jacobian: derivative ", kNames[d], " has ",
                                                     needed[d].size(), " values, not ", size));
    }
  }
  std::vector<double> jacobian(static_cast<size_t>(block.num_points()));
  for (int64_t p = 0; p < block.num_points(); ++p) {
    const Vec3 xu = Tangent(du, p, dim);
    if (parametric_dim == 1) {
      jacobian[p] = Norm(xu);
      continue;
    }
    const Vec3 xv = Tangent(dv, p, dim);
    if (parametric_dim == 3) {
      jacobian[p] = Dot(Cross(xu, xv), Tangent(dw, p, dim));
    } else {
      const Vec3 normal = Cross(xu, xv);
      jacobian[p] = dim == 2 ? normal[2] : Norm(normal);
    }
  }
  return jacobian;
}

absl::StatusOr<std::vector<double>> ScaledJacobianCells(const StructuredBlock& block) {
  int directions = 0;
  for (int d = 0; d < 3; ++d) directions += block.extent(d) > 1;
  if (directions < 2) {
    return absl::InvalidArgumentError(absl::StrCat(
        "cell quality: a block of ", block.extent(0), " x ", block.extent(1), " x ",
        block.extent(2), " points is a curve; it has no cells with an area or volume"));
  }
  const bool hexahedra = directions == 3;
  // The two directions of quadrilaterals: the first two with extent > 1.
  int a = 0, b = 1;
  if (!hexahedra) {
    int found[2], n = 0;
    for (int d = 0; d < 3 && n < 2; ++d) {
      if (block.extent(d) > 1) found[n++] = d;
    }
    a = found[0];
    b = found[1];
  }
  const int64_t num_cells = VtkNumCells(block);
  // Per cell the smallest and largest corner value; the block's orientation (the sign of the
  // sum of all corner values) picks which one is the worst.
  std::vector<double> lowest(static_cast<size_t>(num_cells)), highest(lowest.size());
  const int ci = std::max(block.extent(0) - 1, 1), cj = std::max(block.extent(1) - 1, 1);
  const int ck = std::max(block.extent(2) - 1, 1);
  double orientation = 0.0;
  for (int k = 0; k < ck; ++k) {
    for (int j = 0; j < cj; ++j) {
      for (int i = 0; i < ci; ++i) {
        double low = 1.0, high = -1.0;
        auto add = [&](double value) {
          low = std::min(low, value);
          high = std::max(high, value);
          orientation += value;
        };
        if (hexahedra) {
          Vec3 c[2][2][2];
          for (int n = 0; n < 8; ++n) {
            c[n & 1][(n >> 1) & 1][n >> 2] =
                At(block, i + (n & 1), j + ((n >> 1) & 1), k + (n >> 2));
          }
          for (int n = 0; n < 8; ++n) {
            const int x = n & 1, y = (n >> 1) & 1, z = n >> 2;
            add(Scaled3(Sub(c[1][y][z], c[0][y][z]), Sub(c[x][1][z], c[x][0][z]),
                        Sub(c[x][y][1], c[x][y][0])));
          }
        } else {
          const int index[3] = {i, j, k};
          auto point = [&](int da, int db) {
            int at[3] = {index[0], index[1], index[2]};
            at[a] += da;
            at[b] += db;
            return At(block, at[0], at[1], at[2]);
          };
          const Vec3 p00 = point(0, 0), p10 = point(1, 0), p01 = point(0, 1), p11 = point(1, 1);
          Vec3 normal = {0, 0, 1};
          if (block.spatial_dim() == 3) {
            normal = Cross(Sub(p11, p00), Sub(p01, p10));
            const double length = Norm(normal);
            if (length > 0) normal = {normal[0] / length, normal[1] / length, normal[2] / length};
          }
          // Edge pairs at corners 00, 10, 01, 11, along increasing a and b.
          add(Scaled2(Sub(p10, p00), Sub(p01, p00), normal));
          add(Scaled2(Sub(p10, p00), Sub(p11, p10), normal));
          add(Scaled2(Sub(p11, p01), Sub(p01, p00), normal));
          add(Scaled2(Sub(p11, p01), Sub(p11, p10), normal));
        }
        const int64_t cell = (int64_t{k} * cj + j) * ci + i;
        lowest[cell] = low;
        highest[cell] = high;
      }
    }
  }
  std::vector<double> quality(lowest.size());
  for (size_t c = 0; c < quality.size(); ++c) {
    quality[c] = orientation >= 0 ? lowest[c] : -highest[c];
  }
  return quality;
}

}  // namespace splinegrid
