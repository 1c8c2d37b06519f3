#include "lrcal/measurement_model.h"

#include <cmath>

#include "lrcal/error.h"

namespace lrcal {

void ConfigurationSet::Add(const double* q) {
  for (int j = 0; j < num_joints_; ++j) {
    q_.push_back(q[j]);
    cos_q_.push_back(std::cos(q[j]));
    sin_q_.push_back(std::sin(q[j]));
  }
}

void ConfigurationSet::AddFrom(const ConfigurationSet& other, int i) {
  q_.insert(q_.end(), other.q(i), other.q(i) + num_joints_);
  cos_q_.insert(cos_q_.end(), other.cos_q(i), other.cos_q(i) + num_joints_);
  sin_q_.insert(sin_q_.end(), other.sin_q(i), other.sin_q(i) + num_joints_);
}

void ConfigurationSet::Reserve(int n) {
  q_.reserve(n * num_joints_);
  cos_q_.reserve(n * num_joints_);
  sin_q_.reserve(n * num_joints_);
}

ConfigurationSet ConfigurationSet::Subset(const std::vector<int>& indices) const {
  ConfigurationSet out(num_joints_);
  out.Reserve(static_cast<int>(indices.size()));
  for (int i : indices) out.AddFrom(*this, i);
  return out;
}

void PrepareModelPoint(const RobotModel& robot, const double* v, const Plane& plane,
                       ModelPoint* point) {
  point->num_links = robot.num_links();
  for (int i = 0; i < robot.num_links(); ++i) {
    const double* lv = v + kValuesPerLink * i;
    ModelPoint::LinkTrig& t = point->links[i];
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
  point->plane = plane;
}

Pose<double> ToolPose(const ModelPoint& point, const ConfigurationSet& configs, int c,
                      ChainFrames* frames) {
  const double* cq = configs.cos_q(c);
  const double* sq = configs.sin_q(c);
  const double* q = configs.q(c);
  // Columns of R_{B,i}: x, y, z; o the origin of frame i.
  Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                  z = Eigen::Vector3d::UnitZ(), o = Eigen::Vector3d::Zero();
  for (int i = 0; i < point.num_links; ++i) {
    const ModelPoint::LinkTrig& t = point.links[i];
    double ct, st, d = t.d;
    if (t.prismatic) {
      ct = t.cos_theta0;
      st = t.sin_theta0;
      d += q[i];
    } else {  // cos/sin(θ0 + q) by the addition theorem: no trig per configuration
      ct = t.cos_theta0 * cq[i] - t.sin_theta0 * sq[i];
      st = t.sin_theta0 * cq[i] + t.cos_theta0 * sq[i];
    }
    const Eigen::Vector3d x_common = ct * x + st * y;   // R_{i-1}·Rz(θ)·e_x
    const Eigen::Vector3d y_rotz = -st * x + ct * y;    // R_{i-1}·Rz(θ)·e_y
    const Eigen::Vector3d y_twist = t.cos_alpha * y_rotz + t.sin_alpha * z;   // ·Rx(α)·e_y
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
  if (frames) frames->tool = pose;
  return pose;
}

BeamMiss ClassifyReading(double h, double n_dot_b, const RangerSpec& ranger) {
  if (!(std::fabs(n_dot_b) > 1e-12) || !std::isfinite(h)) return BeamMiss::kParallel;
  if (h <= 0) return BeamMiss::kBehind;
  if (h < ranger.min_range || h > ranger.max_range) return BeamMiss::kOutOfRange;
  if (std::fabs(n_dot_b) < std::cos(ranger.max_incidence)) return BeamMiss::kGrazing;
  return BeamMiss::kNone;
}

MeasurementModel::MeasurementModel(const RobotModel& robot, const Plane& nominal_plane,
                                   ParameterSet parameters)
    : robot_(&robot),
      nominal_plane_(nominal_plane),
      parameters_(std::move(parameters)),
      chart_(nominal_plane.normal) {}

Eigen::VectorXd MeasurementModel::LinkValues(const double* e) const {
  Eigen::VectorXd v = robot_->nominal_values();
  for (int k = 0; k < parameters_.num_robot(); ++k) v[parameters_.robot_values[k]] += e[k];
  return v;
}

Plane MeasurementModel::PlaneAt(const double* e) const {
  Plane p = nominal_plane_;
  if (parameters_.EstimatesNormal()) {
    const int* u = parameters_.u_index;
    Eigen::Matrix<double, 3, 2> unused;
    chart_.NormalAndJacobian(u[0] >= 0 ? e[u[0]] : 0.0, u[1] >= 0 ? e[u[1]] : 0.0, &p.normal,
                             &unused);
  }
  if (parameters_.f_index >= 0) p.offset += e[parameters_.f_index];
  return p;
}

void MeasurementModel::Prepare(const double* e, ModelPoint* point) const {
  double v[kValuesPerLink * kMaxLinks];
  const Eigen::VectorXd& nominal = robot_->nominal_values();
  for (int k = 0; k < robot_->num_values(); ++k) v[k] = nominal[k];
  for (int k = 0; k < parameters_.num_robot(); ++k) v[parameters_.robot_values[k]] += e[k];
  Plane plane = nominal_plane_;
  if (parameters_.EstimatesNormal()) {
    const int* u = parameters_.u_index;
    chart_.NormalAndJacobian(u[0] >= 0 ? e[u[0]] : 0.0, u[1] >= 0 ? e[u[1]] : 0.0,
                             &plane.normal, &point->dn_du);
  }
  if (parameters_.f_index >= 0) plane.offset += e[parameters_.f_index];
  PrepareModelPoint(*robot_, v, plane, point);
}

double MeasurementModel::Evaluate(const ModelPoint& point, const ConfigurationSet& configs,
                                  int i, double* h, double* row) const {
  ChainFrames frames;
  const Pose<double> pose = ToolPose(point, configs, i, row ? &frames : nullptr);
  const Eigen::Vector3d& n = point.plane.normal;
  const Eigen::Vector3d b = pose.R_BT.col(2);
  const double nb = n.dot(b);
  *h = -(n.dot(pose.p_BT) + point.plane.offset) / nb;
  if (!row) return nb;
  const Eigen::Vector3d p_hit = pose.p_BT + (*h) * b;
  const double inv = -1.0 / nb;
  int col = 0;
  // Walk the estimated robot values in order; they are sorted by link value index.
  for (int k = 0; k < parameters_.num_robot(); ++k, ++col) {
    const int index = parameters_.robot_values[k];
    const int link = index / kValuesPerLink;
    double g = 0;
    switch (index % kValuesPerLink) {
      case kTheta:
        g = (p_hit - frames.o_prev[link]).cross(n).dot(frames.z_prev[link]);
        break;
      case kD:
        g = n.dot(frames.z_prev[link]);
        break;
      case kA:
        g = n.dot(frames.x_common[link]);
        break;
      case kAlpha:
        g = (p_hit - frames.o[link]).cross(n).dot(frames.x_common[link]);
        break;
      case kBeta:
        g = (p_hit - frames.o[link]).cross(n).dot(frames.y_twist[link]);
        break;
    }
    row[col] = g * inv;
  }
  for (int c = 0; c < 2; ++c)
    if (parameters_.u_index[c] >= 0) row[parameters_.u_index[c]] = inv * p_hit.dot(point.dn_du.col(c));
  if (parameters_.f_index >= 0) row[parameters_.f_index] = inv;
  return nb;
}

Eigen::Matrix<double, 6, Eigen::Dynamic> GeometricJacobian(const RobotModel& model,
                                                           const Eigen::VectorXd& link_values,
                                                           const double* q) {
  ModelPoint point;
  PrepareModelPoint(model, link_values.data(), Plane{}, &point);
  ConfigurationSet one(model.num_links());
  one.Add(q);
  ChainFrames frames;
  const Pose<double> pose = ToolPose(point, one, 0, &frames);
  Eigen::Matrix<double, 6, Eigen::Dynamic> J(6, model.num_links());
  for (int i = 0; i < model.num_links(); ++i) {
    const Eigen::Vector3d& z = frames.z_prev[i];
    if (model.links()[i].joint == JointType::kRevolute) {
      J.col(i) << z.cross(pose.p_BT - frames.o_prev[i]), z;
    } else {
      J.col(i) << z, Eigen::Vector3d::Zero();
    }
  }
  return J;
}

}  // namespace lrcal
