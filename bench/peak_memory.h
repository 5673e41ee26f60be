// Peak resident memory that a piece of code adds, measured in a forked child process so that
// the benchmark's own allocator state and timings are untouched: the child fixes glibc's mmap
// threshold (large blocks come from fresh pages, so reused heap memory cannot hide them),
// resets the high-water mark (/proc/self/clear_refs), runs the code and reports
// VmHWM - VmRSS through a pipe.
#ifndef SPLINEGRID_BENCH_PEAK_MEMORY_H_
#define SPLINEGRID_BENCH_PEAK_MEMORY_H_

#include <malloc.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <string>

namespace splinegrid::bench {

// kB value of a "Name:   123 kB" line of /proc/self/status, or -1.
inline int64_t ReadStatusKb(const std::string& name) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(name + ":", 0) == 0) return std::stoll(line.substr(name.size() + 1));
  }
  return -1;
}

// Bytes of resident memory that `fn()` adds at its peak, or -1 if it cannot be measured.
template <typename Fn>
int64_t PeakExtraBytes(Fn&& fn) {
  int fds[2];
  if (pipe(fds) != 0) return -1;
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    close(fds[0]);
    mallopt(M_MMAP_THRESHOLD, 64 * 1024);
    mallopt(M_TRIM_THRESHOLD, 64 * 1024);
    malloc_trim(0);
    int64_t result = -1;
    if (std::ofstream("/proc/self/clear_refs") << "5") {
      const int64_t base = ReadStatusKb("VmRSS");
      fn();
      const int64_t peak = ReadStatusKb("VmHWM");
      if (base >= 0 && peak >= 0) result = (peak - base) * 1024;
    }
    (void)!write(fds[1], &result, sizeof(result));
    _exit(0);
  }
  close(fds[1]);
  int64_t result = -1;
  if (read(fds[0], &result, sizeof(result)) != sizeof(result)) result = -1;
  close(fds[0]);
  waitpid(pid, nullptr, 0);
  return result;
}

}  // namespace splinegrid::bench

#endif  // SPLINEGRID_BENCH_PEAK_MEMORY_H_
