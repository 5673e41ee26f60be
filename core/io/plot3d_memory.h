// How much memory parsing a Plot3D file may take, known before parsing: a server charges it to
// its budget first, so that a small upload cannot make the parser allocate far more than it sent.
//
// The amplification this guards against is the text repeat "n*value": "1073741824*0" is 12 bytes
// and 2^30 values (8 GiB as doubles). Binary files hold at most 2 doubles' worth of grid per
// 4-byte float, so for them the bound is a small multiple of the file size.
#ifndef SPLINEGRID_CORE_IO_PLOT3D_MEMORY_H_
#define SPLINEGRID_CORE_IO_PLOT3D_MEMORY_H_

#include <cstdint>
#include <string_view>

namespace splinegrid {

// An upper bound on the bytes ParsePlot3d(bytes) allocates at once (the token values and the
// grid's coordinates and iblank), not counting `bytes` itself. One pass, no allocation.
// Text (the first 4 bytes printable or whitespace, as ParsePlot3d decides): with T tokens
// (runs between whitespace/commas, and null values: a comma after a comma or at the start), R
// repeats and V values once repeats are expanded, 8 max(size / 24 + 16, 2 T) + 32 R + 8 V; binary:
// 2 x the size (4-byte floats become doubles; Fortran records or C stream, whose hypotheses are
// read one at a time, each grid freed before the next). Not counted: ~100 bytes of bookkeeping per block,
// which matters only for files of many tiny blocks (at most ~10 x the size of such a file). Must be
// kept in step with the parser (plot3d_text.cc, fortran_text.cc, plot3d_binary.cc,
// plot3d_stream.cc).
int64_t Plot3dParseBytesBound(std::string_view bytes);

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_IO_PLOT3D_MEMORY_H_
