// The validation metrics' one name list: the store's columns, tables and targets are spelled
// from it.
#include "lrcal/kinematics/validation_metric.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <set>
#include <string>

namespace lrcal {
namespace {

TEST(ValidationMetric, ColumnsAreMetricMajorWithTheAxesLast) {
  EXPECT_STREQ(ValidationColumnName(0), "rms_pos_x");
  EXPECT_STREQ(ValidationColumnName(5), "rms_ori_z");
  EXPECT_STREQ(ValidationColumnName(6), "max_pos_x");
  EXPECT_STREQ(ValidationColumnName(kNumValidationColumns - 1), "max_ori_z");
  std::set<std::string> names;
  for (int k = 0; k < kNumValidationColumns; ++k) names.insert(ValidationColumnName(k));
  EXPECT_EQ(names.size(), 12u);
  EXPECT_THROW(ValidationColumnName(kNumValidationColumns), std::out_of_range);
}

TEST(ValidationMetric, UnitsFollowTheKind) {
  EXPECT_STREQ(TableUnit(ValidationMetric::kRmsPosition), "mm");
  EXPECT_STREQ(TableUnit(ValidationMetric::kMaxOrientation), "mrad");
  EXPECT_EQ(MetricOfColumn(7), ValidationMetric::kMaxPosition);
  EXPECT_EQ(ParseName(kValidationMetricNames, "rms_ori", "--target", "metric"),
            ValidationMetric::kRmsOrientation);
  EXPECT_THAT([] { ParseName(kValidationMetricNames, "rms", "--target", "metric"); },
              ::testing::ThrowsMessage<InputError>(
                  ::testing::HasSubstr("expected rms_pos, rms_ori, max_pos or max_ori")));
}

}  // namespace
}  // namespace lrcal
