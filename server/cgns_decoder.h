// Decoding an uploaded CGNS file in a child process. libcgns and HDF5 are not hardened against
// hostile files (a crafted file can crash or hang them), so the server never parses CGNS
// itself: the upload goes to a private temporary file, `splinegrid-cgns-decode` (io/cgns)
// reads it under memory and CPU limits and prints a CgnsDecoded message, and the server
// validates that output like any client input (ParseCgnsDecoded). A crash, a limit or a hang of
// the child is an INVALID_ARGUMENT of this call; the server keeps serving.
#ifndef SPLINEGRID_SERVER_CGNS_DECODER_H_
#define SPLINEGRID_SERVER_CGNS_DECODER_H_

#include <functional>
#include <string>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "core/grid/source_boundaries.h"
#include "server/memory_budget.h"

namespace splinegrid::server {

struct CgnsDecoderOptions {
  // The decoder executable; empty: splinegrid-cgns-decode beside the running binary.
  std::string executable;
  // Address-space limit of the child (RLIMIT_AS), bytes.
  int64_t memory_limit_bytes = int64_t{4} << 30;
  // CPU time (RLIMIT_CPU) and wall time the child may take.
  absl::Duration cpu_limit = absl::Seconds(120);
  absl::Duration wall_limit = absl::Seconds(300);
};

// The decoder executable `options` name, or FAILED_PRECONDITION when it is not an executable
// file (naming the path and the flag that sets it).
absl::StatusOr<std::string> FindCgnsDecoder(const CgnsDecoderOptions& options);

// Decodes `bytes` (a whole CGNS file). The child's output is charged to `budget` through
// `reservation` as it arrives (a compressed file can decode into far more than it is); the
// caller resizes the reservation to what it keeps. `cancelled` is polled about once a second
// while the child runs: when it returns true the child is killed and the result is CANCELLED.
absl::StatusOr<ImportedGrid> DecodeCgnsUpload(const std::string& bytes,
                                              const CgnsDecoderOptions& options,
                                              MemoryBudget* budget, MemoryReservation* reservation,
                                              const std::function<bool()>& cancelled = {});

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_CGNS_DECODER_H_
