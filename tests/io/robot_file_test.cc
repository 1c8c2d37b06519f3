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
  EXPECT_DOUBLE_EQ(robot.true_errors()[robot.FindValue("theta1")], -7.23e-3);
  EXPECT_DOUBLE_EQ(robot.true_errors()[robot.FindValue("a2")], 1.94e-3);
  EXPECT_DOUBLE_EQ(robot.true_errors()[robot.FindValue("beta6")], -3.36e-3);
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

}  // namespace
}  // namespace lrcal
