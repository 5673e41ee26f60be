// libFuzzer target: FitGridRequest bytes -> ParseFitSpec (proto/convert/convert.cc). Any bytes
// protobuf accepts must give options or INVALID_ARGUMENT; options it accepts must survive
// EncodeFitSpec -> ParseFitSpec unchanged in validity.
#include <cstddef>
#include <cstdint>

#include "proto/convert/convert.h"
#include "splinegrid/v1/splinegrid_service.pb.h"
#include "tests/fuzz/fuzz_proto.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  splinegrid::v1::FitGridRequest request;
  if (!request.ParseFromArray(data, static_cast<int>(size))) return 0;
  absl::StatusOr<splinegrid::GridFitOptions> options = splinegrid::ParseFitSpec(request.spec());
  if (!options.ok()) {
    splinegrid::fuzz::CheckRejection(options.status());
    return 0;
  }
  splinegrid::v1::FitSpec encoded;
  splinegrid::EncodeFitSpec(*options, &encoded);
  absl::StatusOr<splinegrid::GridFitOptions> again = splinegrid::ParseFitSpec(encoded);
  FUZZ_CHECK(again.ok(), again.status().ToString());
  return 0;
}
