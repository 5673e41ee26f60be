#include "core/fit/solve/direction_fit.h"

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

// OK for `params` (m >= 1, strictly increasing) and, without penalty rows, at least as many
// points as the n controls; else INVALID_ARGUMENT.
absl::Status ValidateData(std::span<const double> params, int n, bool no_penalties) {
  const int m = static_cast<int>(params.size());
  if (m < 1) return absl::InvalidArgumentError("no data points");
  if (no_penalties && m < n) {
    return absl::InvalidArgumentError(
        absl::StrCat(n, " control points cannot be fitted to ", m, " points"));
  }
  for (int i = 1; i < m; ++i) {
    if (!(params[i] > params[i - 1])) {
      return absl::InvalidArgumentError(absl::StrCat("parameters are not strictly increasing at ",
                                                     i, ": ", params[i - 1], ", ", params[i]));
    }
  }
  return absl::OkStatus();
}

// The data rows and the penalty rows over all controls, and the bandwidth they need.
struct MergedRows {
  std::vector<FullRow> rows;
  int bandwidth = 0;
};

// Data rows come with non-decreasing first columns (sorted parameters); penalty rows are
// merged in by their first column. INVALID_ARGUMENT for a penalty row outside the n controls.
absl::StatusOr<MergedRows> MergeRows(const SampledBasis& basis,
                                     std::span<const PenaltyRow> penalties, int n) {
  const int m = basis.num_samples(), k = basis.order;
  MergedRows merged;
  merged.bandwidth = k;
  std::vector<const PenaltyRow*> sorted_penalties;
  sorted_penalties.reserve(penalties.size());
  for (const PenaltyRow& p : penalties) {
    const int size = static_cast<int>(p.values.size());
    if (p.first < 0 || size < 1 || p.first + size > n) {
      return absl::InvalidArgumentError(absl::StrCat("penalty row at column ", p.first, " with ",
                                                     size, " entries exceeds ", n, " controls"));
    }
    sorted_penalties.push_back(&p);
    merged.bandwidth = std::max(merged.bandwidth, size);
  }
  std::stable_sort(sorted_penalties.begin(), sorted_penalties.end(),
                   [](const PenaltyRow* x, const PenaltyRow* y) { return x->first < y->first; });
  std::vector<FullRow>& full = merged.rows;
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
  return merged;
}

}  // namespace

bool SchoenbergWhitneyHolds(const KnotVector& knots, std::span<const double> params,
                            std::span<const int> pinned_controls) {
  const int n = knots.num_controls(), k = knots.order(), m = static_cast<int>(params.size());
  std::vector<bool> pinned(n, false);
  for (int c : pinned_controls) {
    if (c >= 0 && c < n) pinned[c] = true;
  }
  const std::span<const double> t = knots.knots();
  int r = 0;  // next unused data point
  for (int j = 0; j < n; ++j) {
    if (pinned[j]) continue;
    // Support of N_j: (t_j, t_{j+k}), closed at a clamped end where N_j is 1.
    const double lo = t[j], hi = t[j + k];
    const bool closed_lo = j == 0, closed_hi = j == n - 1;
    while (r < m && (params[r] < lo || (params[r] == lo && !closed_lo))) ++r;
    if (r == m || params[r] > hi || (params[r] == hi && !closed_hi)) return false;
    ++r;
  }
  return true;
}

absl::StatusOr<DirectionFit> DirectionFit::Create(const KnotVector& knots,
                                                  std::span<const double> params, EndCondition ends,
                                                  std::span<const Pin> interior_pins,
                                                  std::span<const PenaltyRow> penalties) {
  const int m = static_cast<int>(params.size());
  const int n = knots.num_controls();
  const int k = knots.order();
  SG_RETURN_IF_ERROR(ValidateData(params, n, penalties.empty()));
  if (n < 2) ends = EndCondition::kFree;
  DirectionFit fit;
  fit.num_points_ = m;
  fit.num_controls_ = n;
  fit.zero_pins_ = ends == EndCondition::kZero;
  SG_ASSIGN_OR_RETURN(const std::vector<int> pin_of, fit.PinControls(ends, interior_pins));
  const std::vector<int> free_index = fit.SetFreeColumns(pin_of);
  const int n_free = static_cast<int>(fit.free_columns_.size());

  const SampledBasis basis = SampleBasis(knots, params, 0);
  SG_ASSIGN_OR_RETURN(const MergedRows full, MergeRows(basis, penalties, n));
  // Split every row into its free part (contiguous in free-index space, because pinned
  // columns are simply left out) and its pinned terms.
  fit.qr_ = BandedQR(n_free, full.bandwidth, static_cast<int>(full.rows.size()));
  fit.rows_.reserve(full.rows.size());
  std::vector<double> free_values(full.bandwidth);
  for (const FullRow& row : full.rows) {
    fit.AddSplitRow(row.first, std::span<const double>(row.values, row.size), row.data_row, pin_of,
                    free_index, free_values);
  }
  if (n_free > 0) {
    if (absl::Status rank = fit.qr_.CheckRank(); !rank.ok()) {
      return absl::FailedPreconditionError(
          absl::StrCat(rank.message(), " (", n, " controls of order ", k, " for ", m, " points)"));
    }
  }
  return fit;
}

