// SG_CHECK: aborts on a broken internal invariant (a bug, never bad input).
// Abseil 20220623 (Debian 12) has no ABSL_CHECK yet; this is the same contract.
#ifndef SPLINEGRID_CORE_UTIL_CHECK_H_
#define SPLINEGRID_CORE_UTIL_CHECK_H_

#include <cstdio>
#include <cstdlib>

#define SG_CHECK(cond)                                                              \
  do {                                                                              \
    if (!(cond)) {                                                                  \
      std::fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                                 \
    }                                                                               \
  } while (0)

#endif  // SPLINEGRID_CORE_UTIL_CHECK_H_
