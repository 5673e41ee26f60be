// libFuzzer target: SplineBlock bytes -> ParseSplineBlock (proto/convert/convert.cc): knots,
// control counts, control points and the point distribution of a fitted block. Any bytes
// protobuf accepts must give a block or INVALID_ARGUMENT; an accepted block must encode and
// parse back.
#include <cstddef>
#include <cstdint>

#include "proto/convert/convert.h"
#include "splinegrid/v1/grid.pb.h"
#include "tests/fuzz/fuzz_proto.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  splinegrid::v1::SplineBlock message;
  if (!message.ParseFromArray(data, static_cast<int>(size))) return 0;
  absl::StatusOr<splinegrid::FittedBlock> block = splinegrid::ParseSplineBlock(message);
  if (!block.ok()) {
    splinegrid::fuzz::CheckRejection(block.status());
    return 0;
  }
  splinegrid::v1::SplineBlock encoded;
  splinegrid::EncodeSplineBlock(*block, /*index=*/0, /*full=*/true, &encoded);
  absl::StatusOr<splinegrid::FittedBlock> again = splinegrid::ParseSplineBlock(encoded);
  FUZZ_CHECK(again.ok(), again.status().ToString());
  return 0;
}
