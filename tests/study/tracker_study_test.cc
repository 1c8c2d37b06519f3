// Studies with a sensor other than the ranger (sensor.kind scanner, point, pose, contact, socket):
// a cell recovers a truth it can see to within its noise, the covariance it predicts holds over
// its trials (Monte Carlo), the budget buys the configurations it says, sensors share their
// validation poses, the ranger's and the trackers' cells keep their names, and a cell refuses
// the ranger's settings and bad sensor settings at their line.
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
// A fan of 5 beams over ±10° on the tool; a ball 50 mm along the tool axis and three sockets
// within the paper's arm's reach, the first two 50 mm apart (a length reference).
constexpr const char* kScanner = "kind: scanner, beams: 5, fan_deg: 10";
constexpr const char* kSockets =
    "kind: socket, target: [0, 0, 0.05], sockets: [[1.0, 0.5, 0.3], [1.0, 0.55, 0.3], "
    "[0.8, -0.6, 0.4]], socket_distances: ['0,1=0.05']";

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
  const std::pair<const char*, std::string> kinds[] = {{"point", "kind: point"},
                                                       {"pose", "kind: pose"},
                                                       {"scanner", kScanner},
                                                       {"socket", kSockets}};
  for (const auto& [name, kind] : kinds) {
    SCOPED_TRACE(name);
    const Study study = LoadStudy(WriteTrackerStudy(
        std::string("truth_") + name, robot,
        "noise: {sigma_mm: 1e-9, repetitions: 1}\nselection: {count: 30}\nsensor: {" + kind +
            ", sigma_mrad: 1e-9, " + kTracker + "}\n"));
    const auto c = PrepareCell(study, study.cells.at(0));
    ASSERT_FALSE(c->rank_deficient) << c->rank_message;
    testing::ExpectTrialsRecoverTheTruth(*c, 1, kRecovered, kRecovered);
  }
}

TEST(TrackerStudy, ACellPreparedForItsTrialsAloneRunsTheSameTrials) {
  const std::string dir = testing::TempDir("tracker_robot_for_trials");
  const std::string robot = RobotSeenByATracker(dir);
  const Study study = LoadStudy(WriteTrackerStudy(
      "for_trials", robot,
      std::string("selection: {count: 30}\nsensor: {kind: pose, ") + kTracker + "}\n"));
  testing::ExpectForTrialsPreparesTheSameTrials(study, study.cells.at(0), 3);
}

