// Joint offsets (joint_offsets.h): a calibration that is offsets alone is found exactly; for the
// paper's full errors the fitted offsets are a least-squares optimum of the weighted position and
// orientation errors (every nearby δ does worse) and their error, stated over the configurations,
// is smaller than the nominal model's.
#include "lrcal/kinematics/joint_offsets.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "lrcal/kinematics/forward_kinematics.h"
#include "test_util.h"

namespace lrcal {
namespace {

RobotModel WithLinkValues(const RobotModel& robot, const Eigen::VectorXd& values) {
  std::vector<Link> links = robot.links();
  for (std::size_t k = 0; k < links.size(); ++k)
    for (int v = 0; v < kValuesPerLink; ++v)
      links[k].nominal[static_cast<std::size_t>(v)] =
          values[static_cast<Eigen::Index>(kValuesPerLink * k) + v];
  return RobotModel("calibrated", links, "test", robot.base(), robot.tool());
}

ConfigurationSet Workspace(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> angle(-2.5, 2.5);
  ConfigurationSet configs(6);
  for (int i = 0; i < count; ++i) {
    std::vector<double> q(6);
    for (double& v : q) v = angle(rng);
    configs.Add(q.data());
  }
  return configs;
}

double SumOfSquares(const RobotModel& nominal, const RobotModel& calibrated,
                    const ConfigurationSet& configs, const Eigen::VectorXd& delta) {
  double sum = 0;
  for (int i = 0; i < configs.size(); ++i) {
    std::vector<double> q(configs.q(i), configs.q(i) + 6);
    for (int j = 0; j < 6; ++j) q[static_cast<std::size_t>(j)] += delta[j];
    const Pose<double> a =
        ForwardKinematics<double>(nominal, nominal.nominal_values().data(), q.data());
    const Pose<double> b =
        ForwardKinematics<double>(calibrated, calibrated.nominal_values().data(), configs.q(i));
    const Eigen::AngleAxisd turn(b.R_BT * a.R_BT.transpose());
    sum += (a.p_BT - b.p_BT).squaredNorm() +
           kOffsetFitLength * kOffsetFitLength * turn.angle() * turn.angle();
  }
  return sum;
}

TEST(JointOffsets, OffsetsAloneAreFoundExactly) {
  const RobotModel& nominal = testing::PaperRobot();
  Eigen::VectorXd values = nominal.nominal_values();
  const Eigen::VectorXd truth =
      (Eigen::VectorXd(6) << 2e-3, -1e-3, 3e-3, -2e-3, 1e-3, 4e-3).finished();
  for (int j = 0; j < 6; ++j) values[kValuesPerLink * j + kTheta] += truth[j];
  const JointOffsetFit fit =
      FitJointOffsets(nominal, WithLinkValues(nominal, values), Workspace(200, 1));
  EXPECT_THAT(fit.offsets, testing::EigenNear(truth, 1e-12));
  EXPECT_LT(fit.rms, 1e-12);
  EXPECT_GT(fit.nominal_rms, 1e-3);
}

TEST(JointOffsets, FullErrorsGiveALeastSquaresOptimumAndItsError) {
  const RobotModel& nominal = testing::PaperRobot();
  const RobotModel calibrated = WithLinkValues(nominal, testing::PaperTrueValues());
  const ConfigurationSet configs = Workspace(300, 2);
  const JointOffsetFit fit = FitJointOffsets(nominal, calibrated, configs);
  EXPECT_GT(fit.rms, 1e-4);  // the paper's errors are not offsets alone
  EXPECT_LT(fit.rms, fit.nominal_rms);
  EXPECT_LE(fit.rms, fit.worst);
  const double best = SumOfSquares(nominal, calibrated, configs, fit.offsets);
  EXPECT_NEAR(best / configs.size(),
              fit.rms * fit.rms +
                  kOffsetFitLength * kOffsetFitLength * fit.orientation_rms * fit.orientation_rms,
              1e-15);
  for (int j = 0; j < 6; ++j)
    for (double h : {-1e-5, 1e-5}) {
      Eigen::VectorXd other = fit.offsets;
      other[j] += h;
      EXPECT_GT(SumOfSquares(nominal, calibrated, configs, other), best) << j;
    }
}

}  // namespace
}  // namespace lrcal
