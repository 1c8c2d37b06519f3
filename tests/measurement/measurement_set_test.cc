// GroupReadings: readings at identical joint values become one configuration whose mean is the
// sum in reading order over the count; bad readings are refused with their location.
#include "lrcal/measurement/measurement_set.h"

#include <gtest/gtest.h>

#include "lrcal/core/error.h"

namespace lrcal {
namespace {

std::string Where(int r) { return r < 0 ? "data" : "row " + std::to_string(r); }

TEST(GroupReadings, AveragesIdenticalJointValuesInOrderOfFirstAppearance) {
  TargetedConfigurations q(2);
  q.Add({0.1, 0.2});
  q.Add({0.3, 0.4});
  q.Add({0.1, 0.2});
  q.Add({0.1, 0.2});
  const std::vector<double> h = {1.0, 2.0, 1.1, 1.3};
  const MeasurementSet data = GroupReadings(q, h, nullptr, Where);
  ASSERT_EQ(data.size(), 2);
  EXPECT_EQ(data.configs.q(0)[0], 0.1);
  EXPECT_EQ(data.configs.q(1)[1], 0.4);
  EXPECT_EQ(data.repetitions, (std::vector<int>{3, 1}));
  EXPECT_EQ(data.mean_h[0], ((1.0 + 1.1) + 1.3) / 3);  // the same bits: summed in reading order
  EXPECT_EQ(data.mean_h[1], 2.0);
}

// With a median, a configuration's value is its middle reading and its weight R/c.
TEST(GroupReadings, AMedianTakesTheMiddleReadingAndItsVarianceFactor) {
  TargetedConfigurations q(2);
  for (int r = 0; r < 5; ++r) q.Add({0.1, 0.2});
  q.Add({0.3, 0.4});
  const std::vector<double> h = {1.0, 1.2, 9.0, 1.1, 1.3, 2.0};
  const Averaging median = Averaging::Parse("median");
  const MeasurementSet data = GroupReadings(q, h, nullptr, Where, nullptr, median);
  ASSERT_EQ(data.size(), 2);
  EXPECT_EQ(data.mean_h[0], 1.2);  // the 9.0 no longer pulls it
  EXPECT_EQ(data.mean_h[1], 2.0);
  EXPECT_EQ(data.Weight(0), 5 / median.VarianceFactor(5));
  EXPECT_EQ(data.Weight(1), 1.0);  // one reading: nothing cut
}

// With labels (a `configuration` column) readings group by label: jittering joint values of
// one pose are one configuration at their mean; identical ones keep their bits.
TEST(GroupReadings, LabelsGroupJitteringJointValues) {
  TargetedConfigurations q(2);
  q.Add({0.1, 0.2});
  q.Add({0.3, 0.4});
  q.Add({0.1000002, 0.2});
  q.Add({0.1, 0.2000004});
  q.Add({0.3, 0.4});
  const std::vector<double> h = {1.0, 2.0, 1.1, 1.3, 2.2};
  const std::vector<std::string> labels = {"p1", "p2", "p1", "p1", "p2"};
  const MeasurementSet data = GroupReadings(q, h, nullptr, Where, &labels);
  ASSERT_EQ(data.size(), 2);
  EXPECT_EQ(data.repetitions, (std::vector<int>{3, 2}));
  EXPECT_DOUBLE_EQ(data.configs.q(0)[0], (0.1 + 0.1000002 + 0.1) / 3);
  EXPECT_DOUBLE_EQ(data.configs.q(0)[1], (0.2 + 0.2 + 0.2000004) / 3);
  EXPECT_EQ(data.configs.q(1)[0], 0.3);  // all agree: the recorded value itself
  EXPECT_EQ(data.mean_h[0], ((1.0 + 1.1) + 1.3) / 3);
  // Without labels the jittering readings are three configurations.
  EXPECT_EQ(GroupReadings(q, h, nullptr, Where).size(), 4);
}

TEST(GroupReadings, RefusesNonPositiveOutOfRangeAndMismatchedReadings) {
  TargetedConfigurations q(1);
  q.Add({0.0});
  q.Add({1.0});
  try {
    GroupReadings(q, {0.5, -1.0}, nullptr, Where);
    FAIL() << "a negative reading was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "row 1");
  }
  RangerSpec ranger;  // 0.05 .. 3 m
  EXPECT_THROW(GroupReadings(q, {0.5, 500.0}, &ranger, Where), InputError);
  EXPECT_NO_THROW(GroupReadings(q, {0.5, 500.0}, nullptr, Where));
  EXPECT_THROW(GroupReadings(q, {0.5}, nullptr, Where), InputError);
}

}  // namespace
}  // namespace lrcal
