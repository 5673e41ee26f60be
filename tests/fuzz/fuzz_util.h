// Helpers shared by the libFuzzer targets: an invariant check that aborts (a finding for
// libFuzzer), and the status check every parser of untrusted input must pass.
#ifndef SPLINEGRID_TESTS_FUZZ_FUZZ_UTIL_H_
#define SPLINEGRID_TESTS_FUZZ_FUZZ_UTIL_H_

#include <cstdio>
#include <cstdlib>
#include <string>

#include "absl/status/status.h"

// Aborts with `what` when `condition` is false (Debian's Abseil has no absl/log CHECK).
#define FUZZ_CHECK(condition, what)                                                              \
  do {                                                                                           \
    if (!(condition)) {                                                                          \
      std::fprintf(stderr, "%s:%d: FUZZ_CHECK(%s) failed: %s\n", __FILE__, __LINE__, #condition, \
                   std::string(what).c_str());                                                   \
      std::abort();                                                                              \
    }                                                                                            \
  } while (0)

namespace splinegrid::fuzz {

// A parser's rejection of hostile bytes must be INVALID_ARGUMENT with a message; anything else
// (INTERNAL, UNKNOWN, an empty message) is a finding.
inline void CheckRejection(const absl::Status& status) {
  FUZZ_CHECK(status.code() == absl::StatusCode::kInvalidArgument && !status.message().empty(),
             status.ToString());
}

}  // namespace splinegrid::fuzz

#endif  // SPLINEGRID_TESTS_FUZZ_FUZZ_UTIL_H_
