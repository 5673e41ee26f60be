// Decoding an uploaded CGNS file in a child process. libcgns and HDF5 are not hardened against
// hostile files (a crafted file can crash or hang them), so the server never parses CGNS
// itself: the upload goes to a private temporary file, `splinegrid-cgns-decode` (io/cgns)
// reads it under memory and CPU limits and prints a CgnsDecoded message, and the server
// validates that output like any client input (ParseCgnsDecoded). A crash, a limit or a hang of
// the child is an INVALID_ARGUMENT of this call; the server keeps serving.
//
// The child is started with posix_spawn (no fork() of the multi-threaded server): stdin and
// stderr /dev/null, stdout a pipe, every other descriptor closed, default signal handling, its
// own process group (so that a kill reaches anything it started). posix_spawn cannot set
// resource limits, so the child is `/bin/sh -c 'ulimit ...; exec DECODER UPLOAD'`: the limits
// are in place before the decoder's first instruction. Its memory limit is reserved against the
// server's MemoryBudget while it runs, so that concurrent decoders cannot exceed the budget.
#ifndef SPLINEGRID_SERVER_CGNS_DECODER_H_
#define SPLINEGRID_SERVER_CGNS_DECODER_H_

#include <cstdint>
#include <functional>
#include <string>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "core/grid/source_boundaries.h"
#include "server/memory_budget.h"

namespace splinegrid::server {

// The decoder's address-space limit when none is given: 1 GiB holds the decoder's libraries
// (about 40 MiB mapped: libcgns, HDF5, protobuf, libstdc++), HDF5's read of a zone's
// coordinates and the CgnsDecoded copy of them, i.e. grids of some 10 million points (48 bytes
// a 2D point, 72 a 3D one, in the two copies) -- far beyond the grids this service fits, yet
// small enough that a few concurrent imports fit a default budget. At most half the budget
// (CgnsDecoderMemoryLimit), so that one decode cannot starve every other call.
inline constexpr int64_t kDefaultCgnsDecoderMemoryBytes = int64_t{1} << 30;
// Below this the decoder cannot even load its libraries.
inline constexpr int64_t kMinCgnsDecoderMemoryBytes = int64_t{64} << 20;

struct CgnsDecoderOptions {
  // The decoder executable; empty: splinegrid-cgns-decode beside the running binary.
  std::string executable;
  // Address-space limit of the child (RLIMIT_AS), bytes, held against the memory budget while
  // the child runs; 0: the default (CgnsDecoderMemoryLimit). At least
  // kMinCgnsDecoderMemoryBytes when set.
  int64_t memory_limit_bytes = 0;
  // CPU time (RLIMIT_CPU: SIGXCPU at this, SIGKILL 5 s later) and wall time the child may take;
  // whole seconds, at least 1.
  absl::Duration cpu_limit = absl::Seconds(120);
  absl::Duration wall_limit = absl::Seconds(300);
};

// The child's address-space limit: options.memory_limit_bytes when set, else
// min(kDefaultCgnsDecoderMemoryBytes, max(kMinCgnsDecoderMemoryBytes, budget_limit / 2)).
int64_t CgnsDecoderMemoryLimit(const CgnsDecoderOptions& options, int64_t budget_limit);

// The decoder executable `options` name, or FAILED_PRECONDITION when it is not an executable
// file (naming the path and the flag that sets it).
absl::StatusOr<std::string> FindCgnsDecoder(const CgnsDecoderOptions& options);

// Decodes `bytes` (a whole CGNS file). The child's memory limit is reserved against `budget`
// until the child is reaped (RESOURCE_EXHAUSTED naming --cgns_decoder_memory_mb when it does not
// fit, before anything is written or started). The child's output is charged to `budget` through
// `reservation` as it arrives (a compressed file can decode into far more than it is); the
// caller resizes the reservation to what it keeps. `cancelled` is polled about every 100 ms
// while the child runs: when it returns true the child is killed and the result is CANCELLED.
// The child is always reaped and the temporary file removed before this returns.
absl::StatusOr<ImportedGrid> DecodeCgnsUpload(const std::string& bytes,
                                              const CgnsDecoderOptions& options,
                                              MemoryBudget* budget, MemoryReservation* reservation,
                                              const std::function<bool()>& cancelled = {});

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_CGNS_DECODER_H_
