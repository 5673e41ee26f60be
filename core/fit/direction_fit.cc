#include "core/fit/direction_fit.h"

#include <algorithm>
#include <cstring>

#include "absl/strings/str_cat.h"
#include "core/bspline/basis.h"
#include "core/util/check.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

// A row over all n controls before the fixed ends are split off.
struct FullRow {
  int first;
  const double* values;
  int size;
  int data_row;
};

// Row r of an (a, rows, b) tensor restricted to the columns [q0, q1), column q = c + a e, is
// made of runs that are contiguous in memory; `copy(tensor_run, buffer_run, length)` is called
// on each of them.
template <typename Copy>
void ForEachRun(int64_t a, int64_t rows, int64_t r, int64_t q0, int64_t q1, Copy copy) {
  int64_t q = q0;
  while (q < q1) {
    const int64_t e = q / a, c = q % a;
    const int64_t run = std::min(a - c, q1 - q);
    copy(c + a * (r + rows * e), q - q0, run);
    q += run;
  }
}

// buffer = row r of `tensor` on columns [q0, q1).
void GatherRow(const double* tensor, int64_t a, int64_t rows, int64_t r, int64_t q0, int64_t q1,
               double* buffer) {
  if (a < 16) {  // short runs (the first direction: a = coordinates): plain loops beat memcpy
    for (int64_t q = q0; q < q1;) {
      const double* t = tensor + a * (r + rows * (q / a));
      for (int64_t c = q % a; c < a && q < q1; ++c, ++q) buffer[q - q0] = t[c];
    }
    return;
  }
  ForEachRun(a, rows, r, q0, q1, [&](int64_t t, int64_t x, int64_t run) {
    std::memcpy(buffer + x, tensor + t, run * sizeof(double));
  });
}

// Row r of `tensor` on columns [q0, q1) = buffer.
void ScatterRow(const double* buffer, int64_t a, int64_t rows, int64_t r, int64_t q0, int64_t q1,
                double* tensor) {
  if (a < 16) {
    for (int64_t q = q0; q < q1;) {
      double* t = tensor + a * (r + rows * (q / a));
      for (int64_t c = q % a; c < a && q < q1; ++c, ++q) t[c] = buffer[q - q0];
    }
    return;
  }
  ForEachRun(a, rows, r, q0, q1, [&](int64_t t, int64_t x, int64_t run) {
    std::memcpy(tensor + t, buffer + x, run * sizeof(double));
  });
}

}  // namespace

absl::StatusOr<DirectionFit> DirectionFit::Create(const KnotVector& knots,
                                                  std::span<const double> params, EndCondition ends,
                                                  std::span<const PenaltyRow> penalties) {
  const int m = static_cast<int>(params.size());
  const int n = knots.num_controls();
  const int k = knots.order();
  if (m < 1) return absl::InvalidArgumentError("no data points");
  if (n < 2) ends = EndCondition::kFree;
  if (penalties.empty() && m < n) {
    return absl::InvalidArgumentError(
        absl::StrCat(n, " control points cannot be fitted to ", m, " points"));
  }
  for (int i = 1; i < m; ++i) {
    if (!(params[i] > params[i - 1])) {
      return absl::InvalidArgumentError(absl::StrCat("parameters are not strictly increasing at ",
                                                     i, ": ", params[i - 1], ", ", params[i]));
    }
  }
  const SampledBasis basis = SampleBasis(knots, params, 0);

  // Data rows come with non-decreasing first columns (sorted parameters); penalty rows are
  // merged in by their first column.
  int bandwidth = k;
  std::vector<const PenaltyRow*> sorted_penalties;
  sorted_penalties.reserve(penalties.size());
  for (const PenaltyRow& p : penalties) {
    const int size = static_cast<int>(p.values.size());
    if (p.first < 0 || size < 1 || p.first + size > n) {
      return absl::InvalidArgumentError(absl::StrCat("penalty row at column ", p.first, " with ",
                                                     size, " entries exceeds ", n, " controls"));
    }
    sorted_penalties.push_back(&p);
    bandwidth = std::max(bandwidth, size);
  }
  std::stable_sort(sorted_penalties.begin(), sorted_penalties.end(),
                   [](const PenaltyRow* x, const PenaltyRow* y) { return x->first < y->first; });
  std::vector<FullRow> full;
  full.reserve(m + penalties.size());
  for (int r = 0, q = 0; r < m || q < static_cast<int>(sorted_penalties.size());) {
    if (q < static_cast<int>(sorted_penalties.size()) &&
        (r == m || sorted_penalties[q]->first < basis.first[r])) {
      const PenaltyRow& p = *sorted_penalties[q++];
      full.push_back({p.first, p.values.data(), static_cast<int>(p.values.size()), -1});
    } else {
      full.push_back({basis.first[r], basis.Row(r), k, r});
      ++r;
    }
  }

  const int off = ends == EndCondition::kFree ? 0 : 1;
  const int n_free = n - 2 * off;
  BandedQR qr(n_free, bandwidth, static_cast<int>(full.size()));
  std::vector<RowSource> rows;
  rows.reserve(full.size());
  std::vector<double> free_values(bandwidth);
  for (const FullRow& row : full) {
    RowSource source{row.data_row};
    const int last = row.first + row.size - 1;
    if (off == 1) {
      if (row.first == 0) source.first_coef = row.values[0];
      if (last == n - 1) source.last_coef = row.values[row.size - 1];
    }
    const int lo = std::max(row.first, off), hi = std::min(last, n - 1 - off);
    if (lo > hi) continue;
    bool any = false;
    for (int col = lo; col <= hi; ++col) {
      free_values[col - lo] = row.values[col - row.first];
      any |= free_values[col - lo] != 0.0;
    }
    if (!any) continue;
    qr.AddRow(lo - off, std::span<const double>(free_values.data(), hi - lo + 1));
    rows.push_back(source);
  }
  if (n_free > 0) {
    if (absl::Status rank = qr.CheckRank(); !rank.ok()) {
      return absl::FailedPreconditionError(
          absl::StrCat(rank.message(), " (", n, " controls of order ", k, " for ", m, " points)"));
    }
  }
  return DirectionFit(m, n, ends, std::move(qr), std::move(rows));
}

