// `eval --dist DIR=KIND[,...]` (client/cli/eval_support.h): every kind reaches the request, an
// empty flag leaves the request without distributions (the original clustering, and --deviation
// still allowed), and what is not understood is named.
#include <string>

#include "client/cli/eval_support.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace splinegrid::cli {
namespace {

using ::testing::HasSubstr;

TEST(DistFlagTest, KindsReachTheRequest) {
  v1::EvaluateGridRequest request;
  ASSERT_TRUE(ParseDistributionFlag("i=arclength,j=geometric:2e-6:end,k=parameter", &request).ok());
  const v1::Distributions& d = request.distributions();
  EXPECT_EQ(d.i().kind(), v1::Distribution::KIND_UNIFORM_ARC_LENGTH);
  EXPECT_EQ(d.j().kind(), v1::Distribution::KIND_GEOMETRIC);
  EXPECT_EQ(d.j().first_spacing(), 2e-6);
  EXPECT_TRUE(d.j().from_end());
  EXPECT_EQ(d.k().kind(), v1::Distribution::KIND_UNIFORM_PARAMETER);
  v1::EvaluateGridRequest geometric;
  ASSERT_TRUE(ParseDistributionFlag("j=geometric:1e-5,i=original", &geometric).ok());
  EXPECT_FALSE(geometric.distributions().j().from_end());
  EXPECT_EQ(geometric.distributions().i().kind(), v1::Distribution::KIND_ORIGINAL);
}

TEST(DistFlagTest, AnEmptyFlagLeavesTheOriginalClustering) {
  v1::EvaluateGridRequest request;
  ASSERT_TRUE(ParseDistributionFlag("", &request).ok());
  EXPECT_FALSE(request.has_distributions());
}

TEST(DistFlagTest, WhatIsNotUnderstoodIsNamed) {
  const auto error = [](const std::string& text) {
    v1::EvaluateGridRequest request;
    return std::string(ParseDistributionFlag(text, &request).message());
  };
  EXPECT_THAT(error("q=arclength"), HasSubstr("'q=arclength' is not DIR=KIND"));
  EXPECT_THAT(error("j"), HasSubstr("'j' is not DIR=KIND"));
  EXPECT_THAT(error("j=tanh"), HasSubstr("'tanh' in 'j=tanh' is not original, parameter"));
  EXPECT_THAT(error("j=geometric"), HasSubstr("is not original, parameter"));
  EXPECT_THAT(error("j=geometric:abc"), HasSubstr("'abc' in 'j=geometric:abc' is not a number"));
  EXPECT_THAT(error("j=arclength,j=geometric:1e-5"), HasSubstr("direction j is given twice"));
  EXPECT_THAT(error("j=geometric:1e-5:start"),
              HasSubstr("'start' in 'j=geometric:1e-5:start' is not 'end'"));
}

}  // namespace
}  // namespace splinegrid::cli
