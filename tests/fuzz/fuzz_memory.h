// Peak heap use of a piece of code, measured with the sanitizer allocator's malloc/free hooks
// (the fuzz targets are built with ASan): for checking that a parser stays within the memory
// bound its caller charges to a budget before calling it. Single-threaded use only.
#ifndef SPLINEGRID_TESTS_FUZZ_FUZZ_MEMORY_H_
#define SPLINEGRID_TESTS_FUZZ_FUZZ_MEMORY_H_

#include <sanitizer/allocator_interface.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace splinegrid::fuzz {

namespace memory_internal {
inline bool g_on = false;
inline int64_t g_live = 0;
inline int64_t g_peak = 0;

inline void MallocHook(const volatile void*, size_t size) {
  if (!g_on) return;
  g_live += static_cast<int64_t>(size);
  g_peak = std::max(g_peak, g_live);
}

inline void FreeHook(const volatile void* p) {
  if (!g_on || p == nullptr) return;
  const void* q = const_cast<const void*>(p);
  if (__sanitizer_get_ownership(q))
    g_live -= static_cast<int64_t>(__sanitizer_get_allocated_size(q));
}

inline const bool kHooksInstalled =
    __sanitizer_install_malloc_and_free_hooks(&MallocHook, &FreeHook) != 0;
}  // namespace memory_internal

// Measures from construction to Peak(): the most bytes allocated and not yet freed at any time
// (frees of older memory count against it, so it is a lower bound when the code frees such).
class PeakAllocation {
 public:
  PeakAllocation() {
    memory_internal::g_live = 0;
    memory_internal::g_peak = 0;
    memory_internal::g_on = true;
  }
  ~PeakAllocation() { memory_internal::g_on = false; }
  PeakAllocation(const PeakAllocation&) = delete;
  PeakAllocation& operator=(const PeakAllocation&) = delete;

  // Stops measuring; the peak.
  int64_t Peak() {
    memory_internal::g_on = false;
    return memory_internal::g_peak;
  }
};

}  // namespace splinegrid::fuzz

#endif  // SPLINEGRID_TESTS_FUZZ_FUZZ_MEMORY_H_
