// libFuzzer target: GenerateGridRequest bytes -> the GenerateGrid converters
// (proto/convert/generate_convert.cc): layer parameters, profile points, the airfoil file text
// (core/io/airfoil.cc) and the fit spec. Any bytes protobuf accepts must convert or give
// INVALID_ARGUMENT; accepted layer parameters must survive EncodeProfileGridOptions.
#include <cstddef>
#include <cstdint>

#include "core/io/airfoil.h"
#include "proto/convert/convert.h"
#include "proto/convert/generate_convert.h"
#include "splinegrid/v1/splinegrid_service.pb.h"
#include "tests/fuzz/fuzz_proto.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  splinegrid::v1::GenerateGridRequest request;
  if (!request.ParseFromArray(data, static_cast<int>(size))) return 0;
  absl::StatusOr<splinegrid::ProfileGridOptions> options =
      splinegrid::ParseProfileGridOptions(request);
  if (options.ok()) {
    splinegrid::v1::GenerateGridRequest encoded;
    splinegrid::EncodeProfileGridOptions(*options, &encoded);
    absl::StatusOr<splinegrid::ProfileGridOptions> again =
        splinegrid::ParseProfileGridOptions(encoded);
    FUZZ_CHECK(again.ok(), again.status().ToString());
  } else {
    splinegrid::fuzz::CheckRejection(options.status());
  }
  if (request.has_points()) {
    absl::StatusOr<splinegrid::StructuredBlock> points =
        splinegrid::ParseProfilePoints(request.points(), "points");
    if (!points.ok()) splinegrid::fuzz::CheckRejection(points.status());
  }
  if (request.has_airfoil_file()) {
    absl::StatusOr<splinegrid::AirfoilCoordinates> airfoil =
        splinegrid::ParseAirfoil(request.airfoil_file(), "airfoil_file");
    if (!airfoil.ok()) splinegrid::fuzz::CheckRejection(airfoil.status());
  }
  absl::StatusOr<splinegrid::GridFitOptions> spec = splinegrid::ParseFitSpec(request.spec());
  if (!spec.ok()) splinegrid::fuzz::CheckRejection(spec.status());
  return 0;
}
