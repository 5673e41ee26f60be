// The default memory budget: cgroup limit files parsed from their contents, the process's groups
// from /proc/self/cgroup, and the choice among cgroup v2, v1 and physical memory.
#include "server/memory_limit.h"

#include <map>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace splinegrid::server {
namespace {

constexpr int64_t kGiB = int64_t{1} << 30;
constexpr int64_t kMiB = int64_t{1} << 20;

TEST(ParseCgroupLimitTest, MaxAndHugeValuesAreUnlimited) {
  EXPECT_EQ(ParseCgroupLimit("max\n").value(), std::nullopt);
  EXPECT_EQ(ParseCgroupLimit("9223372036854771712\n").value(), std::nullopt);  // v1 "none"
  EXPECT_EQ(ParseCgroupLimit("4611686018427387904").value(), std::nullopt);    // 2^62
}

TEST(ParseCgroupLimitTest, NumbersAreBytes) {
  EXPECT_EQ(ParseCgroupLimit("1073741824\n").value(), std::optional<int64_t>(kGiB));
  EXPECT_EQ(ParseCgroupLimit("  268435456  ").value(), std::optional<int64_t>(256 * kMiB));
  EXPECT_EQ(ParseCgroupLimit("0").value(), std::optional<int64_t>(0));
}

TEST(ParseCgroupLimitTest, GarbageIsInvalid) {
  for (const char* text : {"", "\n", "-1", "1G", "max max", "12 34"}) {
    EXPECT_EQ(ParseCgroupLimit(text).status().code(), absl::StatusCode::kInvalidArgument) << text;
  }
}

TEST(ParseProcSelfCgroupTest, FindsV2AndV1MemoryPaths) {
  const CgroupPaths hybrid = ParseProcSelfCgroup(
      "9:name=systemd:/\n4:memory:/process_api/d0b0\n3:cpu,cpuacct:/x\n0::/user.slice/a\n");
  EXPECT_EQ(hybrid.v2, "/user.slice/a");
  EXPECT_EQ(hybrid.v1_memory, "/process_api/d0b0");
  const CgroupPaths joined = ParseProcSelfCgroup("5:cpu,memory:/docker/abc\n");
  EXPECT_EQ(joined.v1_memory, "/docker/abc");
  EXPECT_EQ(joined.v2, "");
  const CgroupPaths v2 = ParseProcSelfCgroup("0::/\n");
  EXPECT_EQ(v2.v2, "/");
  EXPECT_EQ(ParseProcSelfCgroup("").v1_memory, "");
}

// A fake file system for FindMemoryLimit.
class FakeFiles {
 public:
  std::map<std::string, std::string> files;
  std::function<std::optional<std::string>(const std::string&)> reader() const {
    return [this](const std::string& path) -> std::optional<std::string> {
      auto it = files.find(path);
      if (it == files.end()) return std::nullopt;
      return it->second;
    };
  }
};

TEST(FindMemoryLimitTest, NoFilesMeansPhysicalMemory) {
  FakeFiles fs;
  const MemoryLimit limit = FindMemoryLimit(fs.reader(), 24 * kGiB);
  EXPECT_EQ(limit.bytes, 24 * kGiB);
  EXPECT_EQ(limit.source, "physical memory");
}

TEST(FindMemoryLimitTest, V2MaxIsUnlimited) {
  FakeFiles fs;
  fs.files["/proc/self/cgroup"] = "0::/app\n";
  fs.files["/sys/fs/cgroup/app/memory.max"] = "max\n";
  EXPECT_EQ(FindMemoryLimit(fs.reader(), 8 * kGiB).bytes, 8 * kGiB);
}

TEST(FindMemoryLimitTest, V2LimitOfTheGroupOrAnAncestor) {
  FakeFiles fs;
  fs.files["/proc/self/cgroup"] = "0::/kubepods/pod1/c1\n";
  fs.files["/sys/fs/cgroup/kubepods/pod1/c1/memory.max"] = "max\n";
  fs.files["/sys/fs/cgroup/kubepods/pod1/memory.max"] = "2147483648\n";
  fs.files["/sys/fs/cgroup/kubepods/memory.max"] = "4294967296\n";
  const MemoryLimit limit = FindMemoryLimit(fs.reader(), 24 * kGiB);
  EXPECT_EQ(limit.bytes, 2 * kGiB);
  EXPECT_EQ(limit.source, "cgroup limit (/sys/fs/cgroup/kubepods/pod1/memory.max)");
}

// What a limited group has left, for a client sharing it (the CLI's evaluation guard): the
// smallest limit minus usage over the limited groups.
TEST(FindMemoryLimitTest, HeadroomIsTheLeastThatALimitedGroupHasLeft) {
  FakeFiles fs;
  fs.files["/proc/self/cgroup"] = "0::/job/step\n";
  fs.files["/sys/fs/cgroup/job/step/memory.max"] = "max\n";
  fs.files["/sys/fs/cgroup/job/step/memory.current"] = "100\n";
  fs.files["/sys/fs/cgroup/job/memory.max"] = "4294967296\n";      // 4 GiB
  fs.files["/sys/fs/cgroup/job/memory.current"] = "3221225472\n";  // 3 GiB used
  fs.files["/sys/fs/cgroup/memory.max"] = "8589934592\n";          // 8 GiB
  fs.files["/sys/fs/cgroup/memory.current"] = "1073741824\n";      // 1 GiB used
  const MemoryLimit limit = FindMemoryLimit(fs.reader(), 24 * kGiB);
  EXPECT_EQ(limit.bytes, 4 * kGiB);
  EXPECT_EQ(limit.headroom, kGiB);
  fs.files["/sys/fs/cgroup/job/memory.current"] = "5368709120\n";  // over its limit
  EXPECT_EQ(FindMemoryLimit(fs.reader(), 24 * kGiB).headroom, 0);
  EXPECT_FALSE(FindMemoryLimit(FakeFiles().reader(), 24 * kGiB).headroom.has_value());
}

TEST(FindMemoryLimitTest, V2InACgroupNamespaceReadsTheMountRoot) {
  FakeFiles fs;
  fs.files["/proc/self/cgroup"] = "0::/\n";
  fs.files["/sys/fs/cgroup/memory.max"] = "536870912\n";
  EXPECT_EQ(FindMemoryLimit(fs.reader(), 24 * kGiB).bytes, 512 * kMiB);
}

TEST(FindMemoryLimitTest, V1Limit) {
  FakeFiles fs;
  fs.files["/proc/self/cgroup"] = "4:memory:/docker/abc\n0::/\n";
  fs.files["/sys/fs/cgroup/memory/docker/abc/memory.limit_in_bytes"] = "1073741824\n";
  fs.files["/sys/fs/cgroup/memory/memory.limit_in_bytes"] = "9223372036854771712\n";
  const MemoryLimit limit = FindMemoryLimit(fs.reader(), 24 * kGiB);
  EXPECT_EQ(limit.bytes, kGiB);
  EXPECT_THAT(limit.source, ::testing::HasSubstr("memory.limit_in_bytes"));
}

TEST(FindMemoryLimitTest, V1UnlimitedAndGarbageFallBackToPhysical) {
  FakeFiles fs;
  fs.files["/proc/self/cgroup"] = "4:memory:/x\n";
  fs.files["/sys/fs/cgroup/memory/x/memory.limit_in_bytes"] = "9223372036854771712\n";
  fs.files["/sys/fs/cgroup/memory/memory.limit_in_bytes"] = "not a number\n";
  EXPECT_EQ(FindMemoryLimit(fs.reader(), 3 * kGiB).source, "physical memory");
}

TEST(FindMemoryLimitTest, LimitAbovePhysicalMemoryIsPhysical) {
  FakeFiles fs;
  fs.files["/proc/self/cgroup"] = "0::/big\n";
  fs.files["/sys/fs/cgroup/big/memory.max"] = "68719476736\n";  // 64 GiB
  EXPECT_EQ(FindMemoryLimit(fs.reader(), 24 * kGiB).bytes, 24 * kGiB);
}

TEST(ChooseMemoryBudgetTest, HalfOfTheLimitUnlessRequested) {
  const BudgetChoice auto_budget =
      ChooseMemoryBudget(0, MemoryLimit{24 * kGiB, "physical memory", {}});
  EXPECT_EQ(auto_budget.bytes, 12 * kGiB);
  EXPECT_EQ(auto_budget.description, "12288 MiB (50% of physical memory 24576 MiB)");
  const BudgetChoice flag = ChooseMemoryBudget(64 * kMiB, MemoryLimit{24 * kGiB, "x", {}});
  EXPECT_EQ(flag.bytes, 64 * kMiB);
  EXPECT_EQ(flag.description, "64 MiB (--memory_budget_mb)");
  // A tiny limit still leaves a usable budget.
  EXPECT_EQ(ChooseMemoryBudget(0, MemoryLimit{1000, "cgroup", {}}).bytes, kMiB);
}

TEST(DetectMemoryLimitTest, ThisMachineHasAPositiveLimit) {
  const MemoryLimit limit = DetectMemoryLimit();
  EXPECT_GT(limit.bytes, 0);
  EXPECT_FALSE(limit.source.empty());
}

}  // namespace
}  // namespace splinegrid::server
