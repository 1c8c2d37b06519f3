#include "lrcal/kinematics/joint_constraints.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "lrcal/kinematics/chain.h"

namespace lrcal {

bool SolveJointConstraints(const RobotModel& robot, int rows, const JointConstraints& constraints,
                           double* q) {
  constexpr int kMaxSteps = 100;
  constexpr double kTolerance = 1e-12;  // the constraints' units: m, or ≈ rad
  constexpr double kMaxStep = 0.5;      // rad (or m)
  const int n = robot.num_links();
  // The geometric Jacobian from the fast path's frames (chain.h: the chain's trig once, per step
  // only the joints'). The pose stays the reference's: ToolPose agrees with it to rounding only,
  // and the seated configurations feed rank analyses whose choice among exactly confounded terms
  // follows rounding (a study's held terms would change with the last bit).
  ChainPoint chain;
  PrepareChainPoint(robot, robot.nominal_values().data(), &chain);
  ConfigurationSet one(n);
  ChainFrames frames;
  Eigen::Matrix<double, 6, Eigen::Dynamic> G(6, n);
  Eigen::VectorXd r(rows);
  Eigen::MatrixXd J(rows, n);
  for (int step = 0; step <= kMaxSteps; ++step) {
    one.Clear();
    one.Add(q);
    ToolPose(chain, one, 0, &frames);
    GeometricJacobian(robot, frames, &G);
    const Pose<double> pose = ForwardKinematics<double>(robot, robot.nominal_values().data(), q);
    constraints(pose, G, &r, &J);
    if (!r.allFinite()) return false;
    if (r.norm() < kTolerance) return true;
    if (step == kMaxSteps) break;
    const Eigen::MatrixXd JJt = J * J.transpose();
    const Eigen::LDLT<Eigen::MatrixXd> solve(JJt);
    if (solve.info() != Eigen::Success || !(std::fabs(JJt.determinant()) > 1e-18)) return false;
    const Eigen::VectorXd dq = -J.transpose() * solve.solve(r);
    const double scale = std::min(1.0, kMaxStep / std::max(dq.cwiseAbs().maxCoeff(), 1e-300));
    for (int j = 0; j < n; ++j) q[j] += scale * dq[j];
  }
  return false;
}

bool WrapIntoJointRanges(const RobotModel& robot, double* q) {
  constexpr double kTurn = 2 * 3.141592653589793;
  bool within = true;
  for (int j = 0; j < robot.num_links(); ++j) {
    const Link& link = robot.links()[static_cast<std::size_t>(j)];
    if (link.joint == JointType::kRevolute) {
      while (q[j] > link.q_max && q[j] - kTurn >= link.q_min) q[j] -= kTurn;
      while (q[j] < link.q_min && q[j] + kTurn <= link.q_max) q[j] += kTurn;
    }
    within = within && q[j] >= link.q_min && q[j] <= link.q_max;
  }
  return within;
}

}  // namespace lrcal
