// Validation metrics against closed forms.
#include "lrcal/kinematics/pose_errors.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "test_util.h"

namespace lrcal {
namespace {

TEST(Validation, RotationVectorOfKnownRotations) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, -2, 0.5).normalized();
  for (double angle : {1e-9, 1e-4, 0.3, 3.0}) {
    Eigen::Matrix3d R = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    EXPECT_LT((RotationVector(R) - angle * axis).norm(), 1e-12 * std::max(1.0, angle)) << angle;
  }
  EXPECT_LT(RotationVector(Eigen::Matrix3d::Identity()).norm(), 1e-300);
}

TEST(Validation, IdenticalModelsHaveZeroError) {
  const RobotModel& robot = testing::PaperRobot();
  auto e = ComparePoses(robot, robot.nominal_values(), robot.nominal_values(),
                        testing::PaperHittingConfigurations(10));
  EXPECT_EQ(e.stats.max_position.norm(), 0.0);
  EXPECT_LT(e.stats.max_orientation.norm(), 1e-15);  // R·Rᵀ of one rotation: rounding only
}

TEST(Validation, BaseTranslationErrorIsExactlyThatTranslation) {
  // A d1 error of +1 mm lifts every tool pose by 1 mm along z0 and rotates nothing.
  const RobotModel& robot = testing::PaperRobot();
  Eigen::VectorXd lifted = robot.nominal_values();
  lifted[robot.FindValue("d1")] += 1e-3;
  auto e =
      ComparePoses(robot, lifted, robot.nominal_values(), testing::PaperHittingConfigurations(10));
  EXPECT_NEAR(e.stats.rms_position.z(), 1e-3, 1e-15);
  EXPECT_NEAR(e.stats.max_position.z(), 1e-3, 1e-15);
  EXPECT_LT(e.stats.max_position.head<2>().norm(), 1e-15);
  EXPECT_LT(e.stats.max_orientation.norm(), 1e-15);
}

TEST(Validation, Theta1ErrorIsARotationAboutBaseZ) {
  // θ1 + δ turns every pose about z0 by δ: orientation error (0, 0, δ) everywhere.
  const RobotModel& robot = testing::PaperRobot();
  Eigen::VectorXd turned = robot.nominal_values();
  turned[robot.FindValue("theta1")] += 2e-3;
  auto e =
      ComparePoses(robot, turned, robot.nominal_values(), testing::PaperHittingConfigurations(10));
  EXPECT_NEAR(e.stats.rms_orientation.z(), 2e-3, 1e-12);
  EXPECT_LT(e.stats.max_orientation.head<2>().norm(), 1e-12);
}

}  // namespace
}  // namespace lrcal
