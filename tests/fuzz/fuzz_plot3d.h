// The body of the Plot3D fuzz targets (plot3d_text.cc, plot3d_binary.cc: the same reader, seeded
// with text or with binary files): parse within the memory bound the server charges before
// parsing, reject with a message, and round-trip what was read in the layout detected.
#ifndef SPLINEGRID_TESTS_FUZZ_FUZZ_PLOT3D_H_
#define SPLINEGRID_TESTS_FUZZ_FUZZ_PLOT3D_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "absl/strings/str_cat.h"
#include "core/io/plot3d.h"
#include "core/io/plot3d_memory.h"
#include "tests/fuzz/fuzz_memory.h"
#include "tests/fuzz/fuzz_util.h"

namespace splinegrid::fuzz {

inline constexpr int64_t kPlot3dBudgetBytes = int64_t{64} << 20;

inline int FuzzPlot3d(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const int64_t bound = Plot3dParseBytesBound(bytes);
  if (bound > kPlot3dBudgetBytes) return 0;  // refused before parsing
  Plot3dFormat format;
  PeakAllocation peak;
  absl::StatusOr<MultiBlockGrid> grid = ParsePlot3d(bytes, "fuzz", &format);
  const int64_t used = peak.Peak();
  FUZZ_CHECK(used <= bound + 16384 + 16 * static_cast<int64_t>(size),
             absl::StrCat("parsing ", size, " bytes took ", used,
                          " heap bytes at once; the bound is ", bound));
  if (!grid.ok()) {
    CheckRejection(grid.status());
    return 0;
  }
  // Round trip: what was read must be writable in the layout detected, and read back alike.
  absl::StatusOr<std::string> encoded = EncodePlot3d(*grid, format);
  FUZZ_CHECK(encoded.ok(), encoded.status().ToString());
  absl::StatusOr<MultiBlockGrid> reread = ParsePlot3d(*encoded, "fuzz");
  FUZZ_CHECK(reread.ok(), reread.status().ToString());
  FUZZ_CHECK(reread->blocks.size() == grid->blocks.size(), "block count changed");
  return 0;
}

}  // namespace splinegrid::fuzz

#endif  // SPLINEGRID_TESTS_FUZZ_FUZZ_PLOT3D_H_
