// Gravity's load on each joint (gravity_torque.h) against an independent computation: the
// generalised force is −∂V/∂q of the potential V = −Σ m g·p, by central differences of positions
// from the reference kinematics.
#include "lrcal/kinematics/gravity_torque.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "lrcal/core/error.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "test_util.h"

namespace lrcal {
namespace {

using testing::EigenNear;
// Central differences of a smooth potential with step 1e-6 rad: truncation ~1e-12 relative,
// rounding ~1e-10 N·m on loads of ~100 N·m.
constexpr double kDifferenceAgreement = 1e-6;  // N·m

MassModel ArmMasses() {
  MassModel m;
  m.masses = {{2, 20.0, {-0.5, 0.02, 0.0}},
              {3, 5.0, {0.0, 0.0, 0.1}},
              {4, 12.0, {0.0, 0.4, 0.0}},
              {6, 3.0, {0.01, 0.0, -0.1}},
              {7, 4.0, {0.0, 0.05, 0.1}}};  // link N + 1: the payload on the tool
  return m;
}

// The potential −Σ m g·p of the masses, each placed by the reference kinematics of the chain up to
// its link (a robot truncated there), the payload by the whole chain with its tool.
double Potential(const RobotModel& robot, const MassModel& masses, const std::vector<double>& q,
                 const Eigen::Vector3d& g) {
  double v = 0;
  for (const PointMass& m : masses.masses) {
    Eigen::Matrix4d X = FixedTransformMatrix<double>(robot.base());
    for (int i = 0; i < std::min(m.link, robot.num_links()); ++i) {
      const double* l = robot.nominal_values().data() + kValuesPerLink * i;
      X = X * LinkTransform<double>(l[kTheta] + q[static_cast<std::size_t>(i)], l[kD], l[kA],
                                    l[kAlpha], l[kBeta]);
    }
    if (m.link == robot.num_links() + 1) X = X * FixedTransformMatrix<double>(robot.tool());
    const Eigen::Vector3d p = X.block<3, 3>(0, 0) * m.com + X.block<3, 1>(0, 3);
    v -= m.mass * g.dot(p);
  }
  return v;
}

TEST(GravityTorques, AreMinusTheGradientOfThePotential) {
  const RobotModel& robot = testing::PaperRobotWithFrames();
  const MassModel masses = ArmMasses();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-3, 3);
  for (const Eigen::Vector3d& g : {Eigen::Vector3d(0, 0, -9.81), Eigen::Vector3d(3.0, -4.0, -8.0),
                                   Eigen::Vector3d(0, 1.6, 0)}) {
    for (int trial = 0; trial < 5; ++trial) {
      std::vector<double> q(6);
      for (double& x : q) x = angle(rng);
      const Eigen::VectorXd tau =
          GravityTorques(robot, robot.nominal_values().data(), masses, q.data(), g);
      Eigen::VectorXd expected(6);
      const double step = 1e-6;
      for (int j = 0; j < 6; ++j) {
        std::vector<double> plus = q, minus = q;
        plus[static_cast<std::size_t>(j)] += step;
        minus[static_cast<std::size_t>(j)] -= step;
        expected[j] =
            -(Potential(robot, masses, plus, g) - Potential(robot, masses, minus, g)) / (2 * step);
      }
      EXPECT_THAT(tau, EigenNear(expected, kDifferenceAgreement)) << g.transpose();
      EXPECT_GT(tau.cwiseAbs().maxCoeff(), 1.0);  // a real load, not zeros agreeing
    }
  }
}

TEST(GravityTorques, VanishWithoutGravityAndAlongAVerticalFirstAxis) {
  const RobotModel& robot = testing::PaperRobot();  // base upright: joint 1's axis is z
  const MassModel masses = ArmMasses();
  const std::vector<double> q = {0.3, -0.7, 1.1, 0.4, -0.9, 2.0};
  EXPECT_TRUE(GravityTorques(robot, robot.nominal_values().data(), masses, q.data(),
                             Eigen::Vector3d::Zero())
                  .isZero(0.0));
  const Eigen::VectorXd upright = GravityTorques(robot, robot.nominal_values().data(), masses,
                                                 q.data(), Eigen::Vector3d(0, 0, -9.81));
  EXPECT_NEAR(upright[0], 0.0, 1e-12);
  EXPECT_GT(std::abs(upright[1]), 10.0);
  EXPECT_TRUE(GravityTorques(robot, robot.nominal_values().data(), MassModel{}, q.data(),
                             Eigen::Vector3d(0, 0, -9.81))
                  .isZero(0.0));
}

TEST(MassModel, RefusesABadMassNamingIt) {
  MassModel m;
  m.masses = {{8, 1.0, {0, 0, 0}}};
  try {
    m.Validate(6, "robot.yaml: masses");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("masses[1].link"));
  }
  m.masses = {{2, -1.0, {0, 0, 0}}};
  EXPECT_THROW(m.Validate(6, "masses"), InputError);
}

}  // namespace
}  // namespace lrcal