TEST(TrackerStudy, ThePredictedCovarianceHoldsOverTheTrials) {
  // truth.scale 0: the true arm is the nominal one, so the terms held at nominal are true and the
  // estimate's error is the noise's alone: its Mahalanobis distance δᵀΣ⁻¹δ averages n over the
  // trials (χ²(n)), within 4 standard errors of that mean (√(2n/N)). For contacts the noise is
  // the play of each seating on the true arm (the configurations differ from the design's): a
  // check of the whole contact pipeline against its predicted covariance.
  constexpr int kTrials = 300;
  const std::pair<const char*, std::string> kinds[] = {
      {"point", "kind: point, target: [0, 0, 0.05]"},
      {"pose", "kind: pose, target: [0, 0, 0.05]"},
      {"contact", "kind: contact, target: [0, 0, 0.05]"},
      {"flush", "kind: contact, flush: true, target: [0, 0, 0.05]"},
      {"scanner", kScanner},
      {"socket", kSockets}};
  for (const auto& [name, kind] : kinds) {
    SCOPED_TRACE(name);
    const Study study = LoadStudy(WriteTrackerStudy(
        std::string("coverage_") + name, "paper",
        "truth: {scale: 0}\nnoise: {sigma_mm: 0.05, repetitions: 4}\nselection: {count: 30}\n"
        "sensor: {" +
            kind + ", sigma_mrad: 0.3, " + kTracker + "}\n",
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

TEST(TrackerStudy, AScannerTrialWhoseBeamsMissFitsTheConfigurationsItMeasured) {
  // True errors of 30 mrad and 10 mm turn some beams of a wide fan off their plane or out of
  // range on the true arm: those configurations are left out of the trial, which fits the others
  // (its own evaluator, not the design's) as Identify does on the same values.
  constexpr double kSameEstimate = 1e-8;
  const Study study = LoadStudy(
      WriteTrackerStudy("scanner_misses", "paper",
                        "truth: {mode: random, angle_sigma_mrad: 30, length_sigma_mm: 10}\n"
                        "noise: {sigma_mm: 0.05, repetitions: 4}\nselection: {count: 40}\n"
                        "sensor: {kind: scanner, beams: 9, fan_deg: 40}\n",
                        40));
  const auto c = PrepareCell(study, study.cells.at(0));
  ASSERT_FALSE(c->rank_deficient) << c->rank_message;
  TrialWorkspace ws;
  int with_misses = 0;
  for (int t = 0; t < 40; ++t) {
    const TrialRecord r = RunTrial(*c, t, &ws);
    if (r.missed_configurations == 0) continue;
    ++with_misses;
    EXPECT_EQ(ws.values.configs.size(), 40 - r.missed_configurations);
    if (r.status != TrialStatus::kOk) continue;
    const IdentificationSummary s =
        Identify(*c->kind, ws.values, study.cells[0].typed.identification);
    ASSERT_TRUE(s.IsSolutionUsable());
    for (Eigen::Index k = 0; k < s.delta.size(); ++k)
      EXPECT_NEAR(ws.e[k], s.delta[k], kSameEstimate)
          << c->parameter_names[static_cast<std::size_t>(k)] << ", trial " << t;
  }
  EXPECT_GT(with_misses, 0);
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

TEST(TrackerStudy, TheTrackersCellsKeepTheirNames) {
  // The scanner's and the sockets' keys came after tracker studies were run: at their defaults
  // they stay out of a tracker cell's resolved settings (and so of its name), which are what
  // they were; given, they are in.
  const Study point = LoadStudy(WriteTrackerStudy(
      "names_point", "paper", "sensor: {kind: point, " + std::string(kTracker) + "}\n"));
  const Json& sensor = point.cells.at(0).settings.at("sensor");
  for (const char* key : {"beams", "fan_deg", "sockets", "socket_distances"})
    EXPECT_FALSE(sensor.contains(key)) << key;
  EXPECT_EQ(sensor.size(), 7u) << sensor.dump();  // kind … budget, as tracker studies wrote it
  const Study scanner = LoadStudy(
      WriteTrackerStudy("names_scanner", "paper", "sensor: {" + std::string(kScanner) + "}\n"));
  EXPECT_EQ(scanner.cells.at(0).settings["sensor"]["beams"], 5);
}

TEST(TrackerStudy, ScannerAndSocketPoolsAreWhereTheyMeasure) {
  // A scanner's pool has every beam of its fan on its plane at the nominal arm; a socket cell's
  // has the nominal ball in its socket (to SeatToolPoint's 1e-12), the sockets in turn.
  const Study scanner = LoadStudy(
      WriteTrackerStudy("pool_scanner", "paper",
                        "selection: {count: 30}\nsensor: {" + std::string(kScanner) + "}\n"));
  const auto sc = PrepareCell(scanner, scanner.cells.at(0));
  ASSERT_EQ(sc->pool.size(), 60);
  const std::vector<double> zero(static_cast<std::size_t>(sc->sensor_kind->num_parameters()), 0.0);
  for (const std::string& reason : sc->sensor_kind->MissReasons(sc->pool, zero.data()))
    EXPECT_EQ(reason, "ok");
  const Study socket = LoadStudy(WriteTrackerStudy(
      "pool_socket", "paper", "selection: {count: 30}\nsensor: {" + std::string(kSockets) + "}\n"));
  const auto so = PrepareCell(socket, socket.cells.at(0));
  ASSERT_EQ(so->pool.size(), 60);
  const std::vector<double> none(static_cast<std::size_t>(so->sensor_kind->num_parameters()), 0.0);
  std::vector<double> y(static_cast<std::size_t>(3 * so->pool.size()));
  ASSERT_TRUE(so->sensor_kind->Bind(so->pool)->Predict(none.data(), y.data(), nullptr));
  for (int i = 0; i < so->pool.size(); ++i) {
    EXPECT_EQ(so->pool.target(i), i % 3);
    for (int r = 0; r < 3; ++r) EXPECT_NEAR(y[static_cast<std::size_t>(3 * i + r)], 0.0, 1e-12);
  }
}

TEST(TrackerStudy, BadSensorSettingsAreErrorsAtTheirLine) {
  EXPECT_THAT(TrackerStudyError("kind", "sensor: {kind: sonar}\n"),
              AllOf(HasSubstr("s.yaml:8 key 'sensor.kind'"),
                    HasSubstr("expected ranger, scanner, point, pose, socket or contact")));
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
            HasSubstr("sensor.kind point: it measures no plane")));
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
              AllOf(HasSubstr("key 'sensor.target'"), HasSubstr("seats a point")));
  EXPECT_THAT(TrackerStudyError("beams", "sensor: {kind: scanner, beams: 2.5}\n"),
              AllOf(HasSubstr("key 'sensor.beams'"), HasSubstr("a whole number of beams")));
  EXPECT_THAT(TrackerStudyError("many_beams", "sensor: {kind: scanner, beams: 300}\n"),
              AllOf(HasSubstr("key 'sensor.beams'"), HasSubstr("expected 1 to 256 beams")));
  EXPECT_THAT(TrackerStudyError("fan", "sensor: {kind: scanner, beams: 3, fan_deg: 90}\n"),
              AllOf(HasSubstr("key 'sensor.fan_deg'"), HasSubstr("below 90 deg")));
  EXPECT_THAT(TrackerStudyError("no_sockets", "sensor: {kind: socket}\n"),
              AllOf(HasSubstr("key 'sensor.sockets'"), HasSubstr("the sockets' positions")));
  EXPECT_THAT(TrackerStudyError("bad_socket", "sensor: {kind: socket, sockets: [[1, 2]]}\n"),
              AllOf(HasSubstr("key 'sensor.sockets'"), HasSubstr("socket 0: expected [x, y, z]")));
  EXPECT_THAT(TrackerStudyError("far_sockets",
                                "sensor: {kind: socket, sockets: [[1, 0, 0], [1, "
                                "0.1, 0]], socket_distances: ['0,1=0.05']}\n"),
              AllOf(HasSubstr("key 'sensor.socket_distances'"), HasSubstr("0.1 m apart")));
  EXPECT_THAT(TrackerStudyError("unknown_socket",
                                "sensor: {kind: socket, sockets: [[1, 0, 0]], "
                                "socket_distances: ['0,3=0.05']}\n"),
              HasSubstr("key 'sensor.socket_distances'"));
  EXPECT_THAT(
      TrackerStudyError("socket_plane",
                        "sensor: {" + std::string(kSockets) +
                            "}\nsweep:\n  axes:\n    - key: "
                            "identification.estimate_plane\n      values: [offset]\n"),
      AllOf(HasSubstr("key 'identification.estimate_plane'"), HasSubstr("it measures no plane")));
  EXPECT_EQ(TrackerStudyError("scanner_plane",
                              "sensor: {kind: scanner}\nsweep:\n  axes:\n    - key: "
                              "identification.estimate_plane\n      values: [offset]\n"),
            "no error");
  EXPECT_EQ(TrackerStudyError("contact_plane",
                              "sensor: {kind: contact}\nsweep:\n  axes:\n    - key: "
                              "identification.estimate_plane\n      values: [offset]\n"),
            "no error");  // a contact estimates its planes' terms as the ranger does
}

}  // namespace
}  // namespace lrcal
