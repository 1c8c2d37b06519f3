// Studies with a tracker (sensor.kind point or pose): a tracker cell recovers a truth it can see
// to within its noise, the covariance it predicts holds over its trials (Monte Carlo), the budget
// buys the configurations it says, sensors share their validation poses, the ranger's cells keep
// their names, and a tracker cell refuses the ranger's settings at their line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/study/study.h"
#include "study/trial_pipeline.h"
#include "test_util.h"
#include "trial_checks.h"

namespace lrcal {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

constexpr const char* kTracker = "instrument: [2.5, 0.3, 0.2, 0, 0, 3]";

// The paper's robot file with its true errors kept on links 2 to 5 only: every term a tracker
// cannot separate (d1 and θ1 against the tracker's frame, the last link's against the target)
// is then true at nominal, so a fit that holds them there can recover the truth exactly.
std::string RobotSeenByATracker(const std::string& dir) {
  std::ifstream in(testing::SourcePath("studies/robots/paper.yaml"));
  std::stringstream text;
  text << in.rdbuf();
  std::string robot = text.str();
  robot = std::regex_replace(robot, std::regex(R"(- \{theta: -7\.23[^}]*\})"),
                             "- {theta: 0, alpha: 0, a: 0, d: 0}");
  robot = std::regex_replace(robot, std::regex(R"(- \{theta: -0\.34[^}]*\})"),
                             "- {theta: 0, alpha: 0, a: 0, d: 0, beta: 0}");
  const std::string path = dir + "/robot.yaml";
  std::ofstream(path) << robot;
  return path;
}

std::string WriteTrackerStudy(const std::string& name, const std::string& robot,
                              const std::string& body, int trials = 3) {
  const std::string path = testing::TempDir("tracker_study_" + name) + "/s.yaml";
  std::ofstream(path) << "name: s\nseed: 5\ntrials: " << trials << "\nrobot: " << robot << "\n"
                      << "pool: {size: 60}\nvalidation: {size: 10}\n"
                      << "identification: {on_rank_deficient: fix}\n"
                      << body;
  return path;
}

std::string TrackerStudyError(const std::string& name, const std::string& body) {
  try {
    LoadStudy(WriteTrackerStudy(name, "paper", body));
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(TrackerStudy, ATrackerCellRecoversATruthItCanSeeToWithinItsNoise) {
  // Noise of 1e-9 mm and 1e-9 mrad: the estimate is the truth to 1e-9 of a term's size.
  constexpr double kRecovered = 1e-9;
  const std::string dir = testing::TempDir("tracker_study_truth");
  const std::string robot = RobotSeenByATracker(dir);
  for (const char* kind : {"point", "pose"}) {
    SCOPED_TRACE(kind);
    const Study study = LoadStudy(WriteTrackerStudy(
        std::string("truth_") + kind, robot,
        "noise: {sigma_mm: 1e-9, repetitions: 1}\nselection: {count: 30}\nsensor: {kind: " +
            std::string(kind) + ", sigma_mrad: 1e-9, " + kTracker + "}\n"));
    const auto c = PrepareCell(study, study.cells.at(0));
    ASSERT_FALSE(c->rank_deficient) << c->rank_message;
    testing::ExpectTrialsRecoverTheTruth(*c, 1, kRecovered, kRecovered);
  }
}

TEST(TrackerStudy, ThePredictedCovarianceHoldsOverTheTrials) {
  // truth.scale 0: the true arm is the nominal one, so the terms held at nominal are true and the
  // estimate's error is the noise's alone: its Mahalanobis distance δᵀΣ⁻¹δ averages n over the
  // trials (χ²(n)), within 4 standard errors of that mean (√(2n/N)). For contacts the noise is
  // the play of each seating on the true arm (the configurations differ from the design's): a
  // check of the whole contact pipeline against its predicted covariance.
  constexpr int kTrials = 300;
  const std::pair<const char*, const char*> kinds[] = {{"point", "point"},
                                                       {"pose", "pose"},
                                                       {"contact", "contact"},
                                                       {"flush", "contact, flush: true"}};
  for (const auto& [name, kind] : kinds) {
    SCOPED_TRACE(name);
    const Study study = LoadStudy(WriteTrackerStudy(
        std::string("coverage_") + name, "paper",
        "truth: {scale: 0}\nnoise: {sigma_mm: 0.05, repetitions: 4}\nselection: {count: 30}\n"
        "sensor: {kind: " +
            std::string(kind) + ", sigma_mrad: 0.3, target: [0, 0, 0.05], " + kTracker + "}\n",
        kTrials));
    const auto c = PrepareCell(study, study.cells.at(0));
    ASSERT_FALSE(c->rank_deficient) << c->rank_message;
    const auto n = static_cast<double>(c->parameter_names.size());
    EXPECT_NEAR(testing::MeanMahalanobis(*c, kTrials), n, 4 * std::sqrt(2 * n / kTrials))
        << "n = " << n;
  }
}

TEST(TrackerStudy, TheTrialsLeanFitIsIdentifysFit) {
  // A trial fits with lrcal's LM on the cell's evaluator from the cell's nominal linearisation,
  // without Identify()'s per-fit rank analysis and statistics: the same estimate as Identify on
  // the same values, to the solvers' stopping tolerance (1e-9 of a term's σ is far below it).
  constexpr double kSameEstimate = 1e-10;
  for (const char* kind : {"point", "pose"}) {
    SCOPED_TRACE(kind);
    const Study study = LoadStudy(WriteTrackerStudy(
        std::string("lean_") + kind, "paper",
        "noise: {sigma_mm: 0.05, repetitions: 4}\nselection: {count: 30}\nsensor: {kind: " +
            std::string(kind) + ", sigma_mrad: 0.3, " + kTracker + "}\n"));
    const auto c = PrepareCell(study, study.cells.at(0));
    TrialWorkspace ws;
    for (int t = 0; t < 3; ++t) {
      const TrialRecord r = RunTrial(*c, t, &ws);
      ASSERT_EQ(r.status, TrialStatus::kOk);
      const IdentificationSummary s =
          Identify(*c->kind, ws.values, study.cells[0].typed.identification);
      ASSERT_TRUE(s.IsSolutionUsable());
      for (Eigen::Index k = 0; k < s.delta.size(); ++k)
        EXPECT_NEAR(ws.e[k], s.delta[k], kSameEstimate)
            << c->parameter_names[static_cast<std::size_t>(k)];
      EXPECT_NEAR(r.residual_rms, s.residual_rms, 1e-12);
    }
  }
}

TEST(TrackerStudy, TheBudgetBuysTheCountAndSensorsShareTheirValidationPoses) {
  const Study study = LoadStudy(
      WriteTrackerStudy("budget", "paper",
                        "noise: {repetitions: 5}\nsensor: {budget: 200, " + std::string(kTracker) +
                            "}\nsweep:\n  axes:\n    - key: .\n      values:\n"
                            "        - {sensor: {kind: ranger}}\n"
                            "        - {sensor: {kind: point, cost_per_reading: 2}}\n"
                            "        - {sensor: {kind: pose, cost_per_reading: 4}}\n"));
  ASSERT_EQ(study.cells.size(), 3u);
  const int expected[] = {40, 20, 10};  // ⌊200 / (cost × 5)⌋
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(study.cells[i].typed.select_count, expected[i]);
    EXPECT_EQ(study.cells[i].settings["selection"]["count"], expected[i]);
  }
  const auto ranger = PrepareCell(study, study.cells[0]);
  const auto point = PrepareCell(study, study.cells[1]);
  ASSERT_EQ(ranger->validation.size(), point->validation.size());
  for (int j = 0; j < ranger->validation.size(); ++j)
    for (int q = 0; q < 6; ++q) EXPECT_EQ(ranger->validation.q(j)[q], point->validation.q(j)[q]);
  EXPECT_EQ(point->design.configs.size(), 20);
}

TEST(TrackerStudy, TheRangersCellsKeepTheirNames) {
  // A study without a sensor section and the same study with the ranger's defaults spelled out
  // have the same cell: the section is left out of the identity at its defaults.
  const Study plain = LoadStudy(WriteTrackerStudy("plain", "paper", ""));
  const Study spelled = LoadStudy(WriteTrackerStudy(
      "spelled", "paper", "sensor: {kind: ranger, cost_per_reading: 1, sigma_mrad: 0.2}\n"));
  EXPECT_EQ(plain.cells.at(0).id, spelled.cells.at(0).id);
  EXPECT_FALSE(CellIdentity(plain.cells.at(0).settings).contains("sensor"));
}

TEST(TrackerStudy, BadSensorSettingsAreErrorsAtTheirLine) {
  EXPECT_THAT(TrackerStudyError("kind", "sensor: {kind: sonar}\n"),
              AllOf(HasSubstr("s.yaml:8 key 'sensor.kind'"),
                    HasSubstr("expected ranger, point, pose or contact")));
  EXPECT_THAT(
      TrackerStudyError("no_instrument", "sensor: {kind: point}\n"),
      AllOf(HasSubstr("key 'sensor.instrument'"), HasSubstr("[x, y, z, roll, pitch, yaw]")));
  EXPECT_THAT(
      TrackerStudyError("short_instrument", "sensor: {kind: pose, instrument: [1, 2, 3]}\n"),
      AllOf(HasSubstr("key 'sensor.instrument'"), HasSubstr("got [1,2,3]")));
  EXPECT_THAT(
      TrackerStudyError("point_orientation", "sensor: {kind: point, " + std::string(kTracker) +
                                                 ", target: [0, 0, 0, 0.1, 0, 0]}\n"),
      AllOf(HasSubstr("key 'sensor.target'"), HasSubstr("positions only")));
  EXPECT_THAT(TrackerStudyError("cost", "sensor: {cost_per_reading: 0}\n"),
              AllOf(HasSubstr("key 'sensor.cost_per_reading'"), HasSubstr("expected a cost > 0")));
  EXPECT_THAT(TrackerStudyError("small_budget", "noise: {repetitions: 10}\nsensor: {budget: 5}\n"),
              AllOf(HasSubstr("key 'sensor.budget'"), HasSubstr("at least one configuration")));
  EXPECT_THAT(TrackerStudyError("large_budget", "sensor: {budget: 1e6}\n"),
              AllOf(HasSubstr("key 'sensor.budget'"), HasSubstr("more than pool.size = 60")));
  const std::string tracker = "sensor: {kind: point, " + std::string(kTracker) + "}\n";
  const auto swept = [](const std::string& key, const std::string& value) {
    return "sweep:\n  axes:\n    - key: " + key + "\n      values: [" + value + "]\n";
  };
  EXPECT_THAT(
      TrackerStudyError("plane", tracker + swept("identification.estimate_plane", "offset")),
      AllOf(HasSubstr("key 'identification.estimate_plane'"),
            HasSubstr("sensor.kind point: a tracker reads no plane")));
  EXPECT_THAT(TrackerStudyError("coverage", tracker + swept("validation.coverage", "true")),
              AllOf(HasSubstr("s.yaml:12"), HasSubstr("key 'validation.coverage'"),
                    HasSubstr("sensor.kind point")));
  EXPECT_THAT(TrackerStudyError("encoder", tracker + "noise: {encoder_sigma_mrad: 0.1}\n"),
              AllOf(HasSubstr("key 'noise.encoder_sigma_mrad'"), HasSubstr("ranger only")));
  EXPECT_THAT(TrackerStudyError("task", tracker + "selection: {criterion: I}\n"),
              HasSubstr("key 'selection.criterion'"));
  EXPECT_THAT(TrackerStudyError(
                  "flush", "sensor: {kind: point, flush: true, " + std::string(kTracker) + "}\n"),
              AllOf(HasSubstr("key 'sensor.flush'"), HasSubstr("is the contact sensor's")));
  EXPECT_THAT(TrackerStudyError("contact_orientation",
                                "sensor: {kind: contact, target: [0, 0, 0.05, 0.1, 0, 0]}\n"),
              AllOf(HasSubstr("key 'sensor.target'"), HasSubstr("touches with a point")));
  EXPECT_EQ(TrackerStudyError("contact_plane",
                              "sensor: {kind: contact}\nsweep:\n  axes:\n    - key: "
                              "identification.estimate_plane\n      values: [offset]\n"),
            "no error");  // a contact estimates its planes' terms as the ranger does
}

}  // namespace
}  // namespace lrcal
