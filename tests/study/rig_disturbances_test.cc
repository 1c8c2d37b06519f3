// A real rig's disturbances as study axes: outliers cost accuracy and a robust loss buys it back;
// encoder noise and plane form error, which least squares cannot see, add to the validation
// errors beyond the parameter covariance's prediction; a study without them keeps its numbers.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <map>

#include "lrcal/core/error.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/study/runner.h"
#include "lrcal/study/statistics.h"
#include "lrcal/study/study.h"
#include "lrcal/study/trial_store.h"
#include "run_summaries.h"
#include "study/trial_pipeline.h"
#include "test_util.h"

namespace lrcal {
namespace {

// Mean RMS position error (x, y, z averaged; m) and its SE of every cell, in study order.
std::vector<std::pair<double, double>> RmsPosition(const std::string& dir, const std::string& body,
                                                   int trials) {
  std::ofstream(dir + "/s.yaml") << "name: rig\nseed: 11\ntrials: " << trials
                                 << "\npool: {size: 60}\nselection: {count: 40}\n"
                                    "validation: {size: 10}\n"
                                 << body;
  EXPECT_TRUE(testing::RunStudyFile(dir + "/s.yaml", dir + "/run", 2).complete);
  std::vector<std::pair<double, double>> out;
  for (const CellSummary& s : testing::SummarizeRun(dir + "/run")) {
    double mean = 0, var = 0;
    for (int a = 0; a < 3; ++a) {
      mean += s.validation[a].mean / 3;
      var += s.validation[a].mean_se * s.validation[a].mean_se / 9;  // upper bound: correlated
    }
    out.emplace_back(mean, 3 * std::sqrt(var));
  }
  return out;
}

TEST(RigDisturbances, ARobustLossBuysBackWhatOutliersCost) {
  const std::string dir = testing::TempDir("rig_outliers");
  // One reading per configuration: without outliers, then 5 % of readings off by N(0, 5 mm) with
  // least squares and with Huber at 1.345 σ, on the same readings (common random numbers).
  const auto cells =
      RmsPosition(dir,
                  "noise: {repetitions: 1}\n"
                  "sweep:\n  axes:\n    - {key: '.', values: [{}, "
                  "{noise: {outlier_fraction: 0.05}}, "
                  "{noise: {outlier_fraction: 0.05}, identification: {loss: huber}}]}\n",
                  150);
  ASSERT_EQ(cells.size(), 3u);
  const auto& [clean, clean_se] = cells[0];
  const auto& [ls, ls_se] = cells[1];
  EXPECT_GT(ls - 3 * ls_se, clean + 3 * clean_se) << "clean " << clean << ", outliers " << ls;
  // Huber buys back at least half of what outliers cost: per trial (the three cells see the same
  // readings), d = (least squares − Huber) − ½·(least squares − clean), whose mean must be
  // positive by 3 standard errors.
  TrialStore store(dir + "/run/trials.sqlite");
  std::vector<std::map<long long, double>> rms(3);
  const std::vector<StoredCell> stored = store.Cells();
  for (int c = 0; c < 3; ++c)
    store.ForEachTrial(stored[c].id, [&](const TrialRecord& r) {
      if (r.status == TrialStatus::kOk)
        rms[c][r.trial] = (r.validation[0] + r.validation[1] + r.validation[2]) / 3;
    });
  std::vector<double> d;
  for (const auto& [t, value] : rms[1])
    if (rms[0].count(t) && rms[2].count(t))
      d.push_back((value - rms[2][t]) - 0.5 * (value - rms[0][t]));
  const Distribution paired = Describe(d);
  EXPECT_GT(paired.mean - 3 * paired.mean_se, 0.0)
      << "mean " << paired.mean << " ± " << paired.mean_se << " over " << paired.n << " trials";
}

TEST(RigDisturbances, EncoderNoiseAndFormErrorCostAccuracy) {
  const std::string dir = testing::TempDir("rig_encoder");
  const auto cells = RmsPosition(dir,
                                 "sweep:\n  axes:\n    - {key: '.', values: [{}, "
                                 "{noise: {encoder_sigma_mrad: 0.2}}, "
                                 "{noise: {form_sigma_mm: 0.1}}]}\n",
                                 150);
  ASSERT_EQ(cells.size(), 3u);
  for (int k : {1, 2})
    EXPECT_GT(cells[k].first - 3 * cells[k].second, cells[0].first + 3 * cells[0].second)
        << "cell " << k << ": " << cells[k].first << " against " << cells[0].first;
}

// A ranger with a zero offset (robot file true_errors) and identification.estimate_ranger: the
// offset is a translation along the beam like d6 (o and d6 both +t leave every reading as it
// is), so with d6 fixed at nominal the estimated offset is o − 0.85 mm (d6's true error) and
// otherwise unbiased. The file's scale error is read (and 0 here: unestimated, it would bias).
TEST(RigDisturbances, RangerErrorsFromTheRobotFileAreEstimated) {
  const std::string dir = testing::TempDir("rig_ranger");
  std::string robot = testing::ReadFile(testing::SourcePath("studies/robots/paper.yaml"));
  const std::string anchor = "  length_unit: mm\n";
  robot.replace(robot.find(anchor), anchor.size(),
                anchor + "  ranger_offset_mm: 0.3\n  ranger_scale_ppm: 0\n");
  std::ofstream(dir + "/ranger.yaml") << robot;
  std::ofstream(dir + "/s.yaml")
      << "name: ranger\nseed: 3\ntrials: 300\nrobot: ranger.yaml\npool: {size: 80}\n"
         "selection: {count: 60}\nvalidation: {size: 10}\n"
         "identification: {estimate_ranger: offset, fix: [d6]}\n";
  ASSERT_TRUE(testing::RunStudyFile(dir + "/s.yaml", dir + "/run", 2).complete);
  TrialStore store(dir + "/run/trials.sqlite");
  const CellSummary s = SummarizeCell(store, store.Cells().at(0));
  ASSERT_GT(s.ok, 290);
  bool found = false;
  for (const ParameterStats& p : s.parameters) {
    if (p.name != "ranger_offset") continue;
    found = true;
    // Bias against the true offset: minus d6's error, within 4 standard errors.
    EXPECT_NEAR(p.bias, -0.85e-3, 4 * p.bias_se) << p.bias << " ± " << p.bias_se;
  }
  EXPECT_TRUE(found);
  const std::string csv = testing::ReadFile(dir + "/run/tables/parameters.csv");
  EXPECT_THAT(csv, ::testing::HasSubstr("ranger_offset,mm"));
  // The robot file's ranger errors, in SI.
  robot.replace(robot.find("ranger_scale_ppm: 0"), 19, "ranger_scale_ppm: 150");
  std::ofstream(dir + "/ranger2.yaml") << robot;
  const RobotFile file = LoadRobotFile(dir + "/ranger2.yaml");
  EXPECT_DOUBLE_EQ(file.truth.ranger_offset, 0.3e-3);
  EXPECT_DOUBLE_EQ(file.truth.ranger_scale, 150e-6);
}

// truth.ranger_offset_mm / ranger_scale_ppm override the robot file's ranger errors as sweep
// values; cells that differ only in them share their pool, design and validation set (the errors
// do not change which beams hit), so their numbers differ by the ranger alone.
TEST(RigDisturbances, RangerTruthAsASweepAxisKeepsTheDesign) {
  const std::string dir = testing::TempDir("rig_ranger_axis");
  std::ofstream(dir + "/s.yaml") << "name: s\nseed: 2\ntrials: 2\npool: {size: 60}\n"
                                    "selection: {count: 40}\nvalidation: {size: 10}\nsweep:\n"
                                    "  axes:\n    - {key: truth.ranger_offset_mm, values: "
                                    "[robot_file, 0.5]}\n";
  const Study study = LoadStudy(dir + "/s.yaml");
  ASSERT_EQ(study.cells.size(), 2u);
  const auto a = PrepareCell(study, study.cells[0]), b = PrepareCell(study, study.cells[1]);
  EXPECT_EQ(a->ranger_offset, 0.0);
  EXPECT_DOUBLE_EQ(b->ranger_offset, 0.5e-3);
  ASSERT_EQ(a->design.configs.size(), b->design.configs.size());
  for (int i = 0; i < a->design.configs.size(); ++i)
    for (int j = 0; j < 6; ++j) EXPECT_EQ(a->design.configs.q(i)[j], b->design.configs.q(i)[j]);
  for (int i = 0; i < a->validation.size(); ++i)
    EXPECT_EQ(a->validation.q(i)[0], b->validation.q(i)[0]);
  std::ofstream(dir + "/bad.yaml") << "name: s\nseed: 2\ntrials: 2\n"
                                      "truth: {ranger_scale_ppm: lots}\n";
  EXPECT_THROW(LoadStudy(dir + "/bad.yaml"), InputError);
}

}  // namespace
}  // namespace lrcal
