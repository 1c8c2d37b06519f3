#include "lrcal/kinematics/chain.h"

#include <cmath>

namespace lrcal {

void PrepareChainPoint(const RobotModel& robot, const double* v, ChainPoint* point) {
  point->num_links = robot.num_links();
  for (int i = 0; i < robot.num_links(); ++i) {
    const double* lv = v + kValuesPerLink * i;
    ChainPoint::LinkTrig& t = point->links[i];
    t.cos_theta0 = std::cos(lv[kTheta]);
    t.sin_theta0 = std::sin(lv[kTheta]);
    t.cos_alpha = std::cos(lv[kAlpha]);
    t.sin_alpha = std::sin(lv[kAlpha]);
    t.cos_beta = std::cos(lv[kBeta]);
    t.sin_beta = std::sin(lv[kBeta]);
    t.a = lv[kA];
    t.d = lv[kD];
    t.prismatic = robot.links()[i].joint == JointType::kPrismatic;
  }
  point->base = robot.base();
  point->tool = robot.tool();
  point->has_base = !robot.base().IsIdentity();
  point->has_tool = !robot.tool().IsIdentity();
}

Pose<double> ToolPose(const ChainPoint& point, const ConfigurationSet& configs, int c,
                      ChainFrames* frames) {
  const double* cq = configs.cos_q(c);
  const double* sq = configs.sin_q(c);
  const double* q = configs.q(c);
  // Columns of R_{B,i}: x, y, z; o the origin of frame i.
  Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                  z = Eigen::Vector3d::UnitZ(), o = Eigen::Vector3d::Zero();
  if (point.has_base) {
    x = point.base.rotation.col(0);
    y = point.base.rotation.col(1);
    z = point.base.rotation.col(2);
    o = point.base.translation;
  }
  for (int i = 0; i < point.num_links; ++i) {
    const ChainPoint::LinkTrig& t = point.links[i];
    double ct, st, d = t.d;
    if (t.prismatic) {
      ct = t.cos_theta0;
      st = t.sin_theta0;
      d += q[i];
    } else {  // cos/sin(θ0 + q) by the addition theorem: no trig per configuration
      ct = t.cos_theta0 * cq[i] - t.sin_theta0 * sq[i];
      st = t.sin_theta0 * cq[i] + t.cos_theta0 * sq[i];
    }
    const Eigen::Vector3d x_common = ct * x + st * y;                        // R_{i-1}·Rz(θ)·e_x
    const Eigen::Vector3d y_rotz = -st * x + ct * y;                         // R_{i-1}·Rz(θ)·e_y
    const Eigen::Vector3d y_twist = t.cos_alpha * y_rotz + t.sin_alpha * z;  // ·Rx(α)·e_y
    const Eigen::Vector3d z_alpha = -t.sin_alpha * y_rotz + t.cos_alpha * z;  // ·Rx(α)·e_z
    if (frames) {
      frames->o_prev[i] = o;
      frames->z_prev[i] = z;
      frames->x_common[i] = x_common;
      frames->y_twist[i] = y_twist;
    }
    o += t.a * x_common + d * z;
    // ·Ry(β): x ← cβ·x − sβ·z, z ← sβ·x + cβ·z.
    x = t.cos_beta * x_common - t.sin_beta * z_alpha;
    z = t.sin_beta * x_common + t.cos_beta * z_alpha;
    y = y_twist;
    if (frames) frames->o[i] = o;
  }
  Pose<double> pose;
  pose.R_BT.col(0) = x;
  pose.R_BT.col(1) = y;
  pose.R_BT.col(2) = z;
  pose.p_BT = o;
  if (point.has_tool) {
    pose.p_BT += pose.R_BT * point.tool.translation;
    pose.R_BT = pose.R_BT * point.tool.rotation;
  }
  if (frames) frames->tool = pose;
  return pose;
}

Eigen::Vector3d LinkValueRotation(const ChainFrames& f, int index) {
  const int link = index / kValuesPerLink;
  switch (index % kValuesPerLink) {
    case kTheta:
      return f.z_prev[link];
    case kAlpha:
      return f.x_common[link];
    case kBeta:
      return f.y_twist[link];
    default:  // kD, kA
      return Eigen::Vector3d::Zero();
  }
}

Eigen::Vector3d LinkValuePointMotion(const ChainFrames& f, int index, const Eigen::Vector3d& P) {
  const int link = index / kValuesPerLink;
  switch (index % kValuesPerLink) {
    case kTheta:
      return f.z_prev[link].cross(P - f.o_prev[link]);
    case kD:
      return f.z_prev[link];
    case kA:
      return f.x_common[link];
    case kAlpha:
      return f.x_common[link].cross(P - f.o[link]);
    default:  // kBeta
      return f.y_twist[link].cross(P - f.o[link]);
  }
}

Eigen::Matrix<double, 6, Eigen::Dynamic> GeometricJacobian(const RobotModel& model,
                                                           const Eigen::VectorXd& link_values,
                                                           const double* q) {
  ChainPoint point;
  PrepareChainPoint(model, link_values.data(), &point);
  ConfigurationSet one(model.num_links());
  one.Add(q);
  ChainFrames frames;
  ToolPose(point, one, 0, &frames);
  Eigen::Matrix<double, 6, Eigen::Dynamic> J(6, model.num_links());
  GeometricJacobian(model, frames, &J);
  return J;
}

void GeometricJacobian(const RobotModel& model, const ChainFrames& frames,
                       Eigen::Matrix<double, 6, Eigen::Dynamic>* J) {
  J->resize(6, model.num_links());
  for (int i = 0; i < model.num_links(); ++i) {
    const Eigen::Vector3d& z = frames.z_prev[i];
    if (model.links()[i].joint == JointType::kRevolute) {
      J->col(i) << z.cross(frames.tool.p_BT - frames.o_prev[i]), z;
    } else {
      J->col(i) << z, Eigen::Vector3d::Zero();
    }
  }
}

}  // namespace lrcal
