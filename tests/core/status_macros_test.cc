// SG_RETURN_IF_ERROR and SG_ASSIGN_OR_RETURN, plain and with an annotation.
#include "core/util/status_macros.h"

#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/cord.h"
#include "gtest/gtest.h"

namespace splinegrid {
namespace {

int annotations_built = 0;

// Counts how often an annotation is built: only on the error path.
std::string Where(int b) {
  ++annotations_built;
  return "block " + std::to_string(b) + ": ";
}

absl::Status Check(absl::Status status, bool annotate) {
  if (annotate) {
    SG_RETURN_IF_ERROR(status, Where(3));
  } else {
    SG_RETURN_IF_ERROR(status);
  }
  return absl::OkStatus();
}

absl::StatusOr<int> Twice(absl::StatusOr<int> value, bool annotate) {
  int x = 0;
  if (annotate) {
    SG_ASSIGN_OR_RETURN(x, value, "value ", 7, " of ", Where(2));
  } else {
    SG_ASSIGN_OR_RETURN(x, value);
  }
  return 2 * x;
}

TEST(StatusMacrosTest, AnnotationPrefixesTheMessageAndKeepsCodeAndPayloads) {
  absl::Status error = absl::NotFoundError("no such face");
  error.SetPayload("type.googleapis.com/splinegrid.test", absl::Cord("detail"));
  const absl::Status annotated = Check(error, /*annotate=*/true);
  EXPECT_EQ(annotated.code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(annotated.message(), "block 3: no such face");
  ASSERT_TRUE(annotated.GetPayload("type.googleapis.com/splinegrid.test").has_value());
  EXPECT_EQ(*annotated.GetPayload("type.googleapis.com/splinegrid.test"), "detail");
  EXPECT_EQ(Check(error, /*annotate=*/false), error);
}

TEST(StatusMacrosTest, AssignOrReturnAnnotatesOnlyErrors) {
  annotations_built = 0;
  EXPECT_EQ(Twice(21, /*annotate=*/true).value(), 42);
  EXPECT_EQ(Check(absl::OkStatus(), /*annotate=*/true), absl::OkStatus());
  EXPECT_EQ(annotations_built, 0);
  const absl::StatusOr<int> failed = Twice(absl::OutOfRangeError("too far"), /*annotate=*/true);
  EXPECT_EQ(failed.status().code(), absl::StatusCode::kOutOfRange);
  EXPECT_EQ(failed.status().message(), "value 7 of block 2: too far");
  EXPECT_EQ(annotations_built, 1);
  EXPECT_EQ(Twice(absl::OutOfRangeError("too far"), /*annotate=*/false).status().message(),
            "too far");
}

}  // namespace
}  // namespace splinegrid
