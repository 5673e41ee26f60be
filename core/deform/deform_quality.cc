#include "core/deform/deform_quality.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/bspline/evaluation.h"
#include "core/fit/report/grid_quality.h"
#include "core/fit/report/wall_curvature.h"
#include "core/grid/sampling.h"
#include "core/util/status_macros.h"

namespace splinegrid {
namespace {

constexpr double kDegrees = 180.0 / 3.14159265358979323846;

// The angle in degrees between the partial derivatives along directions d and e at uvw.
double LineAngle(const TensorSpline& spline, const Point3& uvw, int d, int e) {
  const PartialDerivatives ders = EvaluateDerivatives(spline, uvw, 1);
  const Extents du = {d == 0, d == 1, d == 2};
  const Extents de = {e == 0, e == 1, e == 2};
  const Point3& t = ders(du[0], du[1], du[2]);
  const Point3& n = ders(de[0], de[1], de[2]);
  const double tt = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
  const double nn = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!(tt > 0.0 && nn > 0.0)) return 90.0;
  const double c = std::abs(t[0] * n[0] + t[1] * n[1] + t[2] * n[2]) / (tt * nn);
  return std::acos(std::min(c, 1.0)) * kDegrees;
}

}  // namespace

absl::StatusOr<DeformationGate> DeformationGate::Create(const std::vector<FittedBlock>& reference,
                                                        const BoundaryKinds& kinds, int level,
                                                        const CancelCheck& cancel) {
  if (level < 0 || level > kMaxRefinementLevel) {
    return absl::InvalidArgumentError(
        absl::StrCat("level = ", level, " is outside [0, ", kMaxRefinementLevel, "]"));
  }
  DeformationGate gate;
  gate.level_ = level;
  // The reference at the level: deformed cells are compared with its cells.
  for (size_t b = 0; b < reference.size(); ++b) {
    SG_RETURN_IF_ERROR(PollCancel(cancel));
    std::array<std::vector<double>, 3> params;
    for (int d = 0; d < 3; ++d) {
      const int m = reference[b].distribution.num_points(d);
      params[d] = reference[b].distribution.Refined(d, 0, m - 1, level);
    }
    SG_ASSIGN_OR_RETURN(PointDistribution at_level, PointDistribution::Create(params));
    SG_ASSIGN_OR_RETURN(CellReference cells,
                        CellReference::Build(EvaluateGrid(reference[b].spline, params)), "block ",
                        b, ": ");
    gate.blocks_.push_back({std::move(at_level), std::move(cells)});
  }
  // The wall lines' samples at the level and the reference's angles there.
  for (const WallLine& line : FindWallLines(reference, kinds)) {
    SG_RETURN_IF_ERROR(PollCancel(cancel));
    const FittedBlock& ref = reference[line.block];
    const int d = line.direction;
    // The direction leaving the wall: the other active one of a planar block, the normal of
    // the face the line lies on for a volume.
    int e = -1;
    const int dim = ref.spline.spatial_dim();
    int active = 0;
    for (int x = 0; x < 3; ++x) active += ref.distribution.num_points(x) > 1 ? 1 : 0;
    if (active < dim) continue;  // a surface block: no line leaves the wall
    for (int x = 0; x < 3 && e < 0; ++x) {
      const int m = ref.distribution.num_points(x);
      if (x == d || m == 1) continue;
      if (active == 2 || line.start[x] == 0 || line.start[x] == m - 1) e = x;
    }
    if (e < 0) continue;
    const std::vector<double> u =
        ref.distribution.Refined(d, line.start[d], line.start[d] + line.length - 1, level);
    Point3 uvw;
    for (int x = 0; x < 3; ++x) uvw[x] = ref.distribution.params(x)[line.start[x]];
    for (double t : u) {
      uvw[d] = t;
      gate.samples_.push_back({line.block, uvw, d, e, LineAngle(ref.spline, uvw, d, e)});
    }
  }
  return gate;
}

int64_t DeformationGate::num_cells() const {
  int64_t cells = 0;
  for (const Block& block : blocks_) cells += block.cells.num_cells();
  return cells;
}

int64_t DeformationGate::bytes() const {
  int64_t bytes = sizeof(DeformationGate) + samples_.size() * sizeof(WallSample);
  for (const Block& block : blocks_) {
    bytes += block.cells.bytes();
    for (int d = 0; d < 3; ++d) bytes += block.at_level.num_points(d) * int64_t{sizeof(double)};
  }
  return bytes;
}

absl::StatusOr<DeformationCheck> DeformationGate::Check(const std::vector<FittedBlock>& deformed,
                                                        const CancelCheck& cancel) const {
  if (blocks_.size() != deformed.size()) {
    return absl::InvalidArgumentError(absl::StrCat("the deformed grid has ", deformed.size(),
                                                   " blocks, the reference ", blocks_.size()));
  }
  DeformationCheck check;
  check.level = level_;
  CellQualityOptions options;
  options.max_level = 0;
  options.max_size_ratio = 1e300;  // only folds count here
  options.max_reported_cells = 0;
  options.cancel = cancel;
  for (size_t b = 0; b < blocks_.size(); ++b) {
    const FittedBlock now{deformed[b].spline, blocks_[b].at_level, {}};
    SG_ASSIGN_OR_RETURN(const CellQuality q, CheckCellQuality(now, blocks_[b].cells, options),
                        "block ", b, ": ");
    check.cells_checked += q.cells_checked;
    check.folded += q.folded;
    check.max_jacobian_ratio = std::max(check.max_jacobian_ratio, q.max_ratio);
    if (q.cells_checked > 0 && q.min_ratio < check.min_jacobian_ratio) {
      check.min_jacobian_ratio = q.min_ratio;
      check.worst_block = static_cast<int>(b);
      check.worst_cell = q.worst_cell;
    }
  }
  SG_RETURN_IF_ERROR(PollCancel(cancel));
  for (const WallSample& sample : samples_) {
    const double after = LineAngle(deformed[sample.block].spline, sample.uvw, sample.d, sample.e);
    check.max_orthogonality_change_degrees =
        std::max(check.max_orthogonality_change_degrees, std::abs(after - sample.before));
    ++check.wall_samples;
  }
  return check;
}

absl::StatusOr<DeformationCheck> CheckDeformation(const std::vector<FittedBlock>& reference,
                                                  const std::vector<FittedBlock>& deformed,
                                                  const BoundaryKinds& kinds, int level,
                                                  const CancelCheck& cancel) {
  if (reference.size() != deformed.size()) {
    return absl::InvalidArgumentError(absl::StrCat("the deformed grid has ", deformed.size(),
                                                   " blocks, the reference ", reference.size()));
  }
  SG_ASSIGN_OR_RETURN(const DeformationGate gate,
                      DeformationGate::Create(reference, kinds, level, cancel));
  return gate.Check(deformed, cancel);
}

}  // namespace splinegrid
