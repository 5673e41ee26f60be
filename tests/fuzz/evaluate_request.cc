// libFuzzer target: EvaluateGridRequest bytes -> ParseResolution (proto/convert/convert.cc):
// refinement level or counts, and the optional index box. Any bytes protobuf accepts must give
// a resolution or INVALID_ARGUMENT; an accepted resolution is then sampled as EvaluateGrid
// does (SampleExtents, and SampleParameters up to 10^6 points) on the point distribution of
// fuzz_grids.h's fitted 29 x 9 block, with the same error rule (OUT_OF_RANGE allowed for a too fine
// resolution).
#include <cstddef>
#include <cstdint>

#include "core/grid/sampling.h"
#include "proto/convert/convert.h"
#include "splinegrid/v1/splinegrid_service.pb.h"
#include "tests/fuzz/fuzz_grids.h"
#include "tests/fuzz/fuzz_proto.h"
#include "tests/fuzz/fuzz_util.h"

namespace {

// The point distribution the resolution is applied to.
splinegrid::PointDistribution* g_distribution = nullptr;

// Sampling refuses a valid but too fine resolution with OUT_OF_RANGE.
void CheckSampleError(const absl::Status& status) {
  if (status.code() == absl::StatusCode::kOutOfRange) return;
  splinegrid::fuzz::CheckRejection(status);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  splinegrid::GridFit fit = splinegrid::fuzz::FitSmall(splinegrid::fuzz::SmallNaca0012());
  g_distribution = new splinegrid::PointDistribution(fit.blocks.front().fitted.distribution);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  splinegrid::v1::EvaluateGridRequest request;
  if (!request.ParseFromArray(data, static_cast<int>(size))) return 0;
  absl::StatusOr<splinegrid::Resolution> resolution = splinegrid::ParseResolution(request);
  if (!resolution.ok()) {
    splinegrid::fuzz::CheckRejection(resolution.status());
    return 0;
  }
  absl::StatusOr<splinegrid::Extents> extents =
      splinegrid::SampleExtents(*g_distribution, *resolution);
  if (!extents.ok()) {
    CheckSampleError(extents.status());
    return 0;
  }
  for (int d = 0; d < 3; ++d) FUZZ_CHECK((*extents)[d] >= 1, "empty sample extents");
  if (splinegrid::NumPoints(*extents) > 1000000) return 0;
  absl::StatusOr<std::array<std::vector<double>, 3>> parameters =
      splinegrid::SampleParameters(*g_distribution, *resolution);
  if (!parameters.ok()) {
    CheckSampleError(parameters.status());
    return 0;
  }
  for (int d = 0; d < 3; ++d) {
    FUZZ_CHECK(static_cast<int64_t>((*parameters)[d].size()) == (*extents)[d],
               "parameters do not match the extents");
  }
  return 0;
}
