#include "lrcal/kinematics/pose_errors.h"

#include <Eigen/Geometry>
#include <cmath>

namespace lrcal {

Eigen::Vector3d RotationVector(const Eigen::Matrix3d& R) {
  Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

std::vector<Pose<double>> ToolPoses(const RobotModel& robot, const Eigen::VectorXd& link_values,
                                    const ConfigurationSet& configs) {
  ChainPoint point;
  PrepareChainPoint(robot, link_values.data(), &point);
  std::vector<Pose<double>> poses(configs.size());
  for (int i = 0; i < configs.size(); ++i) poses[i] = ToolPose(point, configs, i);
  return poses;
}

PoseErrors ComparePoses(const RobotModel& robot, const Eigen::VectorXd& true_values,
                        const Eigen::VectorXd& model_values, const ConfigurationSet& configs) {
  return ComparePoses(robot, ToolPoses(robot, true_values, configs), model_values, configs);
}

namespace {

// The errors of `model` at configuration i into column i, then the statistics.
template <typename ModelPose>
PoseErrors ComparePoseSets(const std::vector<Pose<double>>& true_poses, int m,
                           const ModelPose& model_pose) {
  PoseErrors out;
  out.position.resize(3, m);
  out.orientation.resize(3, m);
  for (int i = 0; i < m; ++i) {
    const Pose<double>& pt = true_poses[static_cast<std::size_t>(i)];
    const Pose<double> pm = model_pose(i);
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

}  // namespace

PoseErrors ComparePoses(const RobotModel& robot, const std::vector<Pose<double>>& true_poses,
                        const Eigen::VectorXd& model_values, const ConfigurationSet& configs) {
  ChainPoint model;
  PrepareChainPoint(robot, model_values.data(), &model);
  return ComparePoseSets(true_poses, configs.size(),
                         [&](int i) { return ToolPose(model, configs, i); });
}

PoseErrors ComparePoses(const std::vector<Pose<double>>& true_poses,
                        const std::vector<Pose<double>>& model_poses) {
  return ComparePoseSets(true_poses, static_cast<int>(model_poses.size()),
                         [&](int i) { return model_poses[static_cast<std::size_t>(i)]; });
}

}  // namespace lrcal
