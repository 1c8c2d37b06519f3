// RemainingTimeEstimate: the ETA weighs each cell's remaining trials by its own cost.
#include "lrcal/study/remaining_time.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

namespace lrcal {
namespace {

constexpr double kTight = 1e-12;

// Issue 31: a cheap cell done first, an expensive one begun. A run-wide rate (110 trials in 2 s:
// 90 left take 1.6 s) would promise far too early an end; per cell, the 90 trials of 0.1 s left
// are 9 s of compute against 2 s done in 2 s of wall time: 9 s.
TEST(RemainingTimeEstimate, WeighsEachCellsTrialsByItsOwnCost) {
  RemainingTimeEstimate eta({100, 100});
  for (int t = 0; t < 100; ++t) eta.Record(0, 0.01);
  for (int t = 0; t < 10; ++t) eta.Record(1, 0.1);
  EXPECT_EQ(eta.remaining(), 90);
  EXPECT_NEAR(eta.SecondsLeft(2.0), 9.0, kTight);
  // Two threads did the same work in half the wall time: the pace halves the estimate.
  EXPECT_NEAR(eta.SecondsLeft(1.0), 4.5, kTight);
}

// A cell with no finished trial is costed at the mean cost per trial of the cells measured.
TEST(RemainingTimeEstimate, AnUnmeasuredCellTakesTheMeasuredMeanCost) {
  RemainingTimeEstimate eta({10, 10, 20});
  for (int t = 0; t < 10; ++t) eta.Record(0, 0.2);
  for (int t = 0; t < 5; ++t) eta.Record(1, 0.8);
  // done: 2 + 4 = 6 s over 15 trials (0.4 s each on average); left: cell 1 5 × 0.8 = 4,
  // cell 2 20 × 0.4 = 8: 12 s of work, twice what 3 s of wall time did.
  EXPECT_NEAR(eta.SecondsLeft(3.0), 6.0, kTight);
}

TEST(RemainingTimeEstimate, NoEstimateBeforeATrialAndNothingLeftAtTheEnd) {
  RemainingTimeEstimate eta({3});
  EXPECT_TRUE(std::isnan(eta.SecondsLeft(5.0)));
  for (int t = 0; t < 3; ++t) eta.Record(0, 0.5);
  EXPECT_EQ(eta.SecondsLeft(5.0), 0.0);
  eta.Record(7, 1.0);  // not a cell of the plan: ignored
  EXPECT_EQ(eta.remaining(), 0);
}

}  // namespace
}  // namespace lrcal
