// Robot files: the paper's file, and bad files named by file, line and key.
#include "lrcal/io/robot_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "lrcal/core/error.h"
#include "test_util.h"

namespace lrcal {
namespace {

TEST(RobotFile, PaperFileHasTheTwentyFiveNamedParameters) {
  const RobotFile& rig = testing::PaperRig();
  const RobotModel& robot = rig.robot;
  std::vector<std::string> names;
  for (int k : robot.parameter_indices()) names.push_back(robot.ValueName(k));
  const std::vector<std::string> expected = {
      "theta1", "alpha1", "a1",     "d1",     "theta2", "alpha2", "a2",   "beta2",  "theta3",
      "alpha3", "a3",     "d3",     "theta4", "alpha4", "a4",     "d4",   "theta5", "alpha5",
      "a5",     "d5",     "theta6", "alpha6", "a6",     "d6",     "beta6"};
  EXPECT_EQ(names, expected);
  // Errors in SI: theta1 -7.23 mrad, a2 1.94 mm, beta6 -3.36 mrad.
  EXPECT_DOUBLE_EQ(rig.truth.link_errors[robot.FindValue("theta1")], -7.23e-3);
  EXPECT_DOUBLE_EQ(rig.truth.link_errors[robot.FindValue("a2")], 1.94e-3);
  EXPECT_DOUBLE_EQ(rig.truth.link_errors[robot.FindValue("beta6")], -3.36e-3);
  ASSERT_TRUE(rig.planes.has_value());
  EXPECT_NEAR((*rig.planes)[0].normal.norm(), 1.0, 1e-15);
  EXPECT_NEAR((*rig.planes)[0].offset, -0.69 / std::sqrt(1 + 4.6 * 4.6), 1e-15);
}

TEST(RobotFile, BadFilesNameFileLineAndKey) {
  std::string dir = testing::TempDir("robot_bad");
  auto write = [&](const std::string& text) {
    std::string path = dir + "/r.yaml";
    std::ofstream(path) << text;
    return path;
  };
  auto message = [&](const std::string& text) {
    try {
      LoadRobotFile(write(text));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(message("links:\n  - {theta: 0, alpha: 0, a: x, d: 0, parameters: [theta]}\n"),
              ::testing::HasSubstr("r.yaml:2 key 'links[0].a'"));
  EXPECT_THAT(message("links:\n  - {theta: 0, alpha: 0, a: 0, d: 0, parameters: [gamma]}\n"),
              ::testing::HasSubstr("unknown parameter 'gamma'"));
  EXPECT_THAT(message("linkz: []\n"), ::testing::HasSubstr("unknown key"));
  EXPECT_THAT(message("links:\n  - {theta: 0, alpha: 0, a: 0, d: 0, parameters: [theta]}\n"
                      "true_errors:\n  links:\n    - {d: 1}\n"),
              ::testing::HasSubstr("not a parameter"));
  EXPECT_THAT(message("links:\n  - {theta: 0, alpha: 0, a: 0, d: 0, parameters: [theta]}\n"
                      "plane: {normal: [0, 0, 0], offset: 1}\n"),
              ::testing::HasSubstr("zero"));
}

// Issue 31: a calibrated file's covariance and σ are checked, not trusted: a negative variance
// would give better-looking accuracy, an asymmetric matrix a meaningless one.
TEST(RobotFile, ACalibrationRecordsCovarianceMustBeOne) {
  const std::string dir = testing::TempDir("robot_covariance");
  const auto load = [&](const std::string& sigma, const std::string& covariance) {
    const std::string path = dir + "/cal.yaml";
    std::ofstream(path) << "links:\n  - {theta: 0, alpha: 0, a: 0.5, d: 0, parameters: [theta, "
                           "a]}\ncalibration:\n  sigma: "
                        << sigma << "\n  parameters: [theta1, a1]\n  estimate: [0, 0.5]\n"
                        << "  covariance: " << covariance << "\n";
    try {
      LoadRobotFile(path);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(load("2e-4", "[[4e-8, 1e-9], [1e-9, 9e-8]]"), "accepted");
  EXPECT_EQ(load("0", "null"), "accepted");
  EXPECT_THAT(load("2e-4", "[[-4e-8, 0], [0, 9e-8]]"),
              ::testing::AllOf(::testing::HasSubstr("cal.yaml:7 key 'calibration.covariance'"),
                               ::testing::HasSubstr("row 0 has a negative variance")));
  EXPECT_THAT(load("2e-4", "[[4e-8, 1e-9], [0, 9e-8]]"),
              ::testing::HasSubstr("is not symmetric: entries (1, 0) and (0, 1) differ"));
  EXPECT_THAT(load("2e-4", "[[1e-8, 2e-8], [2e-8, 1e-8]]"),
              ::testing::HasSubstr("has a negative eigenvalue"));
  EXPECT_THAT(load("-2e-4", "null"),
              ::testing::AllOf(::testing::HasSubstr("key 'calibration.sigma'"),
                               ::testing::HasSubstr(">= 0 (m), got -0.0002")));
}

// The terms a calibration held at nominal (total_accuracy.h): checked like the covariance, each
// error naming the file, line and key.
TEST(RobotFile, ACalibrationRecordsHeldTermsAreChecked) {
  const std::string dir = testing::TempDir("robot_held");
  const auto load = [&](const std::string& held) {
    const std::string path = dir + "/cal.yaml";
    std::ofstream(path) << "links:\n  - {theta: 0, alpha: 0, a: 0.5, d: 0, parameters: [theta, "
                           "a, d]}\ncalibration:\n  sigma: 2e-4\n  sigma_source: \"given\"\n"
                           "  parameters: [theta1, a1]\n  estimate: [0, 0.5]\n"
                           "  covariance: [[4e-8, 0], [0, 9e-8]]\n"
                        << held;
    try {
      const RobotFile file = LoadRobotFile(path);
      return "accepted " + std::to_string(file.calibration->held.size()) + " " +
             std::to_string(file.calibration->estimate_shift.rows()) + "x" +
             std::to_string(file.calibration->estimate_shift.cols());
    } catch (const InputError& e) {
      return std::string(e.what());
    }
  };
  const std::string good =
      "  held: [d1, ranger_offset]\n  held_sigma: [1e-3, 5e-4]\n  held_defaulted: [d1]\n"
      "  estimate_shift:\n    - [0, 0]\n    - [1, -1]\n";
  EXPECT_EQ(load(good), "accepted 2 2x2");
  EXPECT_EQ(load(""), "accepted 0 0x0");
  EXPECT_THAT(
      load("  held: [d1]\n  held_sigma: [0]\n  estimate_shift: [[0], [1]]\n"),
      ::testing::AllOf(::testing::HasSubstr("cal.yaml:10 key 'calibration.held_sigma'"),
                       ::testing::HasSubstr("entry 1 (d1): expected a standard deviation > 0")));
  EXPECT_THAT(load("  held: [d1]\n  held_sigma: [1e-3, 1e-3]\n  estimate_shift: [[0], [1]]\n"),
              ::testing::HasSubstr("expected one prior standard deviation (SI) per name"));
  EXPECT_THAT(load("  held: [d1]\n  held_sigma: [1e-3]\n  estimate_shift: [[0], [1, 2]]\n"),
              ::testing::AllOf(::testing::HasSubstr("key 'calibration.estimate_shift[1]'"),
                               ::testing::HasSubstr("expected 1 numbers")));
  EXPECT_THAT(load("  held: [d1]\n  held_sigma: [1e-3]\n"),
              ::testing::HasSubstr("expected 2 rows (one per parameter) of 1 numbers"));
  EXPECT_THAT(load("  held: [d1]\n  held_sigma: [1e-3]\n  held_defaulted: [a1]\n"
                   "  estimate_shift: [[0], [1]]\n"),
              ::testing::HasSubstr("'a1' is not in calibration.held"));
  EXPECT_THAT(load("  held_sigma: [1e-3]\n"),
              ::testing::HasSubstr("given without calibration.held"));
}

}  // namespace
}  // namespace lrcal

namespace lrcal {
namespace {

// tolerances: the priors `identify --prior` uses, by class for every link and by name per link,
// plane and ranger term, in the file's units; errors named by file, line and key.
TEST(RobotFile, TolerancesAreThePriorsByClassAndByName) {
  const std::string dir = testing::TempDir("robot_tolerances");
  const std::string two_links =
      "links:\n  - {theta: 0, alpha: 0, a: 0.5, d: 0, parameters: [theta, a]}\n"
      "  - {theta: 0, alpha: 0, a: 0.4, d: 0, parameters: [theta, a, d]}\n"
      "planes:\n  - {normal: [0, 0, 1], offset: 0.3}\n  - {normal: [1, 0, 0], offset: 0.9}\n";
  const auto load = [&](const std::string& tolerances) {
    const std::string path = dir + "/r.yaml";
    std::ofstream(path) << two_links << tolerances;
    return LoadRobotFile(path);
  };
  const RobotFile rig = load(
      "tolerances:\n  angle_unit: mrad\n  length_unit: mm\n"
      "  every_link: {theta: 1, a: 0.5}\n  links:\n    - {}\n    - {d: 0.2}\n"
      "  planes:\n    - {u: 2, f: 1}\n    - {f: 3}\n"
      "  ranger_offset_mm: 0.5\n  ranger_scale_ppm: 200\n");
  const PriorSigmas& p = rig.tolerances;
  EXPECT_DOUBLE_EQ(p.SigmaOf("theta2"), 1e-3);
  EXPECT_DOUBLE_EQ(p.SigmaOf("a1"), 0.5e-3);
  EXPECT_DOUBLE_EQ(p.SigmaOf("d2"), 0.2e-3);
  EXPECT_EQ(p.SigmaOf("d1"), 0.0);
  EXPECT_DOUBLE_EQ(p.SigmaOf("plane1_u2"), 2e-3);
  EXPECT_DOUBLE_EQ(p.SigmaOf("plane1_f"), 1e-3);
  EXPECT_EQ(p.SigmaOf("plane2_u1"), 0.0);
  EXPECT_DOUBLE_EQ(p.SigmaOf("plane2_f"), 3e-3);
  EXPECT_DOUBLE_EQ(p.SigmaOf("ranger_offset"), 0.5e-3);
  EXPECT_DOUBLE_EQ(p.SigmaOf("ranger_scale"), 200e-6);
  // The command line's entries replace the file's of the same key; a name still beats a class.
  const PriorSigmas over = p.OverriddenBy(PriorSigmas::Parse("a=2mm,d2=1mm"));
  EXPECT_DOUBLE_EQ(over.SigmaOf("a1"), 2e-3);
  EXPECT_DOUBLE_EQ(over.SigmaOf("d2"), 1e-3);
  EXPECT_DOUBLE_EQ(over.SigmaOf("theta1"), 1e-3);
  EXPECT_TRUE(load("").tolerances.empty());

  const auto message = [&](const std::string& tolerances) {
    try {
      load(tolerances);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(message("tolerances:\n  links:\n    - {d: 1}\n    - {}\n"),
              ::testing::HasSubstr("r.yaml:9 key 'tolerances.links[0].d': a tolerance is given "
                                   "for a value that is not a parameter of link 1"));
  EXPECT_THAT(message("tolerances:\n  every_link: {theta: -1}\n"),
              ::testing::HasSubstr("key 'tolerances.every_link.theta': expected a standard "
                                   "deviation > 0"));
  EXPECT_THAT(message("tolerances:\n  planes:\n    - {u: 1}\n"),
              ::testing::HasSubstr("'tolerances.planes': expected a list of 2 entries"));
  EXPECT_THAT(message("tolerances:\n  links:\n    - {}\n"),
              ::testing::HasSubstr("'tolerances.links': expected a list of 2 entries"));
  EXPECT_THAT(message("tolerances:\n  base: {x: 1, twist: 2}\n"),
              ::testing::HasSubstr("key 'tolerances.base.twist': unknown key"));
  EXPECT_THAT(
      message("tolerances:\n  tool: {roll: 0}\n"),
      ::testing::HasSubstr("key 'tolerances.tool.roll': expected a standard deviation > 0"));
}

}  // namespace
}  // namespace lrcal
