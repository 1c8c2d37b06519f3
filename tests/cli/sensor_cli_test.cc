// `lrcal identifiability --sensor`: what a laser ranger, a tracker's reflector and a 6-D probe can
// identify on the paper's arm, as a user asks it. The slides' 25 for the ranger and Everett's
// 4R + 2P + 6 = 30 for a full-pose measurement with the instrument's frame estimated (27 with
// positions only) are computed by the rank analysis here, in text and JSON.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::HasSubstr;
using Json = nlohmann::json;

class SensorCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::TempDir("SensorCli");
    std::string out;
    ASSERT_EQ(Run("sample --count 40 --seed 3 --out " + Path("c.csv"), &out), 0) << out;
  }
  std::string Path(const std::string& name) const { return dir_ + "/" + name; }
  int Run(const std::string& args, std::string* out) const {
    return testing::RunCommand(testing::LrcalBinary() + " " + args, out);
  }
  Json Identifiability(const std::string& options) const {
    std::string out;
    EXPECT_EQ(Run("identifiability --configs " + Path("c.csv") + " --format json " + options, &out),
              0)
        << out;
    return Json::parse(out);
  }
  std::string dir_;
};

TEST_F(SensorCli, CountsTheSlidesAndEverettsIdentifiableTerms) {
  const Json ranger = Identifiability("");
  EXPECT_EQ(ranger["rank"], 25);
  EXPECT_EQ(ranger["n_params"], 25);
  EXPECT_FALSE(ranger.contains("sensor"));  // the ranger's output is what it always was
  const Json point = Identifiability("--sensor point --instrument 2.5,0.3,0.2,0,0,3");
  EXPECT_EQ(point["sensor"], "point");
  EXPECT_EQ(point["values_per_configuration"], 3);
  EXPECT_EQ(point["n_params"], 25 + 6 + 3);
  EXPECT_EQ(point["rank"], 27);
  const Json pose = Identifiability("--sensor pose --instrument 2.5,0.3,0.2,0,0,3");
  EXPECT_EQ(pose["sensor"], "pose");
  EXPECT_EQ(pose["values_per_configuration"], 6);
  EXPECT_EQ(pose["n_params"], 25 + 6 + 6);
  EXPECT_EQ(pose["rank"], 30);
  EXPECT_EQ(pose["suggested_fixed"].size(), 7u);

  std::string text;
  ASSERT_EQ(Run("identifiability --configs " + Path("c.csv") + " --sensor pose", &text), 0);
  EXPECT_THAT(text, HasSubstr("sensor: pose (x, y, z in m and an orientation in rad"));
  EXPECT_THAT(text, HasSubstr("parameters: 37, configurations: 40, rank: 30 (DEFICIENT)"));
  EXPECT_THAT(text, HasSubstr("suggested to fix:"));
}

TEST_F(SensorCli, ASecondProbeAddsItsSixTermsWhenTheTargetColumnSaysWhichIsSeen) {
  // The same configurations, alternately seeing probe 1 and probe 2.
  std::ifstream in(Path("c.csv"));
  std::ostringstream tagged;
  std::string line;
  std::getline(in, line);
  tagged << line << ",target\n";
  for (int i = 0; std::getline(in, line); ++i) tagged << line << "," << 1 + i % 2 << "\n";
  std::ofstream(Path("c.csv")) << tagged.str();
  const Json pose = Identifiability("--sensor pose --target 0,0,0.1 --target 0.05,0,0.1,0,0.5,0");
  EXPECT_EQ(pose["n_params"], 25 + 6 + 12);
  EXPECT_EQ(pose["rank"], 36);
}

}  // namespace
}  // namespace lrcal
