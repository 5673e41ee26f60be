#include "server/memory_limit.h"

#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace splinegrid::server {
namespace {

// v1 reports "no limit" as LONG_MAX rounded down to the page size; no real limit is this large.
constexpr int64_t kUnlimitedAtLeast = int64_t{1} << 62;

// "/a/b" -> {"/a/b", "/a", ""}: the group and its ancestors, as suffixes of the mount point.
std::vector<std::string> GroupAndAncestors(std::string path) {
  std::vector<std::string> out;
  while (!path.empty() && path.back() == '/') path.pop_back();
  for (;;) {
    out.push_back(path);
    if (path.empty()) break;
    const size_t slash = path.rfind('/');
    path.resize(slash == std::string::npos ? 0 : slash);
  }
  return out;
}

}  // namespace

absl::StatusOr<std::optional<int64_t>> ParseCgroupLimit(absl::string_view text) {
  const absl::string_view value = absl::StripAsciiWhitespace(text);
  if (value == "max") return std::nullopt;
  int64_t bytes = 0;
  if (!absl::SimpleAtoi(value, &bytes) || bytes < 0) {
    return absl::InvalidArgumentError(absl::StrCat("cgroup memory limit '", value.substr(0, 40),
                                                   "': expected 'max' or a byte count"));
  }
  if (bytes >= kUnlimitedAtLeast) return std::nullopt;
  return bytes;
}

CgroupPaths ParseProcSelfCgroup(absl::string_view text) {
  CgroupPaths paths;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    // hierarchy-ID:controller-list:cgroup-path (the path may itself contain ':').
    const std::vector<absl::string_view> fields = absl::StrSplit(line, absl::MaxSplits(':', 2));
    if (fields.size() != 3) continue;
    if (fields[0] == "0" && fields[1].empty()) {
      paths.v2 = std::string(fields[2]);
      continue;
    }
    for (absl::string_view controller : absl::StrSplit(fields[1], ',')) {
      if (controller == "memory") paths.v1_memory = std::string(fields[2]);
    }
  }
  return paths;
}

MemoryLimit FindMemoryLimit(
    const std::function<std::optional<std::string>(const std::string&)>& read_file,
    int64_t physical_bytes, const std::string& root) {
  MemoryLimit limit{physical_bytes, "physical memory", std::nullopt};
  const std::optional<std::string> self = read_file("/proc/self/cgroup");
  const CgroupPaths paths = ParseProcSelfCgroup(self.value_or(""));
  std::optional<int64_t> headroom;
  auto consider = [&](const std::string& file, const std::string& usage_file) {
    const std::optional<std::string> text = read_file(file);
    if (!text) return;
    const absl::StatusOr<std::optional<int64_t>> bytes = ParseCgroupLimit(*text);
    if (!bytes.ok() || !bytes->has_value()) return;
    if (**bytes < limit.bytes) {
      limit = MemoryLimit{**bytes, absl::StrCat("cgroup limit (", file, ")"), std::nullopt};
    }
    const std::optional<std::string> usage_text = read_file(usage_file);
    const absl::StatusOr<std::optional<int64_t>> usage =
        usage_text ? ParseCgroupLimit(*usage_text) : absl::NotFoundError(usage_file);
    if (usage.ok() && usage->has_value()) {
      const int64_t left = std::max<int64_t>(0, **bytes - **usage);
      headroom = headroom ? std::min(*headroom, left) : left;
    }
  };
  // Without a /proc/self/cgroup line the mount's own files are still the process's group in a
  // container with a cgroup namespace, so the root files are always read.
  for (const std::string& group : GroupAndAncestors(paths.v2)) {
    const std::string dir = absl::StrCat(root, group);
    consider(dir + "/memory.max", dir + "/memory.current");
  }
  for (const std::string& group : GroupAndAncestors(paths.v1_memory)) {
    const std::string dir = absl::StrCat(root, "/memory", group);
    consider(dir + "/memory.limit_in_bytes", dir + "/memory.usage_in_bytes");
  }
  limit.headroom = headroom;
  return limit;
}

MemoryLimit DetectMemoryLimit() {
  const int64_t physical = int64_t{sysconf(_SC_PHYS_PAGES)} * int64_t{sysconf(_SC_PAGESIZE)};
  return FindMemoryLimit(
      [](const std::string& path) -> std::optional<std::string> {
        std::ifstream in(path);
        if (!in) return std::nullopt;
        std::ostringstream text;
        text << in.rdbuf();
        return text.str();
      },
      physical);
}

BudgetChoice ChooseMemoryBudget(int64_t requested_bytes, const MemoryLimit& limit) {
  if (requested_bytes > 0) {
    return {requested_bytes, absl::StrCat(requested_bytes >> 20, " MiB (--memory_budget_mb)")};
  }
  const int64_t bytes = std::max<int64_t>(
      static_cast<int64_t>(static_cast<double>(limit.bytes) * kDefaultBudgetFraction),
      int64_t{1} << 20);
  return {bytes,
          absl::StrCat(bytes >> 20, " MiB (", static_cast<int>(kDefaultBudgetFraction * 100 + 0.5),
                       "% of ", limit.source, " ", limit.bytes >> 20, " MiB)")};
}

BudgetChoice ResolveMemoryBudget(int64_t requested_bytes) {
  if (requested_bytes > 0) return ChooseMemoryBudget(requested_bytes, MemoryLimit{});
  return ChooseMemoryBudget(requested_bytes, DetectMemoryLimit());
}

}  // namespace splinegrid::server
