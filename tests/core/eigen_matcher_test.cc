// The tests' Eigen matcher (test_util.h): it must reject what it is meant to catch, or the
// tests that use it could not fail.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>

#include "test_util.h"

namespace lrcal {
namespace {

using testing::EigenNear;

TEST(EigenNear, AcceptsWithinAndRejectsBeyondTheTolerance) {
  const Eigen::Matrix3d a = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d b = a;
  b(1, 2) = 1e-13;
  EXPECT_THAT(b, EigenNear(a, 1e-12));
  EXPECT_THAT(b, ::testing::Not(EigenNear(a, 1e-14)));
  b(1, 2) = std::nan("");
  EXPECT_THAT(b, ::testing::Not(EigenNear(a, 1.0)));
  EXPECT_THAT(Eigen::Vector3d(1, 2, 3), ::testing::Not(EigenNear(Eigen::Vector2d(1, 2), 1.0)));
}

TEST(EigenNear, SaysWhereTheLargestDeviationIs) {
  const Eigen::Vector3d expected(1, 2, 3), actual(1, 2.5, 3);
  ::testing::StringMatchResultListener listener;
  EXPECT_FALSE(::testing::ExplainMatchResult(EigenNear(expected, 0.1), actual, &listener));
  EXPECT_THAT(listener.str(), ::testing::HasSubstr("largest deviation is 0.5 at (1, 0)"));
}

}  // namespace
}  // namespace lrcal
