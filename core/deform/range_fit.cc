#include "core/deform/range_fit.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace splinegrid {
namespace {

// A B-spline value this close to 1 at a sample makes it the only one there (partition of unity).
constexpr double kPinnedValue = 1.0 - 1e-12;

}  // namespace

absl::StatusOr<RangeFit> RangeFit::Create(const KnotVector& knots,
                                          std::span<const double> samples) {
  if (samples.size() < 2) {
    return absl::InvalidArgumentError(
        absl::StrCat(samples.size(), " samples; a range needs at least 2"));
  }
  for (size_t s = 1; s < samples.size(); ++s) {
    if (!(samples[s] > samples[s - 1])) {
      return absl::InvalidArgumentError(absl::StrCat("samples are not increasing at ", s, ": ",
                                                     samples[s - 1], ", ", samples[s]));
    }
  }
  RangeFit fit;
  fit.basis_ = SampleBasis(knots, samples, 0);
  const int k = knots.order();
  const int num = fit.basis_.num_samples();
  fit.first_ = knots.num_controls();
  fit.last_ = -1;
  for (int s = 0; s < num; ++s) {
    const double* row = fit.basis_.Row(s);
    for (int t = 0; t < k; ++t) {
      if (row[t] == 0.0) continue;
      fit.first_ = std::min(fit.first_, fit.basis_.first[s] + t);
      fit.last_ = std::max(fit.last_, fit.basis_.first[s] + t);
    }
  }
  auto value = [&](int s, int control) {
    const int t = control - fit.basis_.first[s];
    return t >= 0 && t < k ? fit.basis_.Row(s)[t] : 0.0;
  };
  fit.pin_first_ = value(0, fit.first_) > kPinnedValue;
  fit.pin_last_ = fit.last_ > fit.first_ && value(num - 1, fit.last_) > kPinnedValue;
  const int free_first = fit.first_ + (fit.pin_first_ ? 1 : 0);
  const int free_last = fit.last_ - (fit.pin_last_ ? 1 : 0);
  const int num_free = free_last - free_first + 1;
  if (num_free <= 0) return fit;
  fit.qr_ = BandedQR(num_free, k, num);
  std::vector<double> values(k);
  for (int s = 0; s < num; ++s) {
    int lo = -1, count = 0;
    for (int t = 0; t < k; ++t) {
      const int c = fit.basis_.first[s] + t;
      if (c < free_first || c > free_last) continue;
      if (lo < 0) lo = c - free_first;
      values[count++] = fit.basis_.Row(s)[t];
    }
    if (count == 0) continue;
    fit.qr_.AddRow(lo, std::span<const double>(values.data(), count));
    fit.rows_.push_back(s);
  }
  if (absl::Status rank = fit.qr_.CheckRank(); !rank.ok()) {
    return absl::FailedPreconditionError(
        absl::StrCat("the ", num, " samples do not determine controls ", fit.first_, "..",
                     fit.last_, ": ", rank.message()));
  }
  return fit;
}

void RangeFit::Apply(const double* in, int64_t width, double* out) const {
  const int k = basis_.order;
  const int num = basis_.num_samples();
  const int n = num_controls();
  if (pin_first_) std::copy(in, in + width, out);
  if (pin_last_) std::copy(in + (num - 1) * width, in + num * width, out + (n - 1) * width);
  const int free_first = first_ + (pin_first_ ? 1 : 0);
  const int free_last = last_ - (pin_last_ ? 1 : 0);
  const int num_free = free_last - free_first + 1;
  if (num_free <= 0) return;
  // Right-hand sides: the samples minus the pinned controls' share.
  std::vector<double> acc(static_cast<size_t>(num_free) * width, 0.0), v(width);
  for (size_t q = 0; q < rows_.size(); ++q) {
    const int s = rows_[q];
    std::copy(in + s * width, in + (s + 1) * width, v.begin());
    for (int t = 0; t < k; ++t) {
      const int c = basis_.first[s] + t;
      const double b = basis_.Row(s)[t];
      if (b == 0.0) continue;
      const double* pinned = nullptr;
      if (pin_first_ && c == first_) pinned = out;
      if (pin_last_ && c == last_) pinned = out + (n - 1) * width;
      if (pinned == nullptr) continue;
      for (int64_t x = 0; x < width; ++x) v[x] -= b * pinned[x];
    }
    qr_.ReduceRow(static_cast<int>(q), v.data(), acc.data(), width, width);
  }
  qr_.BackSubstitute(acc.data(), width, width);
  std::copy(acc.begin(), acc.end(), out + (free_first - first_) * width);
}

}  // namespace splinegrid
