// A fitted block (spline, point distribution, summary, report) <-> StoredBlockFit
// (archive_convert.h).
#include <array>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"
#include "proto/convert/archive_convert.h"
#include "proto/convert/archive_util.h"
#include "proto/convert/convert.h"

namespace splinegrid {
namespace {

using archive_internal::Annotate;
using archive_internal::CheckNonNegative;
using archive_internal::Invalid;

void EncodeKnotVector(const KnotVector& knots, v1::StoredKnotVector* out) {
  out->set_order(knots.order());
  out->mutable_knots()->Assign(knots.knots().begin(), knots.knots().end());
}

// A knot vector the kernel accepts, on the domain [0, 1] every spline of the kernel maps.
absl::StatusOr<KnotVector> ParseKnotVector(const v1::StoredKnotVector& stored,
                                           const std::string& field) {
  absl::StatusOr<KnotVector> knots =
      KnotVector::Create(stored.order(), {stored.knots().begin(), stored.knots().end()});
  if (!knots.ok()) return Annotate(knots.status(), field);
  if (knots->knot(0) != 0.0 || knots->knots().back() != 1.0) {
    return Invalid(field, ": the domain [", knots->knot(0), ", ", knots->knots().back(),
                   "] is not [0, 1]");
  }
  return knots;
}

void EncodeSpline(const TensorSpline& spline, v1::StoredSpline* out) {
  out->set_spatial_dim(spline.spatial_dim());
  for (int d = 0; d < 3; ++d) EncodeKnotVector(spline.knots(d), out->add_knots());
  out->mutable_control()->Assign(spline.control().begin(), spline.control().end());
}

absl::StatusOr<TensorSpline> ParseSpline(const v1::StoredSpline& stored, const std::string& field) {
  const int s = stored.spatial_dim();
  if (s != 2 && s != 3) return Invalid(field, ".spatial_dim = ", s, "; must be 2 or 3");
  if (stored.knots_size() != 3) {
    return Invalid(field, ".knots: ", stored.knots_size(), " knot vectors; exactly 3 are needed");
  }
  std::array<KnotVector, 3> knots;
  for (int d = 0; d < 3; ++d) {
    SG_ASSIGN_OR_RETURN(knots[d],
                        ParseKnotVector(stored.knots(d), absl::StrCat(field, ".knots[", d, "]")));
  }
  // The count check before TensorSpline::Create, whose product of three counts could overflow
  // for crafted knot vectors: grow the product only while it stays within the values given.
  const int64_t given = stored.control_size();
  int64_t expected = s;
  for (int d = 0; d < 3 && expected <= given; ++d) expected *= knots[d].num_controls();
  if (expected != given) {
    return Invalid(field, ".control: ", given, " coordinates; the knot vectors define ",
                   knots[0].num_controls(), " x ", knots[1].num_controls(), " x ",
                   knots[2].num_controls(), " control points of ", s, " coordinates");
  }
  absl::StatusOr<TensorSpline> spline =
      TensorSpline::Create(std::move(knots), s, {stored.control().begin(), stored.control().end()});
  if (!spline.ok()) return Annotate(spline.status(), field);
  return spline;
}

void EncodeDistribution(const PointDistribution& distribution, v1::StoredDistribution* out) {
  for (int d = 0; d < 3; ++d) {
    v1::StoredDistributionDirection* direction = out->add_directions();
    direction->mutable_params()->Assign(distribution.params(d).begin(),
                                        distribution.params(d).end());
    direction->mutable_breaks()->Assign(distribution.breaks(d).begin(),
                                        distribution.breaks(d).end());
  }
}

absl::StatusOr<PointDistribution> ParseDistribution(const v1::StoredDistribution& stored,
                                                    const std::string& field) {
  if (stored.directions_size() != 3) {
    return Invalid(field, ".directions: ", stored.directions_size(),
                   " directions; exactly 3 are needed");
  }
  std::array<std::vector<double>, 3> params;
  std::array<std::vector<int>, 3> breaks;
  for (int d = 0; d < 3; ++d) {
    params[d].assign(stored.directions(d).params().begin(), stored.directions(d).params().end());
    breaks[d].assign(stored.directions(d).breaks().begin(), stored.directions(d).breaks().end());
  }
  absl::StatusOr<PointDistribution> distribution =
      PointDistribution::Create(std::move(params), std::move(breaks));
  if (!distribution.ok()) return Annotate(distribution.status(), field);
  return distribution;
}

void EncodeSummary(const FitSummary& summary, v1::StoredFitSummary* out) {
  v1::StoredDeviation* deviation = out->mutable_deviation();
  deviation->set_max(summary.deviation.max);
  deviation->set_rms(summary.deviation.rms);
  EncodeExtents(summary.deviation.max_at, deviation->mutable_max_at());
  deviation->set_num_points(summary.deviation.num_points);
  deviation->set_max_ratio(summary.deviation.max_ratio);
  EncodeExtents(summary.deviation.max_ratio_at, deviation->mutable_max_ratio_at());
  out->set_num_points(summary.num_points);
  out->set_num_control_points(summary.num_control_points);
  out->set_compression_ratio(summary.compression_ratio);
  out->set_seconds(summary.seconds);
}

absl::StatusOr<FitSummary> ParseSummary(const v1::StoredFitSummary& stored,
                                        const std::string& field) {
  FitSummary summary;
  const v1::StoredDeviation& deviation = stored.deviation();
  summary.deviation.max = deviation.max();
  summary.deviation.rms = deviation.rms();
  summary.deviation.max_at = ParseExtents(deviation.max_at());
  summary.deviation.num_points = deviation.num_points();
  summary.deviation.max_ratio = deviation.max_ratio();
  summary.deviation.max_ratio_at = ParseExtents(deviation.max_ratio_at());
  summary.num_points = stored.num_points();
  summary.num_control_points = stored.num_control_points();
  summary.compression_ratio = stored.compression_ratio();
  summary.seconds = stored.seconds();
  SG_RETURN_IF_ERROR(
      CheckNonNegative(summary.deviation.num_points, field + ".deviation.num_points"));
  SG_RETURN_IF_ERROR(CheckNonNegative(summary.num_points, field + ".num_points"));
  SG_RETURN_IF_ERROR(CheckNonNegative(summary.num_control_points, field + ".num_control_points"));
  return summary;
}

void EncodeCellQuality(const CellQuality& quality, v1::StoredCellQuality* out) {
  out->set_cells_checked(quality.cells_checked);
  out->set_cells_skipped(quality.cells_skipped);
  out->set_folded(quality.folded);
  out->set_out_of_size(quality.out_of_size);
  out->set_min_ratio(quality.min_ratio);
  out->set_max_ratio(quality.max_ratio);
  EncodeExtents(quality.worst_cell, out->mutable_worst_cell());
  out->set_worst_level(quality.worst_level);
  out->set_num_bad_cells(quality.num_bad_cells);
  out->mutable_bad_cells()->Reserve(3 * static_cast<int>(quality.bad_cells.size()));
  for (const Extents& cell : quality.bad_cells) {
    for (int d = 0; d < 3; ++d) out->add_bad_cells(cell[d]);
  }
}

absl::StatusOr<CellQuality> ParseCellQuality(const v1::StoredCellQuality& stored,
                                             const std::string& field) {
  CellQuality quality;
  quality.cells_checked = stored.cells_checked();
  quality.cells_skipped = stored.cells_skipped();
  quality.folded = stored.folded();
  quality.out_of_size = stored.out_of_size();
  quality.min_ratio = stored.min_ratio();
  quality.max_ratio = stored.max_ratio();
  quality.worst_cell = ParseExtents(stored.worst_cell());
  quality.worst_level = stored.worst_level();
  quality.num_bad_cells = stored.num_bad_cells();
  SG_RETURN_IF_ERROR(CheckNonNegative(quality.cells_checked, field + ".cells_checked"));
  SG_RETURN_IF_ERROR(CheckNonNegative(quality.cells_skipped, field + ".cells_skipped"));
  SG_RETURN_IF_ERROR(CheckNonNegative(quality.folded, field + ".folded"));
  SG_RETURN_IF_ERROR(CheckNonNegative(quality.out_of_size, field + ".out_of_size"));
  SG_RETURN_IF_ERROR(CheckNonNegative(quality.num_bad_cells, field + ".num_bad_cells"));
  if (stored.bad_cells_size() % 3 != 0) {
    return Invalid(field, ".bad_cells: ", stored.bad_cells_size(),
                   " values are not whole (i, j, k) triples");
  }
  quality.bad_cells.resize(stored.bad_cells_size() / 3);  // sized by the data present
  for (size_t c = 0; c < quality.bad_cells.size(); ++c) {
    for (int d = 0; d < 3; ++d) quality.bad_cells[c][d] = stored.bad_cells(3 * c + d);
  }
  return quality;
}

}  // namespace

// ---- BlockFit ----

void EncodeBlockFit(const BlockFit& block, v1::StoredBlockFit* out) {
  EncodeSpline(block.fitted.spline, out->mutable_spline());
  EncodeDistribution(block.fitted.distribution, out->mutable_distribution());
  EncodeSummary(block.fitted.summary, out->mutable_summary());
  out->set_tolerance_met(block.tolerance_met);
  out->set_unmet_reason(block.unmet_reason);
  v1::StoredKindDeviation* deviation = out->mutable_deviation_by_kind();
  deviation->set_wall(block.deviation_by_kind.wall);
  deviation->set_interface(block.deviation_by_kind.interface);
  deviation->set_outer(block.deviation_by_kind.outer);
  deviation->set_interior(block.deviation_by_kind.interior);
  deviation->set_first_layer(block.deviation_by_kind.first_layer);
  EncodeCellQuality(block.quality, out->mutable_quality());
}

absl::StatusOr<BlockFit> ParseBlockFit(const v1::StoredBlockFit& stored, const std::string& field) {
  SG_ASSIGN_OR_RETURN(TensorSpline spline, ParseSpline(stored.spline(), field + ".spline"));
  SG_ASSIGN_OR_RETURN(PointDistribution distribution,
                      ParseDistribution(stored.distribution(), field + ".distribution"));
  SG_ASSIGN_OR_RETURN(FitSummary summary, ParseSummary(stored.summary(), field + ".summary"));
  BlockFit block;
  block.fitted = FittedBlock{std::move(spline), std::move(distribution), summary};
  block.tolerance_met = stored.tolerance_met();
  block.unmet_reason = stored.unmet_reason();
  const v1::StoredKindDeviation& deviation = stored.deviation_by_kind();
  block.deviation_by_kind = {deviation.wall(), deviation.interface(), deviation.outer(),
                             deviation.interior(),
                             deviation.has_first_layer() ? deviation.first_layer() : -1.0};
  SG_ASSIGN_OR_RETURN(block.quality, ParseCellQuality(stored.quality(), field + ".quality"));
  return block;
}

}  // namespace splinegrid
