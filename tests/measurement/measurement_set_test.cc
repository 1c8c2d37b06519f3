// GroupReadings: readings at identical joint values become one configuration whose mean is the
// sum in reading order over the count; bad readings are refused with their location.
#include "lrcal/measurement/measurement_set.h"

#include <gtest/gtest.h>

#include "lrcal/core/error.h"

namespace lrcal {
namespace {

std::string Where(int r) { return r < 0 ? "data" : "row " + std::to_string(r); }

TEST(GroupReadings, AveragesIdenticalJointValuesInOrderOfFirstAppearance) {
  ConfigurationSet q(2);
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

TEST(GroupReadings, RefusesNonPositiveOutOfRangeAndMismatchedReadings) {
  ConfigurationSet q(1);
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
