// The accuracy planner's settings: targets and costs parsed with their units, ranges checked, and
// every error in the words of the front end that reads it.
#include "lrcal/report/accuracy_plan.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::HasSubstr;

std::string CliMessage(const std::function<void()>& f) {
  try {
    f();
  } catch (const SettingError& e) {
    return e.Respelled(Frontend::kCommandLine).what();
  }
  return "no error";
}

TEST(AccuracyTarget, ParsesTheMetricAndValueInItsUnit) {
  const AccuracyTarget pos = AccuracyTarget::Parse("rms_pos=0.05mm");
  EXPECT_EQ(pos.metric, ValidationMetric::kRmsPosition);
  EXPECT_DOUBLE_EQ(pos.value, 0.05e-3);
  EXPECT_EQ(pos.unit(), "mm");
  EXPECT_EQ(pos.first(), 0);
  const AccuracyTarget ori = AccuracyTarget::Parse("max_ori=0.2mrad");
  EXPECT_EQ(ori.first(), 9);
  EXPECT_DOUBLE_EQ(ori.shown(), 0.2);
  EXPECT_THAT(CliMessage([] { AccuracyTarget::Parse("rms_pos=0.05"); }),
              HasSubstr("--target: the value needs its unit (mm)"));
  EXPECT_THAT(CliMessage([] { AccuracyTarget::Parse("rms_ori=0.05mm"); }),
              HasSubstr("--target: the value needs its unit (mrad)"));
  EXPECT_THAT(CliMessage([] { AccuracyTarget::Parse("rms=1mm"); }),
              HasSubstr("expected METRIC=VALUE"));
  EXPECT_THAT(CliMessage([] { AccuracyTarget::Parse("rms_pos=-1mm"); }),
              HasSubstr("--target: expected METRIC=VALUE"));
}

TEST(CampaignCosts, ParsesSecondsPerMoveReadingAndPlane) {
  const CampaignCosts c = CampaignCosts::Parse("configuration=30s,reading=1.5s,plane=600s");
  EXPECT_EQ(c.per_configuration, 30);
  EXPECT_EQ(c.per_reading, 1.5);
  EXPECT_EQ(c.per_plane, 600);
  EXPECT_EQ(CampaignCosts::Parse("reading=2s,configuration=10s").per_plane, 0);
  EXPECT_THAT(CliMessage([] { CampaignCosts::Parse("configuration=30s"); }),
              HasSubstr("--cost: expected configuration=SECONDSs,reading=SECONDSs"));
  EXPECT_THAT(CliMessage([] { CampaignCosts::Parse("configuration=30,reading=1s"); }),
              HasSubstr("--cost"));
  EXPECT_THAT(CliMessage([] { CampaignCosts::Parse("configuration=30s,reading=1s,x=1s"); }),
              HasSubstr("--cost"));
}

TEST(AccuracyPlanOptions, ValidateNamesTheSettingInEachFrontEndsWords) {
  AccuracyPlanOptions o;
  o.target = AccuracyTarget::Parse("rms_pos=0.05mm");
  EXPECT_NO_THROW(o.Validate());
  o.confidence = 1;
  EXPECT_THAT(CliMessage([&] { o.Validate(); }),
              HasSubstr("--confidence: expected a value in (0, 1)"));
  o.confidence = 0.9;
  o.trials = 99;
  EXPECT_THAT(CliMessage([&] { o.Validate(); }), HasSubstr("--trials: expected 100 to"));
  o.trials = 1000;
  o.stop_precision = 1;
  EXPECT_THAT(CliMessage([&] { o.Validate(); }),
              HasSubstr("--stop-precision: expected a value in [0, 1)"));
  o.stop_precision = 0;
  // The command line's and Python's defaults are the struct's, through its schema.
  EXPECT_EQ(CampaignCosts{}.ToString(), "configuration=30s,reading=1s");
  EXPECT_EQ(CampaignCosts::Parse(CampaignCosts{}.ToString()).per_configuration, 30.0);
  EXPECT_EQ(FindSetting(AccuracyPlanOptions::NumericSettings(), "trials")->Default(), 10000.0);
  o.stop_precision = 0;
  o.repetitions = "5:2";
  EXPECT_THAT(CliMessage([&] { o.Validate(); }),
              HasSubstr("--repetitions: expected FIRST:LAST or FIRST:LAST:STEP"));
  try {
    o.Validate();
  } catch (const SettingError& e) {
    EXPECT_THAT(e.Respelled(Frontend::kPython).what(), HasSubstr("repetitions="));
  }
  o.repetitions = "1:10";
  o.target = AccuracyTarget{};
  EXPECT_THAT(CliMessage([&] { o.Validate(); }), HasSubstr("--target"));
}

}  // namespace
}  // namespace lrcal
