// libFuzzer target: FairGridRequest bytes -> ParseFairing (proto/convert/convert.cc). Any
// bytes protobuf accepts must give fairing options or INVALID_ARGUMENT; accepted options must
// survive EncodeFairing -> ParseFairing.
#include <cstddef>
#include <cstdint>

#include "proto/convert/convert.h"
#include "splinegrid/v1/splinegrid_service.pb.h"
#include "tests/fuzz/fuzz_proto.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  splinegrid::v1::FairGridRequest request;
  if (!request.ParseFromArray(data, static_cast<int>(size))) return 0;
  absl::StatusOr<splinegrid::FairingOptions> fairing =
      splinegrid::ParseFairing(request.fairing(), "fairing");
  if (!fairing.ok()) {
    splinegrid::fuzz::CheckRejection(fairing.status());
    return 0;
  }
  splinegrid::v1::Fairing encoded;
  splinegrid::EncodeFairing(*fairing, &encoded);
  absl::StatusOr<splinegrid::FairingOptions> again = splinegrid::ParseFairing(encoded, "fairing");
  FUZZ_CHECK(again.ok(), again.status().ToString());
  return 0;
}
