// libFuzzer target: the Plot3D reader (core/io/plot3d.cc) on text input: tokenizer (Fortran
// "n*value" repeats, D exponents, commas) and all 8 layout hypotheses of plot3d_text.cc. The
// seeds are text, so mutations stay mostly text; binary-looking inputs go to the binary reader.
//
// The contract checked is the server's (server/import_reactor.cc): the upload is charged
// Plot3dParseBytesBound(bytes) before parsing, and refused when that exceeds the budget (64 MiB
// here); so inputs over the budget are not parsed, and for the others the parser's peak heap use
// must stay within the bound (plus bookkeeping: 16 KiB + 16 bytes per input byte). Every input
// must give a grid or INVALID_ARGUMENT; a grid must encode in the layout detected and read back.
#include <cstddef>
#include <cstdint>

#include "tests/fuzz/fuzz_plot3d.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return splinegrid::fuzz::FuzzPlot3d(data, size);
}
