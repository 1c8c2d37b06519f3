// The settings schema: spellings per front end, the expected-value wording, ranges at their
// edges, SI conversion. The option structs' tables: tests/study/option_settings_test.cc.
#include "lrcal/core/settings.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace lrcal {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

const SettingSpec kSigma{"noise", "sigma", "sigma_mm", "mm", 1e-3, "m", 0, kInf, false, false};
const SettingSpec kCount{"noise",
                         "repetitions",
                         "repetitions",
                         "",
                         1,
                         "",
                         1,
                         1e6,
                         false,
                         true,
                         "readings per configuration"};
const SettingSpec kScale{
    "identification",      "loss_scale", "loss_scale_mm", "mm", 1e-3, "m", 0, kInf,
    /*min_exclusive=*/true};

TEST(Settings, EachFrontEndSpellsTheSettingItsOwnWay) {
  EXPECT_EQ(kSigma.Spelling(Frontend::kLibrary), "noise.sigma");
  EXPECT_EQ(kSigma.Spelling(Frontend::kStudyFile), "noise.sigma_mm");
  EXPECT_EQ(kSigma.Spelling(Frontend::kCommandLine), "--sigma-mm");
  EXPECT_EQ(kSigma.Spelling(Frontend::kPython), "sigma_mm=");
  SettingSpec out = kSigma;
  out.name = "out";
  out.python_name = "out_dir";
  EXPECT_EQ(out.Spelling(Frontend::kCommandLine), "--out");
  EXPECT_EQ(out.Spelling(Frontend::kPython), "out_dir=");
}

TEST(Settings, RangesHoldAtTheirEdges) {
  EXPECT_TRUE(kSigma.Allows(0));
  EXPECT_FALSE(kSigma.Allows(-1e-300));
  EXPECT_FALSE(kSigma.Allows(kInf));
  EXPECT_FALSE(kSigma.Allows(std::nan("")));
  EXPECT_FALSE(kScale.Allows(0));  // exclusive
  EXPECT_TRUE(kScale.Allows(1e-300));
  EXPECT_TRUE(kCount.Allows(1));
  EXPECT_TRUE(kCount.Allows(1e6));
  EXPECT_FALSE(kCount.Allows(1e6 + 1));
  EXPECT_FALSE(kCount.Allows(0));
  EXPECT_FALSE(kCount.Allows(2.5));  // whole numbers only
}

// Open ends: a relative tolerance in [0, 1), an angle in (0, 90] degrees; each says which ends
// it excludes.
TEST(Settings, ExclusiveEndsAreRefusedAndSaidSo) {
  SettingSpec tolerance{"t", "tol", "tol", "", 1, "", 0, 1};
  tolerance.max_exclusive = true;
  EXPECT_TRUE(tolerance.Allows(0));
  EXPECT_TRUE(tolerance.Allows(std::nextafter(1.0, 0.0)));
  EXPECT_FALSE(tolerance.Allows(1));
  EXPECT_EQ(tolerance.Expected(), "expected a value in [0, 1)");
  const SettingSpec angle{"r", "a", "a_deg", "deg", M_PI / 180, "rad", 0, 90, true};
  EXPECT_FALSE(angle.Allows(0));
  EXPECT_TRUE(angle.Allows(90 * (M_PI / 180)));
  EXPECT_EQ(angle.Expected(), "expected a value in (0, 90] (deg)");
}

TEST(Settings, TheLibraryNamesItsFieldInSiAndFrontEndsRespellIt) {
  EXPECT_THAT([] { kSigma.Check(-2e-4); },
              ThrowsMessage<SettingError>(
                  ::testing::StrEq("noise.sigma: expected a finite value >= 0 (m), got -0.0002")));
  try {
    kSigma.Check(-2e-4);
    FAIL() << "no error";
  } catch (const SettingError& e) {
    EXPECT_EQ(e.where(), "noise.sigma");
    EXPECT_STREQ(e.Respelled(Frontend::kCommandLine).what(),
                 "--sigma-mm: expected a finite value >= 0 (mm), got -0.2");
    EXPECT_STREQ(e.Respelled(Frontend::kPython).what(),
                 "sigma_mm=: expected a finite value >= 0 (mm), got -0.2");
    EXPECT_STREQ(e.Respelled(Frontend::kStudyFile, "s.yaml:4 key 'noise.sigma_mm'").what(),
                 "s.yaml:4 key 'noise.sigma_mm': expected a finite value >= 0 (mm), got -0.2");
  }
  EXPECT_THAT([] { kCount.Check(0); },
              ThrowsMessage<SettingError>(HasSubstr("expected 1 to 1,000,000 readings per "
                                                    "configuration, got 0")));
  EXPECT_THAT([] { kScale.Check(0); },
              ThrowsMessage<SettingError>(HasSubstr("expected a finite value > 0 (m)")));
}

// Advice that names another setting is in each reader's words too: {i} is the setting, {i:v}
// the setting given v; braces that are not a mention stay as written.
TEST(Settings, OtherSettingsNamedInAProblemAreRespelledWithIt) {
  const SettingSpec plan_on = SettingSpec::Named("plan", "plan_on", "plan_on");
  const SettingError e(kSigma, "too small for {x}; raise {0} or set {1:data}", {kCount, plan_on});
  EXPECT_STREQ(e.what(),
               "noise.sigma: too small for {x}; raise noise.repetitions or set plan.plan_on: data");
  EXPECT_STREQ(e.Respelled(Frontend::kCommandLine).what(),
               "--sigma-mm: too small for {x}; raise --repetitions or set --plan-on data");
  EXPECT_STREQ(e.Respelled(Frontend::kPython).what(),
               "sigma_mm=: too small for {x}; raise repetitions= or set plan_on='data'");
  EXPECT_STREQ(e.Respelled(Frontend::kStudyFile, "s.yaml:2").what(),
               "s.yaml:2: too small for {x}; raise noise.repetitions or set plan.plan_on: data");
  EXPECT_STREQ(SettingError(kSigma, "{2} and {", {kCount}).what(), "noise.sigma: {2} and {");
  EXPECT_STREQ(SettingError(kSigma, "got '{99999999999999999999}'", {kCount}).what(),
               "noise.sigma: got '{99999999999999999999}'");
}

TEST(Settings, SiValuesReadBackInTheSettingsUnitWithoutRoundingNoise) {
  EXPECT_EQ(kSigma.FromSi(0.2e-3), 0.2);  // 0.2e-3 / 1e-3 is 0.19999999999999998
  EXPECT_EQ(kSigma.FromSi(5e-3), 5.0);
  EXPECT_EQ(kCount.FromSi(10), 10.0);
}

}  // namespace
}  // namespace lrcal