absl::StatusOr<std::vector<int>> DirectionFit::PinControls(EndCondition ends,
                                                           std::span<const Pin> interior_pins) {
  const int m = num_points_, n = num_controls_;
  std::vector<int> pin_of(n, -1);  // control -> pin index
  auto add_pin = [&](Pin pin) -> absl::Status {
    if (pin.control < 0 || pin.control >= n || pin.data_row < 0 || pin.data_row >= m ||
        pin_of[pin.control] >= 0) {
      return absl::InvalidArgumentError(absl::StrCat("pin of control ", pin.control,
                                                     " to data row ", pin.data_row,
                                                     " is out of range or repeated"));
    }
    pin_of[pin.control] = static_cast<int>(pins_.size());
    pins_.push_back(pin);
    return absl::OkStatus();
  };
  if (ends != EndCondition::kFree) {
    SG_RETURN_IF_ERROR(add_pin({0, 0}));
    SG_RETURN_IF_ERROR(add_pin({n - 1, m - 1}));
  }
  for (const Pin& pin : interior_pins) SG_RETURN_IF_ERROR(add_pin(pin));
  return pin_of;
}

std::vector<int> DirectionFit::SetFreeColumns(const std::vector<int>& pin_of) {
  std::vector<int> free_index(num_controls_, -1);
  for (int col = 0; col < num_controls_; ++col) {
    if (pin_of[col] < 0) {
      free_index[col] = static_cast<int>(free_columns_.size());
      free_columns_.push_back(col);
    }
  }
  return free_index;
}

void DirectionFit::AddSplitRow(int first, std::span<const double> values, int data_row,
                               const std::vector<int>& pin_of, const std::vector<int>& free_index,
                               std::vector<double>& free_values) {
  RowSource source{data_row, static_cast<int>(pinned_terms_.size()), 0};
  int first_free = -1, count = 0;
  bool any = false;
  for (int t = 0; t < static_cast<int>(values.size()); ++t) {
    const int col = first + t;
    if (pin_of[col] >= 0) {
      if (values[t] != 0.0) pinned_terms_.push_back({pin_of[col], values[t]});
      continue;
    }
    if (first_free < 0) first_free = free_index[col];
    free_values[count++] = values[t];
    any |= values[t] != 0.0;
  }
  source.pinned_end = static_cast<int>(pinned_terms_.size());
  if (!any) {
    pinned_terms_.resize(source.pinned_begin);  // the row constrains nothing free
    return;
  }
  qr_.AddRow(first_free, std::span<const double>(free_values.data(), count));
  rows_.push_back(source);
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
  // v, one row per pin, accumulator.
  std::vector<double> scratch((n_free + 1 + pins_.size()) * width);
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
  const int num_pins = static_cast<int>(pins_.size());
  // When the block lies inside one slab e (a long contiguous run) and the free controls are
  // consecutive (no interior pins), data rows are read in place and the accumulator is the
  // output itself: nothing is copied.
  const int off = n_free > 0 ? free_columns_.front() : 0;
  const bool consecutive = n_free == 0 || free_columns_.back() - off == n_free - 1;
  const bool in_place = q0 / a == (q1 - 1) / a && width >= 16 && consecutive;
  const int64_t e = q0 / a, c = q0 % a;
  const double* in_slab = in + c + a * m * e;
  double* out_slab = out + c + a * n * e;
  double* v = scratch.data();
  double* pin_values = v + width;  // num_pins rows
  double* acc = in_place ? out_slab + off * a : pin_values + num_pins * width;
  const int64_t stride = in_place ? a : width;
  for (int j = 0; j < n_free; ++j) std::fill_n(acc + j * stride, width, 0.0);
  for (int p = 0; p < num_pins; ++p) {
    double* value = pin_values + p * width;
    if (zero_pins_) {
      std::fill_n(value, width, 0.0);
    } else {
      GatherRow(in, a, m, pins_[p].data_row, q0, q1, value);
    }
  }
  for (int i = 0; i < static_cast<int>(rows_.size()); ++i) {
    const RowSource& row = rows_[i];
    const double* rhs = v;
    const bool corrected = !zero_pins_ && row.pinned_end > row.pinned_begin;
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
      for (int t = row.pinned_begin; t < row.pinned_end; ++t) {
        const double coef = pinned_terms_[t].coef;
        const double* value = pin_values + pinned_terms_[t].pin * width;
        for (int64_t x = 0; x < width; ++x) v[x] -= coef * value[x];
      }
    }
    qr_.ReduceRow(i, rhs, acc, width, stride);
  }
  qr_.BackSubstitute(acc, width, stride);
  if (!in_place) {
    for (int j = 0; j < n_free; ++j) {
      ScatterRow(acc + j * width, a, n, free_columns_[j], q0, q1, out);
    }
  }
  for (int p = 0; p < num_pins; ++p) {
    ScatterRow(pin_values + p * width, a, n, pins_[p].control, q0, q1, out);
  }
}

}  // namespace splinegrid
