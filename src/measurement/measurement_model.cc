#include "lrcal/measurement/measurement_model.h"

#include <cmath>

#include "lrcal/core/error.h"

namespace lrcal {

void PrepareModelPoint(const RobotModel& robot, const double* v, const Plane& plane,
                       ModelPoint* point) {
  PrepareChainPoint(robot, v, point);
  point->plane = plane;
  point->ranger_offset = 0;
  point->ranger_scale = 0;
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
    chart_.NormalAndJacobian(u[0] >= 0 ? e[u[0]] : 0.0, u[1] >= 0 ? e[u[1]] : 0.0, &plane.normal,
                             &point->dn_du);
  }
  if (parameters_.f_index >= 0) plane.offset += e[parameters_.f_index];
  PrepareModelPoint(*robot_, v, plane, point);
  if (parameters_.ranger_offset_index >= 0)
    point->ranger_offset = e[parameters_.ranger_offset_index];
  if (parameters_.ranger_scale_index >= 0) point->ranger_scale = e[parameters_.ranger_scale_index];
}

void MeasurementModel::ApplyRanger(const ModelPoint& point, int m, double* h, double* J) const {
  const int io = parameters_.ranger_offset_index, is = parameters_.ranger_scale_index;
  const double o = point.ranger_offset, s = point.ranger_scale;
  if (io < 0 && is < 0 && o == 0 && s == 0) return;
  if (J) {
    for (int k = 0; k < num_parameters(); ++k) {
      double* col = J + static_cast<std::size_t>(k) * m;
      if (k == io) {
        for (int i = 0; i < m; ++i) col[i] = 1.0;
      } else if (k == is) {
        for (int i = 0; i < m; ++i) col[i] = h[i];
      } else if (s != 0) {
        for (int i = 0; i < m; ++i) col[i] *= 1 + s;
      }
    }
  }
  for (int i = 0; i < m; ++i) h[i] = (1 + s) * h[i] + o;
}

double MeasurementModel::Evaluate(const ModelPoint& point, const ConfigurationSet& configs, int i,
                                  double* h, double* row) const {
  ChainFrames frames;
  const Pose<double> pose = ToolPose(point, configs, i, row ? &frames : nullptr);
  const Eigen::Vector3d& n = point.plane.normal;
  const Eigen::Vector3d b = pose.R_BT.col(2);
  double nb;
  *h = BeamReading(pose, point.plane, &nb);
  if (!row) {
    ApplyRanger(point, 1, h, nullptr);
    return nb;
  }
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
    if (parameters_.u_index[c] >= 0)
      row[parameters_.u_index[c]] = inv * p_hit.dot(point.dn_du.col(c));
  if (parameters_.f_index >= 0) row[parameters_.f_index] = inv;
  // One configuration: a 1×n row is a column-major matrix with leading dimension 1.
  ApplyRanger(point, 1, h, row);
  return nb;
}

}  // namespace lrcal
