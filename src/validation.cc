#include "lrcal/validation.h"

#include <Eigen/Geometry>
#include <cmath>

namespace lrcal {

Eigen::Vector3d RotationVector(const Eigen::Matrix3d& R) {
  Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

PoseErrors ComparePoses(const RobotModel& robot, const Eigen::VectorXd& true_values,
                        const Eigen::VectorXd& model_values, const ConfigurationSet& configs) {
  ModelPoint truth, model;
  PrepareModelPoint(robot, true_values.data(), Plane{}, &truth);
  PrepareModelPoint(robot, model_values.data(), Plane{}, &model);
  const int m = configs.size();
  PoseErrors out;
  out.position.resize(3, m);
  out.orientation.resize(3, m);
  for (int i = 0; i < m; ++i) {
    const Pose<double> pt = ToolPose(truth, configs, i);
    const Pose<double> pm = ToolPose(model, configs, i);
    out.position.col(i) = pt.p_BT - pm.p_BT;
    out.orientation.col(i) = RotationVector(pt.R_BT * pm.R_BT.transpose());
  }
  if (m > 0) {
    out.stats.rms_position = (out.position.array().square().rowwise().sum() / m).sqrt();
    out.stats.rms_orientation = (out.orientation.array().square().rowwise().sum() / m).sqrt();
    out.stats.max_position = out.position.cwiseAbs().rowwise().maxCoeff();
    out.stats.max_orientation = out.orientation.cwiseAbs().rowwise().maxCoeff();
  }
  return out;
}

}  // namespace lrcal
