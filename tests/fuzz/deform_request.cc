// libFuzzer target: DeformGridRequest bytes -> the DeformGrid converters
// (proto/convert/deform_convert.cc, convert.cc): deform options (boundary selection, face
// ranges, propagation, radii), the rigid motion, boundary-point ranges, and the control
// displacements against a real Deformer (fuzz_grids.h's 29 x 9 NACA 0012 grid, fitted once
// at start-up). Any bytes protobuf accepts must convert or give INVALID_ARGUMENT. What converts
// then goes through the kernel as DeformGrid would: Deformer::Create with the options (face
// ranges against the grid), and the motion applied; errors there must be INVALID_ARGUMENT or
// FAILED_PRECONDITION.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/deform/deform_motion.h"
#include "core/deform/deformer.h"
#include "proto/convert/convert.h"
#include "proto/convert/deform_convert.h"
#include "splinegrid/v1/splinegrid_service.pb.h"
#include "tests/fuzz/fuzz_grids.h"
#include "tests/fuzz/fuzz_proto.h"
#include "tests/fuzz/fuzz_util.h"

namespace {

// The reference revision and the deformer with the default options (every wall point moves),
// which maps control indices (DisplacementsInDeformerOrder) and applies the motions.
std::vector<splinegrid::FittedBlock> g_blocks;
splinegrid::BoundaryKinds g_kinds;
std::unique_ptr<splinegrid::Deformer> g_deformer;

// A kernel error for a request that converted: the request's fault, never a crash or INTERNAL.
void CheckKernelError(const absl::Status& status) {
  if (status.code() == absl::StatusCode::kFailedPrecondition) return;
  splinegrid::fuzz::CheckRejection(status);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  splinegrid::GridFit fit = splinegrid::fuzz::FitSmall(splinegrid::fuzz::SmallNaca0012());
  for (splinegrid::BlockFit& block : fit.blocks) g_blocks.push_back(std::move(block.fitted));
  g_kinds = std::move(fit.kinds);
  absl::StatusOr<splinegrid::Deformer> deformer =
      splinegrid::Deformer::Create(g_blocks, g_kinds, {});
  FUZZ_CHECK(deformer.ok(), deformer.status().ToString());
  g_deformer = std::make_unique<splinegrid::Deformer>(std::move(*deformer));
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  splinegrid::v1::DeformGridRequest request;
  if (!request.ParseFromArray(data, static_cast<int>(size))) return 0;
  absl::StatusOr<splinegrid::DeformOptions> options = splinegrid::ParseDeformOptions(request);
  if (!options.ok()) {
    splinegrid::fuzz::CheckRejection(options.status());
  } else {
    absl::StatusOr<splinegrid::Deformer> deformer =
        splinegrid::Deformer::Create(g_blocks, g_kinds, *options);
    if (!deformer.ok()) CheckKernelError(deformer.status());
  }
  // The motion as DeformGrid converts it (ParseDeformMotion) and applies it (ApplyMotion:
  // control displacements are mapped to the deformer's order there).
  absl::StatusOr<splinegrid::DeformMotion> motion = splinegrid::ParseDeformMotion(request);
  if (!motion.ok()) {
    splinegrid::fuzz::CheckRejection(motion.status());
    return 0;
  }
  absl::StatusOr<std::vector<splinegrid::FittedBlock>> moved =
      splinegrid::ApplyMotion(*g_deformer, *motion);
  if (!moved.ok()) CheckKernelError(moved.status());
  return 0;
}
