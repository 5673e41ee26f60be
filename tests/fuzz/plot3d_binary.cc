// libFuzzer target: the Plot3D reader (core/io/plot3d.cc) on binary input (plot3d_binary.cc):
// both byte orders, block count or not, 2D/3D, single/double precision, iblank or not. The seeds
// are binary, so mutations stay mostly binary; text-looking inputs go to the text reader.
//
// The contract checked is the server's (server/import_reactor.cc): the upload is charged
// Plot3dParseBytesBound(bytes) before parsing, and refused when that exceeds the budget (64 MiB
// here); so inputs over the budget are not parsed, and for the others the parser's peak heap use
// must stay within the bound (plus bookkeeping: 16 KiB + 16 bytes per input byte). Every input
// must give a grid or INVALID_ARGUMENT; a grid must encode in the layout detected and read back.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "absl/strings/str_cat.h"
#include "core/io/plot3d.h"
#include "core/io/plot3d_memory.h"
#include "tests/fuzz/fuzz_memory.h"
#include "tests/fuzz/fuzz_util.h"

namespace {

constexpr int64_t kBudgetBytes = int64_t{64} << 20;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const int64_t bound = splinegrid::Plot3dParseBytesBound(bytes);
  if (bound > kBudgetBytes) return 0;  // refused before parsing
  splinegrid::Plot3dFormat format;
  splinegrid::fuzz::PeakAllocation peak;
  absl::StatusOr<splinegrid::MultiBlockGrid> grid = splinegrid::ParsePlot3d(bytes, "fuzz", &format);
  const int64_t used = peak.Peak();
  FUZZ_CHECK(used <= bound + 16384 + 16 * static_cast<int64_t>(size),
             absl::StrCat("parsing ", size, " bytes took ", used,
                          " heap bytes at once; the bound is ", bound));
  if (!grid.ok()) {
    splinegrid::fuzz::CheckRejection(grid.status());
    return 0;
  }
  // Round trip: what was read must be writable in the layout detected, and read back alike.
  absl::StatusOr<std::string> encoded = splinegrid::EncodePlot3d(*grid, format);
  FUZZ_CHECK(encoded.ok(), encoded.status().ToString());
  absl::StatusOr<splinegrid::MultiBlockGrid> reread = splinegrid::ParsePlot3d(*encoded, "fuzz");
  FUZZ_CHECK(reread.ok(), reread.status().ToString());
  FUZZ_CHECK(reread->blocks.size() == grid->blocks.size(), "block count changed");
  return 0;
}