absl::Status DirectionFit::Apply(const double* in, int64_t a, int64_t b, double* out,
                                 const CancelCheck& cancel) const {
  const int64_t columns = a * b;
  if (num_points_ == 1 && num_controls_ == 1) {
    std::memcpy(out, in, columns * sizeof(double));
    return absl::OkStatus();
  }
  // Keep the accumulator (free controls x width) around 128 KiB so it stays in L2.
  const int64_t n_free = std::max(qr_.num_cols(), 1);
  const int64_t width = std::min(std::clamp<int64_t>((16384 / n_free) / 8 * 8, 8, 1024), columns);
  std::vector<double> scratch((n_free + 3) * width);  // v, ends, accumulator
  if (a >= width) {
    // Blocks inside one slab: rows are contiguous runs (see ApplyBlock).
    for (int64_t e = 0; e < b; ++e) {
      for (int64_t c = 0; c < a; c += width) {
        SG_RETURN_IF_ERROR(PollCancel(cancel));
        ApplyBlock(in, a, e * a + c, e * a + std::min(c + width, a), out, scratch);
      }
    }
  } else {
    // Blocks of whole lines.
    const int64_t lines = width / a;
    for (int64_t e = 0; e < b; e += lines) {
      SG_RETURN_IF_ERROR(PollCancel(cancel));
      ApplyBlock(in, a, e * a, std::min(e + lines, b) * a, out, scratch);
    }
  }
  return absl::OkStatus();
}

void DirectionFit::ApplyBlock(const double* in, int64_t a, int64_t q0, int64_t q1, double* out,
                              std::vector<double>& scratch) const {
  const int64_t width = q1 - q0;
  const int m = num_points_, n = num_controls_;
  const int n_free = qr_.num_cols();
  const int off = ends_ == EndCondition::kFree ? 0 : 1;
  // When the block lies inside one slab e (a long contiguous run), data rows are read in place
  // and the accumulator is the output itself (rows off .. off + n_free - 1): nothing is copied.
  const bool in_place = q0 / a == (q1 - 1) / a && width >= 16;
  const int64_t e = q0 / a, c = q0 % a;
  const double* in_slab = in + c + a * m * e;
  double* out_slab = out + c + a * n * e;
  double* v = scratch.data();
  double* first = v + width;
  double* last = first + width;
  double* acc = in_place ? out_slab + off * a : last + width;
  const int64_t stride = in_place ? a : width;
  for (int j = 0; j < n_free; ++j) std::fill_n(acc + j * stride, width, 0.0);
  if (ends_ == EndCondition::kInterpolate) {
    GatherRow(in, a, m, 0, q0, q1, first);
    GatherRow(in, a, m, m - 1, q0, q1, last);
  } else {
    std::fill_n(first, width, 0.0);
    std::fill_n(last, width, 0.0);
  }
  for (int i = 0; i < static_cast<int>(rows_.size()); ++i) {
    const RowSource& row = rows_[i];
    const double* rhs = v;
    const bool corrected =
        ends_ == EndCondition::kInterpolate && (row.first_coef != 0.0 || row.last_coef != 0.0);
    if (row.data_row < 0) {
      std::fill_n(v, width, 0.0);
    } else if (in_place && !corrected) {
      rhs = in_slab + a * row.data_row;
      // The next data row is a separate stream far away in memory: fetch it while this one is
      // rotated (the hardware prefetcher does not cross into it on its own).
      if (i + 1 < static_cast<int>(rows_.size()) && rows_[i + 1].data_row >= 0) {
        const double* next = in_slab + a * rows_[i + 1].data_row;
        for (int64_t x = 0; x < width; x += 8) __builtin_prefetch(next + x);
      }
    } else {
      GatherRow(in, a, m, row.data_row, q0, q1, v);
    }
    if (corrected) {
      for (int64_t x = 0; x < width; ++x) {
        v[x] -= row.first_coef * first[x] + row.last_coef * last[x];
      }
    }
    qr_.ReduceRow(i, rhs, acc, width, stride);
  }
  qr_.BackSubstitute(acc, width, stride);
  if (!in_place) {
    for (int j = 0; j < n_free; ++j) ScatterRow(acc + j * width, a, n, j + off, q0, q1, out);
  }
  if (off == 1) {
    ScatterRow(first, a, n, 0, q0, q1, out);
    ScatterRow(last, a, n, n - 1, q0, q1, out);
  }
}

}  // namespace splinegrid
