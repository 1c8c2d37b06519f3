// Compensation (compensation.h): commands planned on the nominal paper arm, corrected so that the
// calibrated arm (the paper's true errors) reaches the planned tool poses — checked by the
// calibrated model's own forward kinematics to 1e-9 — by a small joint motion; position-only
// targets; a target that needs a joint beyond its range is flagged.
#include "lrcal/kinematics/compensation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <random>

#include "lrcal/kinematics/chain.h"
#include "test_util.h"

namespace lrcal {
namespace {

constexpr double kReached = testing::tolerance::kRoundTrip;  // m, rad

// The paper arm with the given link values as its nominal ones (a calibrated robot file), and
// joint ranges narrowed to ±`range` (rad).
RobotModel WithValues(const RobotModel& robot, const Eigen::VectorXd& values, double range = 3.14) {
  std::vector<Link> links = robot.links();
  for (std::size_t k = 0; k < links.size(); ++k) {
    for (int v = 0; v < kValuesPerLink; ++v)
      links[k].nominal[static_cast<std::size_t>(v)] =
          values[static_cast<Eigen::Index>(kValuesPerLink * k) + v];
    links[k].q_min = -range;
    links[k].q_max = range;
  }
  return RobotModel("calibrated", links, "test", robot.base(), robot.tool());
}

std::vector<double> RandomCommand(std::mt19937* rng) {
  std::uniform_real_distribution<double> angle(-2.5, 2.5);
  std::vector<double> q(6);
  for (double& v : q) v = angle(*rng);
  return q;
}

double Turn(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle();
}

TEST(Compensation, CalibratedArmReachesTheNominalPlansPoses) {
  const RobotModel& nominal = testing::PaperRobot();
  const RobotModel calibrated = WithValues(nominal, testing::PaperTrueValues());
  std::mt19937 rng(11);
  int reached = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const std::vector<double> plan = RandomCommand(&rng);
    const Pose<double> target =
        ForwardKinematics<double>(nominal, nominal.nominal_values().data(), plan.data());
    const Pose<double> before =
        ForwardKinematics<double>(calibrated, calibrated.nominal_values().data(), plan.data());
    const Compensation c = Compensate(calibrated, target, plan.data());
    // Near a singular posture the arm may not reach it: then it says so.
    if (!c.converged) continue;
    ++reached;
    const Pose<double> after =
        ForwardKinematics<double>(calibrated, calibrated.nominal_values().data(), c.q.data());
    EXPECT_LT((after.p_BT - target.p_BT).norm(), kReached);
    EXPECT_LT(Turn(after.R_BT, target.R_BT), kReached);
    EXPECT_NEAR(c.position_error, (after.p_BT - target.p_BT).norm(), 1e-15);
    // The uncompensated command misses by millimetres, and the correction is the least joint
    // motion that removes that miss: within 1.5 times its first-order size |e|/σ_min(J) (large
    // only near a singular posture, where small tool motions take large joint motions).
    Eigen::VectorXd miss(6);
    miss.head<3>() = target.p_BT - before.p_BT;
    const Eigen::AngleAxisd turn(target.R_BT * before.R_BT.transpose());
    miss.tail<3>() = turn.angle() * turn.axis();
    EXPECT_GT(miss.head<3>().norm(), 1e-4);
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(
        GeometricJacobian(calibrated, calibrated.nominal_values(), plan.data()));
    const double first_order = miss.norm() / svd.singularValues().minCoeff();
    double moved = 0;
    for (int j = 0; j < 6; ++j) moved += (c.q[j] - plan[j]) * (c.q[j] - plan[j]);
    EXPECT_LT(std::sqrt(moved), 1.5 * first_order);
    EXPECT_TRUE(c.within_limits);
  }
  EXPECT_GE(reached, 95);
}

TEST(Compensation, PositionOnlyTargetsLeaveTheOrientationFree) {
  const RobotModel& nominal = testing::PaperRobot();
  const RobotModel calibrated = WithValues(nominal, testing::PaperTrueValues());
  std::mt19937 rng(12);
  const std::vector<double> plan = RandomCommand(&rng);
  Pose<double> target =
      ForwardKinematics<double>(nominal, nominal.nominal_values().data(), plan.data());
  const Compensation c = Compensate(calibrated, target, plan.data(), false);
  ASSERT_TRUE(c.converged);
  EXPECT_EQ(c.orientation_error, 0);
  const Pose<double> after =
      ForwardKinematics<double>(calibrated, calibrated.nominal_values().data(), c.q.data());
  EXPECT_LT((after.p_BT - target.p_BT).norm(), kReached);
  // A 3-D task on six joints: the least motion reaching it moves less than the full pose's.
  const Compensation full = Compensate(calibrated, target, plan.data(), true);
  ASSERT_TRUE(full.converged);
  double position_only = 0, whole = 0;
  for (int j = 0; j < 6; ++j) {
    position_only += (c.q[j] - plan[j]) * (c.q[j] - plan[j]);
    whole += (full.q[j] - plan[j]) * (full.q[j] - plan[j]);
  }
  EXPECT_LT(position_only, whole);
}

TEST(Compensation, ATargetBeyondAJointsRangeIsFlagged) {
  const RobotModel& nominal = testing::PaperRobot();
  const RobotModel narrow = WithValues(nominal, nominal.nominal_values(), 1.0);
  std::vector<double> start = {0.3, 1.0, -0.4, 0.5, 0.6, -0.2};  // joint 2 at its limit
  std::vector<double> beyond = start;
  beyond[1] = 1.02;
  const Pose<double> target =
      ForwardKinematics<double>(narrow, narrow.nominal_values().data(), beyond.data());
  const Compensation c = Compensate(narrow, target, start.data());
  ASSERT_TRUE(c.converged);
  EXPECT_NEAR(c.q[1], 1.02, 1e-9);
  EXPECT_FALSE(c.within_limits);
}

}  // namespace
}  // namespace lrcal
