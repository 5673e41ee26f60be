// libFuzzer target: the airfoil coordinate reader (core/io/airfoil.cc, Selig and Lednicer) on
// arbitrary bytes. Every input must give an outline of >= 5 finite 2D points or an
// INVALID_ARGUMENT status, with peak heap use linear in the input (64 KiB + 64 bytes per input
// byte: the reader is O(size of text)).
#include "core/io/airfoil.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "absl/strings/str_cat.h"
#include "tests/fuzz/fuzz_memory.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  splinegrid::fuzz::PeakAllocation peak;
  absl::StatusOr<splinegrid::AirfoilCoordinates> airfoil = splinegrid::ParseAirfoil(text, "fuzz");
  const int64_t used = peak.Peak();
  FUZZ_CHECK(used <= 65536 + 64 * static_cast<int64_t>(size),
             absl::StrCat("parsing ", size, " bytes took ", used, " heap bytes at once"));
  if (!airfoil.ok()) {
    splinegrid::fuzz::CheckRejection(airfoil.status());
    return 0;
  }
  const splinegrid::StructuredBlock& points = airfoil->points;
  FUZZ_CHECK(points.spatial_dim() == 2, "not 2D");
  FUZZ_CHECK(points.num_points() >= 5, "too few points");
  for (double c : points.coords()) FUZZ_CHECK(std::isfinite(c), "non-finite coordinate");
  return 0;
}
