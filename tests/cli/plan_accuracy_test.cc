// lrcal plan-accuracy end to end on a small set-up: the cheapest campaign by the first-order
// prediction, confirmed by Monte Carlo, written as a study that runs again; bad options exit 2.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "lrcal/study/study.h"
#include "test_util.h"

namespace lrcal {
namespace {

using Json = nlohmann::json;

TEST(PlanAccuracy, FindsTheCheapestCampaignAndConfirmsIt) {
  const std::string dir = testing::TempDir("plan_accuracy");
  const std::string study = dir + "/setup.yaml";
  std::ofstream(study) << "name: setup\nseed: 4\ntrials: 10\nrobot: "
                       << testing::SourcePath("studies/robots/paper.yaml")
                       << "\npool: {size: 60}\nvalidation: {size: 10}\n";
  std::string out;
  ASSERT_EQ(testing::RunCommand(testing::LrcalBinary() + " plan-accuracy " + study +
                                    " --target rms_pos=0.08mm --configurations 30:60:10 "
                                    "--trials 400 --out " +
                                    dir + "/plan --format json",
                                &out),
            0)
      << out;
  const Json j = Json::parse(out.substr(out.find('{')));
  const Json& campaigns = j["campaigns"];
  ASSERT_GE(campaigns.size(), 2u);
  const Json& chosen = campaigns[0];
  EXPECT_EQ(chosen["label"], "chosen");
  EXPECT_LE(chosen["predicted"].get<double>(), 0.08);
  for (const auto& c : campaigns) {
    if (c["label"] == "one reading fewer") {
      EXPECT_GT(c["predicted"].get<double>(), 0.08);  // just beyond the target by prediction
      EXPECT_LT(c["cost_seconds"].get<double>(), chosen["cost_seconds"].get<double>());
    } else {
      EXPECT_GE(c["cost_seconds"].get<double>(), chosen["cost_seconds"].get<double>());
    }
    EXPECT_EQ(c["trials"], 400);
    // The Monte-Carlo figure agrees with the prediction to a few per cent.
    EXPECT_NEAR(c["monte_carlo"].get<double>() / c["predicted"].get<double>(), 1.0, 0.08);
  }
  // The campaigns are an ordinary study, rerunnable.
  const Study s = LoadStudy(j["study"].get<std::string>());
  EXPECT_EQ(s.cells.size(), campaigns.size());
  EXPECT_EQ(s.cells[0].typed.select_count, chosen["configurations"].get<int>());
  EXPECT_EQ(s.cells[0].typed.repetitions, chosen["repetitions"].get<int>());
}

TEST(PlanAccuracy, BadTargetsAndRangesAreExitTwo) {
  std::string out;
  EXPECT_EQ(
      testing::RunCommand(testing::LrcalBinary() + " plan-accuracy --target rms_pos=0.05", &out),
      2);
  EXPECT_NE(out.find("--target"), std::string::npos) << out;
  EXPECT_NE(out.find("needs its unit (mm)"), std::string::npos) << out;
  EXPECT_EQ(testing::RunCommand(
                testing::LrcalBinary() + " plan-accuracy --target rms_pos=0.05mm --repetitions 5:1",
                &out),
            2);
  EXPECT_NE(out.find("--repetitions"), std::string::npos) << out;
  EXPECT_EQ(
      testing::RunCommand(
          testing::LrcalBinary() + " plan-accuracy --target rms_pos=0.05mm --cost walk=3s", &out),
      2);
  EXPECT_NE(out.find("--cost"), std::string::npos) << out;
}

}  // namespace
}  // namespace lrcal
