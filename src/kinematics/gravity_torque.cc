#include "lrcal/kinematics/gravity_torque.h"

#include <cmath>

#include "lrcal/core/error.h"
#include "lrcal/kinematics/forward_kinematics.h"

namespace lrcal {

void MassModel::Validate(int num_links, const std::string& source) const {
  for (std::size_t i = 0; i < masses.size(); ++i) {
    const PointMass& m = masses[i];
    const std::string where = source + "[" + std::to_string(i + 1) + "]";
    if (m.link < 1 || m.link > num_links + 1)
      throw InputError(where + ".link", "expected a link from 1 to " + std::to_string(num_links) +
                                            ", or 'tool' for a payload; got " +
                                            std::to_string(m.link));
    if (!(m.mass > 0) || !std::isfinite(m.mass))
      throw InputError(where + ".mass", "expected a positive mass in kg");
    if (!m.com.allFinite()) throw InputError(where + ".com", "expected three finite numbers (m)");
  }
}

Eigen::VectorXd GravityTorques(const RobotModel& robot, const double* link_values,
                               const MassModel& masses, const double* q,
                               const Eigen::Vector3d& gravity) {
  const int n = robot.num_links();
  Eigen::VectorXd tau = Eigen::VectorXd::Zero(n);
  if (masses.empty() || gravity.isZero(0.0)) return tau;
  // Frames 0..N and the tool in B: frame[k] is link k's (frame 0 the chain's base).
  std::vector<Eigen::Matrix4d> frame(static_cast<std::size_t>(n) + 2);
  frame[0] = FixedTransformMatrix<double>(robot.base());
  for (int i = 0; i < n; ++i) {
    const double* v = link_values + kValuesPerLink * i;
    const bool revolute = robot.links()[static_cast<std::size_t>(i)].joint == JointType::kRevolute;
    frame[static_cast<std::size_t>(i) + 1] =
        frame[static_cast<std::size_t>(i)] *
        LinkTransform<double>(v[kTheta] + (revolute ? q[i] : 0.0), v[kD] + (revolute ? 0.0 : q[i]),
                              v[kA], v[kAlpha], v[kBeta]);
  }
  frame[static_cast<std::size_t>(n) + 1] =
      frame[static_cast<std::size_t>(n)] * FixedTransformMatrix<double>(robot.tool());
  for (const PointMass& m : masses.masses) {
    const Eigen::Matrix4d& X = frame[static_cast<std::size_t>(m.link)];
    const Eigen::Vector3d p = X.block<3, 3>(0, 0) * m.com + X.block<3, 1>(0, 3);
    const Eigen::Vector3d force = m.mass * gravity;
    // Joint j (1-based) turns every link from j on: masses on links ≥ j and the payload.
    for (int j = 1; j <= std::min(m.link, n); ++j) {
      const Eigen::Matrix4d& J = frame[static_cast<std::size_t>(j) - 1];
      const Eigen::Vector3d z = J.block<3, 1>(0, 2);
      const bool revolute =
          robot.links()[static_cast<std::size_t>(j) - 1].joint == JointType::kRevolute;
      tau[j - 1] += revolute ? z.dot((p - J.block<3, 1>(0, 3)).cross(force)) : z.dot(force);
    }
  }
  return tau;
}

}  // namespace lrcal
