// Studies of trees (tool_link with several links, base_link): a tree cell recovers every chain's
// truth when its noise vanishes (a coupled chain's gain too, and a chain up a leg from a sole),
// its predicted covariance holds over its trials (Monte Carlo), its validation's first-order
// prediction matches the trials, sharing the torso with the other arm improves the judged arm,
// the budget pays for every chain's reading, the tables do not depend on the threads, and bad
// tree settings are errors at their line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>

#include "lrcal/core/error.h"
#include "lrcal/study/study.h"
#include "study/trial_pipeline.h"
#include "test_util.h"
#include "trial_checks.h"

namespace lrcal {
namespace {

using ::testing::AllOf;
using ::testing::Contains;
using ::testing::HasSubstr;
using ::testing::Not;

// The tracker registered to the robot's base and the probes on the flanges known (held): the
// chains' every link term is then identifiable, and nothing the truth perturbs is held.
constexpr const char* kKnownTracker =
    "{kind: pose, instrument: [2.0, 0.0, 0.5, 0, 0, 3.1416], sigma_mrad: 0.2}";
const char* const kHeldFrames[] = {"instrument_x",    "instrument_y",     "instrument_z",
                                   "instrument_roll", "instrument_pitch", "instrument_yaw"};
const char* const kProbeAxes[] = {"x", "y", "z", "roll", "pitch", "yaw"};

// identification.fix holding the instrument and each listed tool's probe ("" : the one chain's,
// unlabelled).
std::string HeldFrames(const std::vector<std::string>& tools) {
  std::string fix = "[";
  for (const char* name : kHeldFrames) fix += std::string(name) + ", ";
  for (const std::string& tool : tools)
    for (const char* axis : kProbeAxes)
      fix += (tool.empty() ? "" : tool + ".") + "target_" + axis + ", ";
  fix.resize(fix.size() - 2);
  return fix + "]";
}

// A tree study's sections, each replaceable.
struct TreeSections {
  std::string robot = "examples/urdf/dual_arm_torso.urdf";
  std::string base_link;  ///< empty: none given (the root)
  std::string tool_link = "left_tool,right_tool";
  std::string truth = "{mode: random, angle_sigma_mrad: 1, length_sigma_mm: 1}";
  std::string noise = "{sigma_mm: 0.05}";
  std::string pool = "{size: 80}";
  std::string selection = "{count: 20}";
  std::string validation = "{size: 20}";
  std::string identification =
      "{on_rank_deficient: fix, fix: " + HeldFrames({"left_tool", "right_tool"}) + "}";
  std::string sensor = kKnownTracker;
  std::string rest;  ///< a sweep
};

std::string WriteTreeStudy(const std::string& name, const TreeSections& t, int trials = 3) {
  const std::string path = testing::TempDir("tree_study_" + name) + "/s.yaml";
  std::ofstream(path) << "name: s\nseed: 5\ntrials: " << trials
                      << "\nrobot: " << testing::SourcePath(t.robot) << "\n"
                      << (t.base_link.empty() ? "" : "base_link: " + t.base_link + "\n")
                      << (t.tool_link.empty() ? "" : "tool_link: " + t.tool_link + "\n")
                      << "truth: " << t.truth << "\nnoise: " << t.noise << "\npool: " << t.pool
                      << "\nselection: " << t.selection << "\nvalidation: " << t.validation
                      << "\nidentification: " << t.identification << "\nsensor: " << t.sensor
                      << "\n"
                      << t.rest;
  return path;
}

std::string TreeStudyError(const std::string& name, const TreeSections& t) {
  try {
    const Study study = LoadStudy(WriteTreeStudy(name, t));
    PrepareCell(study, study.cells.at(0));
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(TreeStudy, ACellPreparedForItsTrialsAloneRunsTheSameTrials) {
  const Study study = LoadStudy(WriteTreeStudy("for_trials", TreeSections{}));
  testing::ExpectForTrialsPreparesTheSameTrials(study, study.cells.at(0), 2);
}

TEST(TreeStudy, ANoiseFreeTreeCellRecoversEveryChainsTruth) {
  // Noise of 1e-9 mm and 1e-9 mrad: the estimate is the truth to 1e-9 of a term's size, the
  // shared torso's terms and each arm's own alike, and so is the judged arm's pose.
  constexpr double kRecovered = 1e-9;
  TreeSections t;
  t.noise = "{sigma_mm: 1e-9, repetitions: 1}";
  t.sensor = "{kind: pose, instrument: [2.0, 0.0, 0.5, 0, 0, 3.1416], sigma_mrad: 1e-9}";
  const Study study = LoadStudy(WriteTreeStudy("truth", t));
  const auto c = PrepareCell(study, study.cells.at(0));
  ASSERT_FALSE(c->rank_deficient) << c->rank_message;
  EXPECT_TRUE(c->fixed_for_rank.empty());
  // The torso's links once, unlabelled; each arm's own links with its tool link.
  EXPECT_THAT(c->parameter_names, Contains("theta2"));
  EXPECT_THAT(c->parameter_names, Contains("left_tool.theta9"));
  EXPECT_THAT(c->parameter_names, Contains("right_tool.theta9"));
  EXPECT_THAT(c->parameter_names, Not(Contains("left_tool.theta2")));
  testing::ExpectTrialsRecoverTheTruth(*c, 2, kRecovered, kRecovered);
}

TEST(TreeStudy, ACoupledChainsGainIsFittedWithItsProbesOrientations) {
  // The head (its tilt mimics the last torso joint) with the left arm, a 6-D probe on each, noise
  // of 1e-9: every trial converges and the coupling's gain (true at nominal) and every other
  // term come back to 1e-9. The fit moves the tilt with the gain while the probe's orientations
  // stay in their nominal charts.
  constexpr double kRecovered = 1e-9;
  TreeSections t;
  t.tool_link = "left_tool,head";
  t.noise = "{sigma_mm: 1e-9, repetitions: 1}";
  t.sensor = "{kind: pose, instrument: [2.0, 0.0, 0.5, 0, 0, 3.1416], sigma_mrad: 1e-9}";
  t.identification = "{on_rank_deficient: fix, fix: " + HeldFrames({"left_tool", "head"}) + "}";
  const Study study = LoadStudy(WriteTreeStudy("coupled", t));
  const auto c = PrepareCell(study, study.cells.at(0));
  ASSERT_FALSE(c->rank_deficient) << c->rank_message;
  ASSERT_THAT(c->parameter_names, Contains("head.coupling4_gain"));
  testing::ExpectTrialsRecoverTheTruth(*c, 3, kRecovered, kRecovered);
}

TEST(TreeStudy, AChainFromASoleUpTheLegIsStudiedAsAnyArm) {
  // base_link in a study: the humanoid-like robot from its left sole up the leg, the torso and
  // the left arm to the gripper (14 joints, 6 of them passed child to parent), one tracker cell;
  // noise-free, every term and the gripper's validation poses come back to 1e-9.
  constexpr double kRecovered = 1e-9;
  TreeSections t;
  t.robot = "examples/urdf/humanoid_like.urdf";
  t.base_link = "left_sole";
  t.tool_link = "left_gripper";
  t.pool = "{size: 120}";
  t.selection = "{count: 30}";
  t.noise = "{sigma_mm: 1e-9, repetitions: 1}";
  t.sensor = "{kind: pose, instrument: [2.0, 0.0, 0.5, 0, 0, 3.1416], sigma_mrad: 1e-9}";
  t.identification = "{on_rank_deficient: fix, fix: " + HeldFrames({""}) + "}";
  const Study study = LoadStudy(WriteTreeStudy("leg", t));
  const auto c = PrepareCell(study, study.cells.at(0));
  ASSERT_FALSE(c->rank_deficient) << c->rank_message;
  EXPECT_EQ(c->robot->num_links(), 14);
  EXPECT_EQ(c->tree, nullptr);  // one chain: a tracker cell
  testing::ExpectTrialsRecoverTheTruth(*c, 1, kRecovered, kRecovered);
}

TEST(TreeStudy, ARobotFilesCoupledArmIsStudiedAsATreeOfOneChain) {
  // examples/robots/parallelogram_arm.yaml (q3 = -q2 by couple:): a tree cell of its one chain,
  // labelled "tool", the linkage's gain estimated. With noise of 1e-12 mm and mrad, every trial's
  // validation poses come back to 1e-7: the terms held for rank (d1 with a3, d4 with a1 when
  // q3 = -q2) carry their true errors of 1 mm, which the others take up exactly to first order
  // only (what is left, second order, measured 5e-9). The ranger is refused by name.
  constexpr double kTakenUp = 1e-7;
  TreeSections t;
  t.robot = "examples/robots/parallelogram_arm.yaml";
  t.tool_link = "";
  t.noise = "{sigma_mm: 1e-12, repetitions: 1}";
  t.selection = "{count: 30}";
  t.sensor = "{kind: pose, instrument: [2.0, 0.0, 0.5, 0, 0, 3.1416], sigma_mrad: 1e-12}";
  t.identification = "{on_rank_deficient: fix, fix: " + HeldFrames({"tool"}) + "}";
  const Study study = LoadStudy(WriteTreeStudy("yaml_coupled", t));
  const auto c = PrepareCell(study, study.cells.at(0));
  ASSERT_NE(c->tree, nullptr);
  ASSERT_FALSE(c->rank_deficient) << c->rank_message;
  EXPECT_THAT(c->parameter_names, Contains("coupling3_gain"));
  testing::ExpectTrialsRecoverTheTruth(*c, 2, -1, kTakenUp);
  TreeSections ranger = t;
  ranger.sensor = "{kind: ranger}";
  ranger.identification = "{on_rank_deficient: fix}";
  EXPECT_THAT(TreeStudyError("yaml_ranger", ranger),
              AllOf(HasSubstr("sensor.kind"), HasSubstr("studied with a tracker")));
}

TEST(TreeStudy, ThePredictedCovarianceAndValidationHoldOverTheTrials) {
  // A truth of 0.01 mrad and 0.01 mm: the model at the truth is the nominal one to first order,
  // so the estimate's error is the noise's alone and its Mahalanobis distance δᵀΣ⁻¹δ averages n
  // (χ²(n)), within 4 standard errors of that mean (√(2n/N)); the judged arm's mean validation
  // RMS position error is the first-order prediction's within 10 %.
  constexpr int kTrials = 300;
  constexpr double kPredictionTolerance = 0.10;
  TreeSections t;
  t.truth = "{mode: random, angle_sigma_mrad: 0.01, length_sigma_mm: 0.01}";
  t.noise = "{sigma_mm: 0.05, repetitions: 4}";
  const Study study = LoadStudy(WriteTreeStudy("coverage", t, kTrials));
  const auto c = PrepareCell(study, study.cells.at(0));
  ASSERT_FALSE(c->rank_deficient) << c->rank_message;
  const auto n = static_cast<double>(c->parameter_names.size());
  EXPECT_NEAR(testing::MeanMahalanobis(*c, kTrials), n, 4 * std::sqrt(2 * n / kTrials))
      << "n = " << n;
  double rms_position = 0;
  TrialWorkspace ws;
  for (int trial = 0; trial < kTrials; ++trial)
    rms_position += RunTrial(*c, trial, &ws).validation[0];
  EXPECT_NEAR(rms_position / kTrials / c->predicted_validation[0], 1.0, kPredictionTolerance);
}

TEST(TreeStudy, SharingTheTorsoImprovesTheJudgedArm) {
  // The left arm calibrated alone from 15 configurations, then with the right arm's readings at
  // the same 15 (the torso's terms shared): its mean validation RMS position error over 100
  // trials falls by more than 7 % (it falls by 10 to 20 % from this pool of 80 candidates, by a
  // third from a pool of 200; each mean's standard error is about 2.5 %). The right arm judged
  // instead is the right chain's, from the same calibration.
  constexpr int kTrials = 100;
  constexpr double kAtMost = 0.93;
  const std::string both = HeldFrames({"left_tool", "right_tool"});
  TreeSections t;
  t.tool_link = "left_tool";
  t.selection = "{count: 15}";
  t.identification = "{on_rank_deficient: fix, fix: " + HeldFrames({""}) + "}";
  t.rest =
      "sweep:\n  axes:\n    - key: .\n      values:\n        - {tool_link: left_tool}\n"
      "        - {tool_link: 'left_tool,right_tool', identification: {fix: " +
      both +
      "}}\n        - {tool_link: 'left_tool,right_tool', validation: {tool_link: right_tool}, "
      "identification: {fix: " +
      both + "}}\n";
  const Study study = LoadStudy(WriteTreeStudy("sharing", t, kTrials));
  ASSERT_EQ(study.cells.size(), 3u);
  std::vector<std::unique_ptr<CellContext>> cells;
  double mean[2] = {0, 0};
  for (int cell = 0; cell < 2; ++cell) {
    cells.push_back(PrepareCell(study, study.cells[static_cast<std::size_t>(cell)]));
    TrialWorkspace ws;
    for (int trial = 0; trial < kTrials; ++trial) {
      const TrialRecord r = RunTrial(*cells.back(), trial, &ws);
      ASSERT_EQ(r.status, TrialStatus::kOk);
      mean[cell] += r.validation[0] / kTrials;
    }
  }
  EXPECT_LT(mean[1], kAtMost * mean[0])
      << "alone " << mean[0] << " m, with the right arm " << mean[1];
  const CellContext& left = *cells[1];
  const auto right = PrepareCell(study, study.cells[2]);
  EXPECT_EQ(left.tree->judged, 0);
  EXPECT_EQ(right->tree->judged, 1);
  EXPECT_EQ(right->robot->name(), right->tree->tree.chains[1].robot.name());
  EXPECT_EQ(right->parameter_names, left.parameter_names);  // one calibration, two judgements
}

TEST(TreeStudy, TheBudgetPaysForEveryChainsReading) {
  // A configuration reads both tools: ⌊budget / (cost × repetitions × 2)⌋ configurations.
  TreeSections t;
  t.noise = "{repetitions: 5}";
  t.sensor = "{kind: pose, instrument: [2.0, 0.0, 0.5, 0, 0, 3.1416], budget: 200}";
  const Study study = LoadStudy(WriteTreeStudy("budget", t));
  EXPECT_EQ(study.cells.at(0).typed.select_count, 20);
}

TEST(TreeStudy, TablesDoNotDependOnTheThreads) {
  TreeSections t;
  t.selection = "{count: 12}";
  const std::string path = WriteTreeStudy("threads", t, 6);
  const std::string dir = std::filesystem::path(path).parent_path().string();
  testing::RunStudyFile(path, dir + "/t1", 1);
  testing::RunStudyFile(path, dir + "/t2", 2);
  for (const char* table : {"summary.json", "validation.csv", "parameters.csv"})
    EXPECT_EQ(testing::ReadFile(dir + "/t1/tables/" + table),
              testing::ReadFile(dir + "/t2/tables/" + table))
        << table;
  EXPECT_THAT(testing::ReadFile(dir + "/t1/tables/parameters.csv"), HasSubstr("right_tool.theta9"));
}

TEST(TreeStudy, BadTreeSettingsAreErrorsAtTheirLine) {
  TreeSections ranger;
  ranger.sensor = "{kind: ranger}";
  EXPECT_THAT(TreeStudyError("ranger", ranger),
              AllOf(HasSubstr("key 'sensor.kind'"), HasSubstr("expected point or pose")));
  TreeSections fixed_truth;
  fixed_truth.truth = "{mode: robot_file}";
  EXPECT_THAT(TreeStudyError("truth", fixed_truth),
              AllOf(HasSubstr("s.yaml:6 key 'truth.mode'"), HasSubstr("expected random")));
  TreeSections twice;
  twice.tool_link = "left_tool,left_tool";
  EXPECT_THAT(TreeStudyError("twice", twice), AllOf(HasSubstr("s.yaml:5 key 'tool_link'"),
                                                    HasSubstr("'left_tool' is given twice")));
  TreeSections empty;
  empty.tool_link = "left_tool,,right_tool";
  EXPECT_THAT(TreeStudyError("empty", empty),
              AllOf(HasSubstr("key 'tool_link'"), HasSubstr("an empty link name")));
  TreeSections judged;
  judged.validation = "{size: 20, tool_link: head}";
  EXPECT_THAT(TreeStudyError("judged", judged),
              AllOf(HasSubstr("s.yaml:10 key 'validation.tool_link'"),
                    HasSubstr("'head' is not one of tool_link")));
  TreeSections unknown_term;
  unknown_term.identification = "{fix: [target_x]}";
  EXPECT_THAT(TreeStudyError("fix", unknown_term),
              AllOf(HasSubstr("identification.fix"),
                    HasSubstr("'target_x' is not a term of the tree's chains")));
  TreeSections nowhere;
  nowhere.tool_link = "left_tool,nowhere";
  EXPECT_THAT(TreeStudyError("link", nowhere), HasSubstr("nowhere"));
  TreeSections singular;  // no arm's Jacobian has a singular value of 10
  singular.pool = "{size: 80, min_singular_value: 10}";
  EXPECT_THAT(TreeStudyError("singular", singular),
              AllOf(HasSubstr("pool.size"), HasSubstr("only 0 of 1600 whole-robot draws have "
                                                      "every chain's Jacobian")));
}

}  // namespace
}  // namespace lrcal
