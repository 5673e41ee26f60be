// Tells ThreadSanitizer about the ordering gRPC guarantees between a reactor's operations and
// their completions (StartRead -> OnReadDone, StartWrite -> OnWriteDone, Finish -> OnDone).
// Debian's gRPC is not instrumented, so TSan cannot see that ordering by itself and would report
// every hand-off of a reactor between gRPC's threads. Outside TSan builds these are no-ops.
#ifndef SPLINEGRID_SERVER_HAPPENS_BEFORE_H_
#define SPLINEGRID_SERVER_HAPPENS_BEFORE_H_

#if defined(__SANITIZE_THREAD__)  // GCC
#define SG_THREAD_SANITIZER 1
#elif defined(__has_feature)  // clang
#if __has_feature(thread_sanitizer)
#define SG_THREAD_SANITIZER 1
#endif
#endif

#if defined(SG_THREAD_SANITIZER)
extern "C" void __tsan_acquire(void* addr);
extern "C" void __tsan_release(void* addr);
// Everything before this point happens before a later SG_HAPPENS_AFTER(addr).
#define SG_HAPPENS_BEFORE(addr) __tsan_release(static_cast<void*>(addr))
#define SG_HAPPENS_AFTER(addr) __tsan_acquire(static_cast<void*>(addr))
#else
#define SG_HAPPENS_BEFORE(addr) \
  do {                          \
  } while (0)
#define SG_HAPPENS_AFTER(addr) \
  do {                         \
  } while (0)
#endif

#endif  // SPLINEGRID_SERVER_HAPPENS_BEFORE_H_
