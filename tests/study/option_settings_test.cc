// The settings tables of the library's option structs (settings.h): consistent with the structs'
// own defaults, the study defaults drawn from them, library errors naming library fields.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "lrcal/core/settings.h"
#include "lrcal/identification/identification.h"
#include "lrcal/measurement/simulation.h"
#include "lrcal/study/runner.h"
#include "lrcal/study/study.h"

namespace lrcal {
namespace {

using ::testing::StartsWith;
using ::testing::ThrowsMessage;

// Every table: unique names, a default inside its own range, help for every setting.
template <class Options>
void CheckTable(const std::vector<SettingField<Options>>& fields) {
  std::set<std::string> names, members;
  for (const SettingField<Options>& f : fields) {
    SCOPED_TRACE(f.spec.Spelling(Frontend::kLibrary));
    EXPECT_TRUE(names.insert(f.spec.name).second);
    EXPECT_TRUE(members.insert(f.spec.field).second);
    EXPECT_TRUE(f.spec.Allows(f.Default() * f.spec.to_si));
    EXPECT_STRNE(f.spec.help, "");
    EXPECT_EQ(FindSetting(fields, f.spec.name), &f);
    Options o;
    f.Set(&o, f.spec.min * f.spec.to_si + (f.spec.min_exclusive ? 1e-3 : 0));
    EXPECT_NO_THROW(CheckSettings(o, fields));
  }
  EXPECT_EQ(FindSetting(fields, "no_such_setting"), nullptr);
}

TEST(Settings, TheLibrarysTablesAreConsistent) {
  CheckTable(NoiseModel::Settings());
  CheckTable(IdentificationOptions::Settings());
  CheckTable(RunOptions::Settings());
}

TEST(Settings, StudyDefaultsAreTheOptionStructsDefaults) {
  const Json& defaults = StudyDefaults();
  for (const SettingField<NoiseModel>& f : NoiseModel::Settings()) {
    ASSERT_TRUE(defaults["noise"].contains(f.spec.name)) << f.spec.name;
    EXPECT_EQ(defaults["noise"][f.spec.name].get<double>(), f.Default()) << f.spec.name;
  }
  // Plus the one setting that is not a number: noise.average.
  EXPECT_EQ(defaults["noise"].size(), NoiseModel::Settings().size() + 1);
  EXPECT_EQ(defaults["noise"]["average"], Averaging{}.Name());
  EXPECT_EQ(defaults["noise"]["sigma_mm"].get<double>(), NoiseModel{}.sigma * 1e3);
  EXPECT_EQ(defaults["identification"]["max_iterations"].get<int>(),
            IdentificationOptions{}.max_iterations);
}

TEST(Settings, RunOptionsNameTheLibraryFieldsNotTheCommandLinesOptions) {
  RunOptions o;
  o.out_dir = "run";
  o.threads = 5000;
  EXPECT_THAT([&] { o.Validate(); },
              ThrowsMessage<SettingError>(StartsWith("run.threads: expected 0 (all cores) to "
                                                     "4096 worker threads, got 5000")));
  o.threads = 0;
  o.shard_index = 3;
  o.shard_count = 2;
  EXPECT_THAT([&] { o.Validate(); }, ThrowsMessage<SettingError>(StartsWith("run.shard: ")));
  o = RunOptions{};
  try {
    o.Validate();
    FAIL() << "an empty run directory was accepted";
  } catch (const SettingError& e) {
    EXPECT_STREQ(e.Respelled(Frontend::kCommandLine).what(),
                 "--out: expected a run directory, got an empty name");
    EXPECT_THAT(e.Respelled(Frontend::kPython).what(), StartsWith("out_dir=: "));
  }
}

}  // namespace
}  // namespace lrcal
