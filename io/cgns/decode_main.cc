// splinegrid-cgns-decode FILE: reads a CGNS file (ReadCgnsFile) and prints it as one
// splinegrid.v1.CgnsDecoded message on stdout (exit 0). A file it cannot read gives the reason
// as text on stdout and exit status 2; usage errors exit 64.
//
// The server runs this for every uploaded CGNS file in a child process with memory and CPU
// limits, because libcgns and HDF5 are not hardened against hostile files: a crash here ends
// the child, never the server, which validates the output like any client input.
#include <cstdio>
#include <iostream>
#include <string>

#include "io/cgns/cgns_io.h"
#include "proto/convert/source_boundaries_convert.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: splinegrid-cgns-decode FILE.cgns > decoded.binpb\n");
    return 64;
  }
  absl::StatusOr<splinegrid::ImportedGrid> grid = splinegrid::ReadCgnsFile(argv[1]);
  if (!grid.ok()) {
    std::fputs(std::string(grid.status().message()).c_str(), stdout);
    return 2;
  }
  splinegrid::v1::CgnsDecoded decoded;
  splinegrid::EncodeCgnsDecoded(*grid, &decoded);
  if (!decoded.SerializeToOstream(&std::cout) || !std::cout.flush()) {
    std::fprintf(stderr, "splinegrid-cgns-decode: writing stdout failed\n");
    return 1;
  }
  return 0;
}
