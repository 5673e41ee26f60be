#include "core/deform/deform_motion.h"

#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/util/status_macros.h"

namespace splinegrid {

absl::StatusOr<std::vector<double>> DisplacementsInDeformerOrder(
    const Deformer& deformer, std::span<const BlockControlDisplacements> given) {
  const int s = deformer.reference().front().spline.spatial_dim();
  std::map<std::pair<int, int64_t>, size_t> index;
  for (size_t q = 0; q < deformer.moved_controls().size(); ++q) {
    index[deformer.moved_controls()[q]] = q;
  }
  std::vector<double> out(deformer.moved_controls().size() * s, 0.0);
  const int num_blocks = static_cast<int>(deformer.reference().size());
  for (size_t e = 0; e < given.size(); ++e) {
    const BlockControlDisplacements& block = given[e];
    const std::string field = absl::StrCat("blocks[", e, "]");
    if (block.block < 0 || block.block >= num_blocks) {
      return absl::InvalidArgumentError(
          absl::StrCat(field, ".block = ", block.block, " is outside [0, ", num_blocks - 1, "]"));
    }
    if (block.values.size() != s * block.controls.size()) {
      return absl::InvalidArgumentError(absl::StrCat(field, ": ", block.values.size(),
                                                     " values for ", block.controls.size(),
                                                     " controls of ", s, " coordinates"));
    }
    for (size_t q = 0; q < block.controls.size(); ++q) {
      const auto it = index.find({block.block, block.controls[q]});
      if (it == index.end()) {
        return absl::InvalidArgumentError(absl::StrCat(
            field, ".controls[", q, "] = ", block.controls[q],
            " does not carry the moved boundary (or is no control of block ", block.block, ")"));
      }
      for (int c = 0; c < s; ++c) {
        const double value = block.values[s * q + c];
        if (!std::isfinite(value)) {
          return absl::InvalidArgumentError(
              absl::StrCat(field, ".values[", s * q + c, "] = ", value, " is not finite"));
        }
        out[s * it->second + c] = value;
      }
    }
  }
  return out;
}

absl::StatusOr<std::vector<FittedBlock>> ApplyMotion(const Deformer& deformer,
                                                     const DeformMotion& motion) {
  if (const auto* rigid = std::get_if<RigidMotion>(&motion)) return deformer.Rigid(*rigid);
  if (const auto* points = std::get_if<std::vector<BoundaryPoints>>(&motion)) {
    return deformer.MoveBoundaryPoints(*points);
  }
  SG_ASSIGN_OR_RETURN(const std::vector<double> displacements,
                      DisplacementsInDeformerOrder(
                          deformer, std::get<std::vector<BlockControlDisplacements>>(motion)));
  return deformer.DisplaceControls(displacements);
}

}  // namespace splinegrid
