#include "core/bspline/parametrization.h"

#include <cmath>
#include <memory>

#include "absl/strings/str_cat.h"
#include "core/util/check.h"

namespace splinegrid {

std::string_view ParametrizationName(Parametrization p) {
  switch (p) {
    case Parametrization::kUniform:
      return "uniform";
    case Parametrization::kChordLength:
      return "chord_length";
    case Parametrization::kCentripetal:
      return "centripetal";
  }
  return "unknown";
}

absl::Status ValidateParametrization(Parametrization p) {
  switch (p) {
    case Parametrization::kUniform:
    case Parametrization::kChordLength:
    case Parametrization::kCentripetal:
      return absl::OkStatus();
  }
  return absl::InvalidArgumentError(
      absl::StrCat("parametrization = ", static_cast<int>(p), " is not a known value"));
}

namespace {

// The increment of one segment for a squared chord length d2.
template <Parametrization P>
inline double Increment(double d2) {
  if constexpr (P == Parametrization::kCentripetal) {
    return std::sqrt(std::sqrt(d2));
  } else {
    return std::sqrt(d2);
  }
}

// A row of points with each coordinate in its own contiguous array (structure of arrays), so
// that distances between neighbours vectorise without shuffling interleaved coordinates.
template <int S>
struct RowSoA {
  std::array<std::vector<double>, S> x;
  void Load(const double* points, int64_t count) {
    for (int c = 0; c < S; ++c) {
      x[c].resize(count);
      double* out = x[c].data();
      for (int64_t i = 0; i < count; ++i) out[i] = points[S * i + c];
    }
  }
};

// out[i] = Increment(|b_i - a_i|^2) for i < count, points of rows a and b from the given
// offsets.
template <int S, Parametrization P>
void SegmentIncrements(const RowSoA<S>& a, int64_t a_offset, const RowSoA<S>& b, int64_t b_offset,
                       int64_t count, double* __restrict out) {
  const double* pa[S];
  const double* pb[S];
  for (int c = 0; c < S; ++c) {
    pa[c] = a.x[c].data() + a_offset;
    pb[c] = b.x[c].data() + b_offset;
  }
  for (int64_t i = 0; i < count; ++i) {
    double d2 = 0.0;
    for (int c = 0; c < S; ++c) d2 += (pb[c][i] - pa[c][i]) * (pb[c][i] - pa[c][i]);
    out[i] = Increment<P>(d2);
  }
}

// sum_x a[x] * b[x] (b == nullptr: sum_x a[x]) with eight independent partial sums, so that
// the loop vectorises instead of waiting on one chain of dependent additions.
double Dot(const double* a, const double* b, int64_t n) {
  double partial[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  int64_t x = 0;
  for (; x + 8 <= n; x += 8) {
    for (int t = 0; t < 8; ++t) partial[t] += b ? a[x + t] * b[x + t] : a[x + t];
  }
  double sum = 0.0;
  for (; x < n; ++x) sum += b ? a[x] * b[x] : a[x];
  for (double p : partial) sum += p;
  return sum;
}

// Sum over lines of normalised increments, and the number of lines that took part.
struct LineAverage {
  std::vector<double> sum;
  int64_t lines = 0;
};

// 1 / length, or 0 for a collapsed (or non-finite) line, which then takes no part.
inline double InverseLength(double length) {
  return length > 0.0 && std::isfinite(length) ? 1.0 / length : 0.0;
}

// One sweep over the points, row by row, computes the increments of all three directions:
//  - i: each grid row is a whole line, normalised at once;
//  - j: a k-plane holds whole j-lines; their increments wait for the end of the plane;
//  - k: lines span the block; their increments wait for the end of the block.
// Every row is read once, into coordinate arrays (RowSoA); the last row read at each j is kept,
// so that a row's j-neighbour (the row before it in this plane) and its k-neighbour (the same
// row of the previous plane) are at hand without reading the points again (reading them twice,
// interleaved, took 10% longer at 128^3).
// Memory beyond the input: one plane of points (two rows for surfaces), the j-increments of one
// plane and the k-increments of the block (a third of the input for volumes).
template <int S, Parametrization P>
std::array<LineAverage, 3> SweepIncrements(const StructuredBlock& block) {
  const Extents& n = block.extents();
  const int64_t ni = n[0], nj = n[1], nk = n[2], plane = ni * nj;
  std::array<LineAverage, 3> avg;
  for (int d = 0; d < 3; ++d) avg[d].sum.assign(n[d] - 1, 0.0);
  // Fully written before read: left uninitialised (no memset of a third of the input).
  std::unique_ptr<double[]> plane_j(new double[(nj - 1) * ni]);
  std::unique_ptr<double[]> inc_k(new double[(nk - 1) * plane]);
  std::vector<double> inc_i(ni), length_j(ni), length_k(nk > 1 ? plane : 0, 0.0);
  const double* coords = block.coords().data();
  // last[slot(j)]: row j of the current plane once read, else of the previous plane. A surface
  // needs only the previous row.
  auto slot = [nk](int64_t j) { return nk > 1 ? j : j % 2; };
  std::vector<RowSoA<S>> last(nk > 1 ? nj : 2);
  RowSoA<S> row;
  for (int64_t k = 0; k < nk; ++k) {
    std::fill(length_j.begin(), length_j.end(), 0.0);
    for (int64_t j = 0; j < nj; ++j) {
      row.Load(coords + S * (plane * k + ni * j), ni);
      if (ni > 1) {
        SegmentIncrements<S, P>(row, 0, row, 1, ni - 1, inc_i.data());
        if (const double inv = InverseLength(Dot(inc_i.data(), nullptr, ni - 1)); inv > 0.0) {
          for (int64_t i = 0; i + 1 < ni; ++i) avg[0].sum[i] += inc_i[i] * inv;
          ++avg[0].lines;
        }
      }
      if (j > 0) {
        double* inc = plane_j.get() + ni * (j - 1);
        SegmentIncrements<S, P>(last[slot(j - 1)], 0, row, 0, ni, inc);
        for (int64_t i = 0; i < ni; ++i) length_j[i] += inc[i];
      }
      if (k > 0) {
        double* inc = inc_k.get() + plane * (k - 1) + ni * j;
        SegmentIncrements<S, P>(last[j], 0, row, 0, ni, inc);
        double* length = length_k.data() + ni * j;
        for (int64_t i = 0; i < ni; ++i) length[i] += inc[i];
      }
      std::swap(last[slot(j)], row);
    }
    if (nj > 1) {
      for (double& len : length_j) {
        len = InverseLength(len);
        avg[1].lines += len > 0.0 ? 1 : 0;
      }
      for (int64_t j = 0; j + 1 < nj; ++j) {
        avg[1].sum[j] += Dot(plane_j.get() + ni * j, length_j.data(), ni);
      }
    }
  }
  if (nk > 1) {
    for (double& len : length_k) {
      len = InverseLength(len);
      avg[2].lines += len > 0.0 ? 1 : 0;
    }
    for (int64_t k = 0; k + 1 < nk; ++k) {
      avg[2].sum[k] = Dot(inc_k.get() + plane * k, length_k.data(), plane);
    }
  }
  return avg;
}

// Parameters from summed normalised increments (uniform when no line took part).
std::vector<double> ParametersFromIncrements(const LineAverage& avg) {
  const int m = static_cast<int>(avg.sum.size()) + 1;
  std::vector<double> params(m, 0.0);
  if (m == 1) return params;
  std::vector<double> increments = avg.sum;
  for (double& inc : increments) inc = avg.lines == 0 ? 1.0 / (m - 1) : inc / avg.lines;
  // Repeated points on every line leave an increment of exactly zero; give such intervals a
  // millionth of a uniform step so that parameters stay strictly increasing.
  double total = 0.0;
  for (double& inc : increments) {
    if (!(inc > 0.0)) inc = 1e-6 / (m - 1);
    total += inc;
  }
  for (int i = 1; i < m; ++i) params[i] = params[i - 1] + increments[i - 1] / total;
  params[m - 1] = 1.0;
  return params;
}

}  // namespace

std::array<std::vector<double>, 3> ParametrizeBlock(const StructuredBlock& block,
                                                    Parametrization parametrization) {
  std::array<LineAverage, 3> avg;
  const bool planar = block.spatial_dim() == 2;
  switch (parametrization) {
    case Parametrization::kUniform:
      for (int d = 0; d < 3; ++d) avg[d].sum.assign(block.extent(d) - 1, 0.0);
      break;
    case Parametrization::kChordLength:
      avg = planar ? SweepIncrements<2, Parametrization::kChordLength>(block)
                   : SweepIncrements<3, Parametrization::kChordLength>(block);
      break;
    case Parametrization::kCentripetal:
      avg = planar ? SweepIncrements<2, Parametrization::kCentripetal>(block)
                   : SweepIncrements<3, Parametrization::kCentripetal>(block);
      break;
  }
  return {ParametersFromIncrements(avg[0]), ParametersFromIncrements(avg[1]),
          ParametersFromIncrements(avg[2])};
}

std::vector<double> ParametrizeLines(const StructuredBlock& block, int d,
                                     const std::vector<Extents>& lines,
                                     Parametrization parametrization) {
  const int m = block.extent(d);
  LineAverage avg;
  avg.sum.assign(m - 1, 0.0);
  std::vector<double> inc(m > 1 ? m - 1 : 0);
  const int s = block.spatial_dim();
  for (Extents at : lines) {
    double length = 0.0;
    for (int t = 0; t + 1 < m; ++t) {
      at[d] = t;
      const double* a = block.Point(at[0], at[1], at[2]);
      const double* b = a + s * (d == 0   ? 1
                                 : d == 1 ? int64_t{block.extent(0)}
                                          : int64_t{block.extent(0)} * block.extent(1));
      double d2 = 0.0;
      for (int c = 0; c < s; ++c) d2 += (b[c] - a[c]) * (b[c] - a[c]);
      switch (parametrization) {
        case Parametrization::kUniform:
          inc[t] = 1.0;
          break;
        case Parametrization::kChordLength:
          inc[t] = Increment<Parametrization::kChordLength>(d2);
          break;
        case Parametrization::kCentripetal:
          inc[t] = Increment<Parametrization::kCentripetal>(d2);
          break;
      }
      length += inc[t];
    }
    const double inv = InverseLength(length);
    if (inv == 0.0) continue;
    for (int t = 0; t + 1 < m; ++t) avg.sum[t] += inc[t] * inv;
    ++avg.lines;
  }
  if (avg.lines == 0) return ParametrizeBlock(block, parametrization)[d];
  return ParametersFromIncrements(avg);
}

}  // namespace splinegrid
