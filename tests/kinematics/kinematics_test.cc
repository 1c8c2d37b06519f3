// Forward kinematics of the paper's arm against poses computed by hand, and the fast
// (trig-free) chain against the reference product of elementary transforms.
#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "lrcal/core/error.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/measurement/measurement_model.h"
#include "test_util.h"

namespace lrcal {
namespace {

// Poses are built from exact rotations of ±π/2: agreement to rounding (a few ulps of 1 m).
constexpr double kExactTolerance = 1e-12;

using testing::PaperRobot;

TEST(Kinematics, PaperArmAtZeroMatchesHandComputedPose) {
  // By hand (docs/PAPER.md): at q = 0 the frames stack to a tool at (0, 2.2, 0.62) m with
  // x6 = -z0, y6 = -x0 and the beam z6 = +y0.
  const RobotModel& robot = PaperRobot();
  const double q[6] = {0, 0, 0, 0, 0, 0};
  Pose<double> pose = ForwardKinematics<double>(robot, robot.nominal_values().data(), q);
  EXPECT_NEAR(pose.p_BT.x(), 0.0, kExactTolerance);
  EXPECT_NEAR(pose.p_BT.y(), 2.2, kExactTolerance);
  EXPECT_NEAR(pose.p_BT.z(), 0.62, kExactTolerance);
  Eigen::Matrix3d expected;
  expected << 0, -1, 0,  //
      0, 0, 1,           //
      -1, 0, 0;
  EXPECT_TRUE(pose.R_BT.isApprox(expected, kExactTolerance)) << pose.R_BT;
}

TEST(Kinematics, PaperArmJointOneQuarterTurnRotatesAboutBaseZ) {
  const RobotModel& robot = PaperRobot();
  const double q[6] = {M_PI / 2, 0, 0, 0, 0, 0};
  Pose<double> pose = ForwardKinematics<double>(robot, robot.nominal_values().data(), q);
  EXPECT_NEAR(pose.p_BT.x(), -2.2, kExactTolerance);
  EXPECT_NEAR(pose.p_BT.y(), 0.0, kExactTolerance);
  EXPECT_NEAR(pose.p_BT.z(), 0.62, kExactTolerance);
  EXPECT_TRUE(pose.R_BT.col(2).isApprox(Eigen::Vector3d(-1, 0, 0), kExactTolerance));
}

TEST(Kinematics, PaperArmJointTwoQuarterTurnSwingsArmDown) {
  // Joint 2's axis at q = 0 is -x0 through (0, 0, 0.5): a quarter turn maps the tool offset
  // (0, 2.2, 0.12) from that point to (0, 0.12, -2.2), and the beam +y0 to -z0.
  const RobotModel& robot = PaperRobot();
  const double q[6] = {0, M_PI / 2, 0, 0, 0, 0};
  Pose<double> pose = ForwardKinematics<double>(robot, robot.nominal_values().data(), q);
  EXPECT_NEAR(pose.p_BT.x(), 0.0, kExactTolerance);
  EXPECT_NEAR(pose.p_BT.y(), 0.12, kExactTolerance);
  EXPECT_NEAR(pose.p_BT.z(), -1.7, kExactTolerance);
  EXPECT_TRUE(pose.R_BT.col(2).isApprox(Eigen::Vector3d(0, 0, -1), kExactTolerance));
}

TEST(Kinematics, LinkTransformMatchesCorrectedSlideMatrix) {
  // The slide's expanded A·Rot(y,β) with the typo at (1,3) corrected (NOTES.md):
  // element (0,2) = cθ·sβ + sθ·sα·cβ.
  const double th = 0.3, d = 0.2, a = 0.7, al = -0.4, be = 0.25;
  Eigen::Matrix4d A = LinkTransform<double>(th, d, a, al, be);
  using std::cos;
  using std::sin;
  Eigen::Matrix4d slide;
  slide << cos(th) * cos(be) - sin(th) * sin(al) * sin(be), -sin(th) * cos(al),
      cos(th) * sin(be) + sin(th) * sin(al) * cos(be), a * cos(th),  //
      sin(th) * cos(be) + cos(th) * sin(al) * sin(be), cos(th) * cos(al),
      sin(th) * sin(be) - cos(th) * sin(al) * cos(be), a * sin(th),  //
      -cos(al) * sin(be), sin(al), cos(al) * cos(be), d,             //
      0, 0, 0, 1;
  EXPECT_TRUE(A.isApprox(slide, 1e-14)) << A << "\n" << slide;
}

TEST(Kinematics, FastChainMatchesReferenceOnRandomModelsAndConfigurations) {
  const RobotModel& robot = PaperRobot();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uq(-M_PI, M_PI), ue(-0.05, 0.05);
  for (int trial = 0; trial < 200; ++trial) {
    Eigen::VectorXd values = robot.nominal_values();
    for (int k = 0; k < values.size(); ++k) values[k] += ue(rng);
    double q[6];
    for (double& v : q) v = uq(rng);
    Pose<double> ref = ForwardKinematics<double>(robot, values.data(), q);
    ModelPoint point;
    PrepareModelPoint(robot, values.data(), Plane{}, &point);
    ConfigurationSet one(6);
    one.Add(q);
    Pose<double> fast = ToolPose(point, one, 0);
    EXPECT_LT((ref.p_BT - fast.p_BT).norm(), 1e-13);
    EXPECT_LT((ref.R_BT - fast.R_BT).norm(), 1e-13);
  }
}

TEST(Kinematics, GeometricJacobianMatchesFiniteDifferences) {
  const double q[6] = {0.3, -0.7, 1.1, 0.4, -0.9, 0.2};
  const auto [linear, angular] = testing::GeometricJacobianDeviation(PaperRobot(), q);
  EXPECT_LT(linear, 1e-8);
  EXPECT_LT(angular, 1e-6);
}

}  // namespace
}  // namespace lrcal
