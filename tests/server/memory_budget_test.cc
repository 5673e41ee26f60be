// MemoryBudget: reservations within the limit, refusals naming what needed how much, and a
// growing reservation's refusal stating what it holds already (which is counted as in use).
#include "server/memory_budget.h"

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace splinegrid::server {
namespace {

using ::testing::HasSubstr;

constexpr int64_t kMiB = int64_t{1} << 20;

TEST(MemoryBudgetTest, ReservationsHoldUntilReleased) {
  MemoryBudget budget(64 * kMiB);
  {
    absl::StatusOr<MemoryReservation> a = budget.Reserve(40 * kMiB, "a");
    ASSERT_TRUE(a.ok());
    EXPECT_EQ(budget.used(), 40 * kMiB);
    const absl::StatusOr<MemoryReservation> b = budget.Reserve(30 * kMiB, "the second upload");
    EXPECT_EQ(b.status().code(), absl::StatusCode::kResourceExhausted);
    EXPECT_THAT(b.status().message(),
                HasSubstr("the second upload needs 30 MiB but the server's memory budget has "
                          "24 MiB of 64 MiB left"));
  }
  EXPECT_EQ(budget.used(), 0);
}

TEST(MemoryBudgetTest, AGrowingReservationSaysWhatItHoldsAlready) {
  MemoryBudget budget(64 * kMiB);
  absl::StatusOr<MemoryReservation> upload = budget.Reserve(32 * kMiB, "the Plot3D upload");
  ASSERT_TRUE(upload.ok());
  const absl::Status grown = budget.Resize(&*upload, 96 * kMiB, "the Plot3D upload");
  EXPECT_EQ(grown.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(grown.message(),
              HasSubstr("the Plot3D upload needs 64 MiB more (96 MiB in all; it holds 32 MiB) "
                        "but the server's memory budget has 32 MiB of 64 MiB left"));
  EXPECT_EQ(budget.used(), 32 * kMiB);  // left as it was
  EXPECT_TRUE(budget.Resize(&*upload, 60 * kMiB, "the Plot3D upload").ok());
  EXPECT_EQ(budget.used(), 60 * kMiB);
}

}  // namespace
}  // namespace splinegrid::server
