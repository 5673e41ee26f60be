// The memory this process may use and the server's default memory budget, a fraction of it.
//
// The limit is the smallest memory limit of the process's control group and its ancestors
// (cgroup v2 `memory.max`, cgroup v1 `memory.limit_in_bytes`, found through /proc/self/cgroup
// under /sys/fs/cgroup), or the physical memory when no group limits it. The parsing functions
// are pure (file contents in, numbers out) so that they can be tested without a container.
#ifndef SPLINEGRID_SERVER_MEMORY_LIMIT_H_
#define SPLINEGRID_SERVER_MEMORY_LIMIT_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace splinegrid::server {

// The share of the memory limit the default budget takes. The rest is for what the budget does
// not count: gRPC, threads, the allocator's slack, transient copies (see memory_budget.h).
inline constexpr double kDefaultBudgetFraction = 0.5;

// Contents of a cgroup limit file -> bytes, or nullopt for "no limit": v2's "max", and v1's
// "unlimited" value (LONG_MAX rounded down to a page, anything >= 2^62 is taken as unlimited).
// Surrounding whitespace is ignored. INVALID_ARGUMENT for anything else.
absl::StatusOr<std::optional<int64_t>> ParseCgroupLimit(absl::string_view text);

// The process's cgroup paths from the contents of /proc/self/cgroup: the v2 path (line
// "0::PATH") and the v1 path of the memory controller (line "N:...memory...:PATH"); empty when
// the line is absent.
struct CgroupPaths {
  std::string v2;
  std::string v1_memory;
};
CgroupPaths ParseProcSelfCgroup(absl::string_view text);

// Where a memory limit came from, and its size.
struct MemoryLimit {
  int64_t bytes = 0;
  std::string source;  // "physical memory" or "cgroup limit (FILE)"
  // What the most constrained group has left: the smallest limit minus usage (memory.current,
  // memory.usage_in_bytes beside the limit file) over the groups with a limit; unset without a
  // cgroup limit or when no usage can be read. A process sharing its group with others (a
  // batch job's allocation) may use only this much more.
  std::optional<int64_t> headroom;
};

// The effective limit: the smallest limit among the cgroup files of the process's groups and
// their ancestors (v2 under `root`, v1 under `root`/memory), else `physical_bytes`.
// `read_file(path)` returns a file's contents or nullopt when it is missing or unreadable;
// unparsable contents count as no limit.
MemoryLimit FindMemoryLimit(
    const std::function<std::optional<std::string>(const std::string&)>& read_file,
    int64_t physical_bytes, const std::string& root = "/sys/fs/cgroup");

// FindMemoryLimit on this machine (the real files and sysconf's physical memory).
MemoryLimit DetectMemoryLimit();

// The budget a server uses and why: `requested_bytes` when positive (the flag), else
// kDefaultBudgetFraction of `limit`. `description` reads like "64 MiB (--memory_budget_mb)" or
// "12052 MiB (50% of physical memory 24105 MiB)".
struct BudgetChoice {
  int64_t bytes = 0;
  std::string description;
};
BudgetChoice ChooseMemoryBudget(int64_t requested_bytes, const MemoryLimit& limit);

// ChooseMemoryBudget with DetectMemoryLimit (which is only consulted when requested_bytes <= 0).
BudgetChoice ResolveMemoryBudget(int64_t requested_bytes);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_MEMORY_LIMIT_H_
