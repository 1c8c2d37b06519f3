#include "lrcal/kinematics/joint_offsets.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "lrcal/kinematics/chain.h"
#include "lrcal/kinematics/forward_kinematics.h"

namespace lrcal {

namespace {

// q + δ for configuration i.
std::vector<double> Shifted(const ConfigurationSet& configs, int i, const Eigen::VectorXd& delta) {
  std::vector<double> q(configs.q(i), configs.q(i) + configs.num_joints());
  for (std::size_t j = 0; j < q.size(); ++j) q[j] += delta[static_cast<Eigen::Index>(j)];
  return q;
}

// The fit's statistics at δ.
void Measure(const RobotModel& nominal, const std::vector<Pose<double>>& targets,
             const ConfigurationSet& configs, JointOffsetFit* fit) {
  double sum = 0, sum0 = 0, sum_turn = 0;
  for (int i = 0; i < configs.size(); ++i) {
    const auto u = static_cast<std::size_t>(i);
    const std::vector<double> q = Shifted(configs, i, fit->offsets);
    const Pose<double> shifted =
        ForwardKinematics<double>(nominal, nominal.nominal_values().data(), q.data());
    const Pose<double> plain =
        ForwardKinematics<double>(nominal, nominal.nominal_values().data(), configs.q(i));
    const double d = (shifted.p_BT - targets[u].p_BT).norm();
    const double d0 = (plain.p_BT - targets[u].p_BT).norm();
    const double turn = Eigen::AngleAxisd(shifted.R_BT * targets[u].R_BT.transpose()).angle();
    sum += d * d;
    sum0 += d0 * d0;
    sum_turn += turn * turn;
    fit->worst = std::max(fit->worst, d);
    fit->nominal_worst = std::max(fit->nominal_worst, d0);
    fit->orientation_worst = std::max(fit->orientation_worst, turn);
  }
  const double m = configs.size();
  fit->rms = std::sqrt(sum / m);
  fit->nominal_rms = std::sqrt(sum0 / m);
  fit->orientation_rms = std::sqrt(sum_turn / m);
}

}  // namespace

JointOffsetFit FitJointOffsets(const RobotModel& nominal, const RobotModel& calibrated,
                               const ConfigurationSet& configs) {
  const int n = nominal.num_links();
  if (calibrated.num_links() != n || configs.num_joints() != n)
    throw std::invalid_argument("FitJointOffsets: the robots and configurations differ in joints");
  if (configs.size() == 0) throw std::invalid_argument("FitJointOffsets: no configurations");
  std::vector<Pose<double>> targets;
  for (int i = 0; i < configs.size(); ++i)
    targets.push_back(
        ForwardKinematics<double>(calibrated, calibrated.nominal_values().data(), configs.q(i)));
  JointOffsetFit fit;
  fit.offsets = Eigen::VectorXd::Zero(n);
  constexpr int kMaxSteps = 50;
  constexpr double kSmallStep = 1e-15;
  for (; fit.iterations < kMaxSteps; ++fit.iterations) {
    Eigen::MatrixXd JtJ = Eigen::MatrixXd::Zero(n, n);
    Eigen::VectorXd Jtr = Eigen::VectorXd::Zero(n);
    for (int i = 0; i < configs.size(); ++i) {
      const std::vector<double> q = Shifted(configs, i, fit.offsets);
      const Pose<double> pose =
          ForwardKinematics<double>(nominal, nominal.nominal_values().data(), q.data());
      Eigen::MatrixXd J = GeometricJacobian(nominal, nominal.nominal_values(), q.data());
      J.bottomRows(3) *= kOffsetFitLength;
      const Pose<double>& target = targets[static_cast<std::size_t>(i)];
      const Eigen::AngleAxisd turn(target.R_BT * pose.R_BT.transpose());
      Eigen::Matrix<double, 6, 1> r;
      r << target.p_BT - pose.p_BT, kOffsetFitLength * turn.angle() * turn.axis();
      JtJ += J.transpose() * J;
      Jtr += J.transpose() * r;
    }
    const Eigen::VectorXd step = JtJ.ldlt().solve(Jtr);
    if (!step.allFinite()) break;
    fit.offsets += step;
    if (step.cwiseAbs().maxCoeff() < kSmallStep) break;
  }
  Measure(nominal, targets, configs, &fit);
  return fit;
}

}  // namespace lrcal
