#include "lrcal/kinematics/compensation.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "lrcal/kinematics/chain.h"
#include "lrcal/kinematics/joint_constraints.h"

namespace lrcal {

namespace {

// The error to remove at `pose`: the target's position minus the tool's, then the rotation vector
// of R_target·R_BTᵀ (base frame), when asked.
Eigen::VectorXd ToolError(const Pose<double>& pose, const Pose<double>& target, bool orientation) {
  Eigen::VectorXd e(orientation ? 6 : 3);
  e.head<3>() = target.p_BT - pose.p_BT;
  if (orientation) {
    const Eigen::AngleAxisd turn(target.R_BT * pose.R_BT.transpose());
    e.tail<3>() = turn.angle() * turn.axis();
  }
  return e;
}

}  // namespace

Compensation Compensate(const RobotModel& calibrated, const Pose<double>& target,
                        const double* start, bool orientation) {
  constexpr int kMaxSteps = 100;
  constexpr double kStartDamping = 1e-3;  // m (or rad): λ of the first step
  const Eigen::VectorXd& values = calibrated.nominal_values();
  const int n = calibrated.num_links(), rows = orientation ? 6 : 3;
  Compensation c;
  c.q.assign(start, start + n);
  Eigen::VectorXd e = ToolError(ForwardKinematics<double>(calibrated, values.data(), c.q.data()),
                                target, orientation);
  double lambda = kStartDamping;
  const auto done = [&](const Eigen::VectorXd& error) {
    return error.head<3>().norm() < kCompensationTolerance &&
           (!orientation || error.tail<3>().norm() < kCompensationTolerance);
  };
  for (; c.iterations < kMaxSteps && !done(e) && e.allFinite(); ++c.iterations) {
    const Eigen::Matrix<double, 6, Eigen::Dynamic> G =
        GeometricJacobian(calibrated, values, c.q.data());
    const Eigen::MatrixXd J = G.topRows(rows);
    // Retry with more damping until the step reduces the error (at most 10 tries).
    for (int attempt = 0; attempt < 10; ++attempt) {
      const Eigen::MatrixXd A =
          J * J.transpose() + lambda * lambda * Eigen::MatrixXd::Identity(rows, rows);
      const Eigen::VectorXd dq = J.transpose() * A.ldlt().solve(e);
      std::vector<double> q = c.q;
      for (int j = 0; j < n; ++j) q[static_cast<std::size_t>(j)] += dq[j];
      const Eigen::VectorXd next = ToolError(
          ForwardKinematics<double>(calibrated, values.data(), q.data()), target, orientation);
      if (next.allFinite() && next.norm() < e.norm()) {
        c.q = q;
        e = next;
        lambda *= 0.5;
        break;
      }
      lambda = std::max(lambda * 10, 1e-9);
    }
  }
  c.converged = done(e);
  c.position_error = e.head<3>().norm();
  c.orientation_error = orientation ? e.tail<3>().norm() : 0;
  c.within_limits = WrapIntoJointRanges(calibrated, c.q.data());
  return c;
}

}  // namespace lrcal
