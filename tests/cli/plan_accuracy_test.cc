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
    // The prediction lies in the Monte-Carlo figure's 95 % interval, widened by 5 % for the
    // first-order prediction's own bias (the linearisation leaves out the curvature terms).
    const double predicted = c["predicted"].get<double>();
    EXPECT_GE(predicted, 0.95 * c["monte_carlo_ci"][0].get<double>()) << c.dump();
    EXPECT_LE(predicted, 1.05 * c["monte_carlo_ci"][1].get<double>()) << c.dump();
  }
  // The campaigns are an ordinary study, rerunnable.
  const Study s = LoadStudy(j["study"].get<std::string>());
  EXPECT_EQ(s.cells.size(), campaigns.size());
  EXPECT_EQ(s.cells[0].typed.select_count, chosen["configurations"].get<int>());
  EXPECT_EQ(s.cells[0].typed.repetitions, chosen["repetitions"].get<int>());
}

// The plan is a function of the study and its seed, not of where the study or --out are: the
// candidates and validation set are written into --out and named there, and files count by
// content in a cell's identity. (A first version drew the prediction from a stream hashed with
// --out's path, so CI's temporary folder gave another plan.)
TEST(PlanAccuracy, ThePlanDoesNotDependOnWhereItIsWritten) {
  std::string plans[2], dirs[2];
  for (int k = 0; k < 2; ++k) {
    const std::string dir = dirs[k] =
        testing::TempDir(k == 0 ? "plan_here" : "plan_elsewhere/deeper");
    const std::string study = dir + "/setup.yaml";
    std::ofstream(study) << "name: setup\nseed: 4\ntrials: 10\nrobot: "
                         << testing::SourcePath("studies/robots/paper.yaml")
                         << "\npool: {size: 60}\nvalidation: {size: 10}\n";
    std::string out;
    ASSERT_EQ(testing::RunCommand(testing::LrcalBinary() + " plan-accuracy " + study +
                                      " --target rms_pos=0.08mm --configurations 40:60:10 "
                                      "--trials 100 --out " +
                                      dir + "/plan" + std::to_string(k) + " --format json",
                                  &out),
              0)
        << out;
    Json j = Json::parse(out.substr(out.find('{')));
    for (auto& c : j["campaigns"]) plans[k] += c.dump();
  }
  EXPECT_EQ(plans[0], plans[1]);
  // The plan's folder moves: its study names the configuration files beside it.
  const std::string from = dirs[0] + "/plan0";
  const std::string to = testing::TempDir("plan_moved") + "/plan";
  std::filesystem::create_directories(to);
  for (const char* f : {"campaigns.yaml", "pool.csv", "validation.csv"})
    std::filesystem::copy_file(from + "/" + f, to + "/" + f);
  const Study original = LoadStudy(from + "/campaigns.yaml"),
              moved = LoadStudy(to + "/campaigns.yaml");
  ASSERT_EQ(original.cells.size(), moved.cells.size());
  for (std::size_t i = 0; i < moved.cells.size(); ++i)
    EXPECT_EQ(original.cells[i].id, moved.cells[i].id);
}

// --stop-precision: the confirmation runs with the adaptive stopping rule, --trials being the
// maximum: every campaign stops at a block boundary before it, the campaigns' study carries the
// rule, and a precision outside (0, 1) is exit 2.
TEST(PlanAccuracy, ConfirmationStopsWhenPreciseEnough) {
  const std::string dir = testing::TempDir("plan_accuracy_stop");
  const std::string study = dir + "/setup.yaml";
  std::ofstream(study) << "name: setup\nseed: 4\ntrials: 10\nrobot: "
                       << testing::SourcePath("studies/robots/paper.yaml")
                       << "\npool: {size: 60}\nvalidation: {size: 10}\n";
  const std::string plan = testing::LrcalBinary() + " plan-accuracy " + study +
                           " --target rms_pos=0.08mm --configurations 40:60:10 --trials 5000 "
                           "--format json --out " +
                           dir + "/plan";
  std::string out;
  ASSERT_EQ(testing::RunCommand(plan + " --stop-precision 0.1", &out), 0) << out;
  const Json j = Json::parse(out.substr(out.find('{')));
  for (const auto& c : j["campaigns"]) {
    const long long trials = c["trials"].get<long long>();
    EXPECT_LT(trials, 5000) << c.dump();
    EXPECT_EQ(trials % 500, 0) << c.dump();  // decisions at multiples of the block
  }
  const Study s = LoadStudy(j["study"].get<std::string>());
  EXPECT_TRUE(s.stop_when.enabled());
  EXPECT_EQ(s.stop_when.block, 500);
  EXPECT_EQ(testing::RunCommand(plan + " --stop-precision 1.5", &out), 2);
  EXPECT_NE(out.find("--stop-precision: expected 0 (run every trial) or a relative precision"),
            std::string::npos)
      << out;
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
