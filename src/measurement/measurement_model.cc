#include "lrcal/measurement/measurement_model.h"

#include <cmath>

#include "lrcal/core/error.h"

namespace lrcal {

void PrepareModelPoint(const RobotModel& robot, const double* v, const PlaneSet& planes,
                       ModelPoint* point) {
  PrepareChainPoint(robot, v, point);
  point->num_planes = planes.size();
  for (int p = 0; p < planes.size(); ++p) {
    point->planes[p] = planes[p];
    point->dn_du[p].setZero();
  }
  point->ranger_offset = 0;
  point->ranger_scale = 0;
}

MeasurementModel::MeasurementModel(const RobotModel& robot, const PlaneSet& nominal_planes,
                                   ParameterSet parameters)
    : robot_(&robot), nominal_planes_(nominal_planes), parameters_(std::move(parameters)) {
  if (parameters_.num_planes() != nominal_planes_.size())
    throw InputError("parameters",
                     "the parameter set has terms for " + std::to_string(parameters_.num_planes()) +
                         " plane(s) but the set-up has " + std::to_string(nominal_planes_.size()));
  for (const Plane& p : nominal_planes_) charts_.emplace_back(p.normal);
}

Eigen::VectorXd MeasurementModel::LinkValues(const double* e) const {
  Eigen::VectorXd v = robot_->nominal_values();
  for (int k = 0; k < parameters_.num_robot(); ++k) v[parameters_.robot_values[k]] += e[k];
  return v;
}

Plane MeasurementModel::PlaneAt(const double* e, int p) const {
  Plane plane = nominal_planes_[p];
  const PlaneColumns& c = parameters_.plane_columns[p];
  if (c.EstimatesNormal()) {
    Eigen::Matrix<double, 3, 2> unused;
    charts_[p].NormalAndJacobian(c.u[0] >= 0 ? e[c.u[0]] : 0.0, c.u[1] >= 0 ? e[c.u[1]] : 0.0,
                                 &plane.normal, &unused);
  }
  if (c.f >= 0) plane.offset += e[c.f];
  return plane;
}

PlaneSet MeasurementModel::PlanesAt(const double* e) const {
  PlaneSet out = nominal_planes_;
  for (int p = 0; p < num_planes(); ++p) out[p] = PlaneAt(e, p);
  return out;
}

void MeasurementModel::Prepare(const double* e, ModelPoint* point) const {
  double v[kValuesPerLink * kMaxLinks];
  const Eigen::VectorXd& nominal = robot_->nominal_values();
  for (int k = 0; k < robot_->num_values(); ++k) v[k] = nominal[k];
  for (int k = 0; k < parameters_.num_robot(); ++k) v[parameters_.robot_values[k]] += e[k];
  PrepareChainPoint(*robot_, v, point);
  point->num_planes = num_planes();
  for (int p = 0; p < num_planes(); ++p) {
    Plane& plane = point->planes[p];
    plane = nominal_planes_[p];
    point->dn_du[p].setZero();
    const PlaneColumns& c = parameters_.plane_columns[p];
    if (c.EstimatesNormal())
      charts_[p].NormalAndJacobian(c.u[0] >= 0 ? e[c.u[0]] : 0.0, c.u[1] >= 0 ? e[c.u[1]] : 0.0,
                                   &plane.normal, &point->dn_du[p]);
    if (c.f >= 0) plane.offset += e[c.f];
  }
  point->ranger_offset =
      parameters_.ranger_offset_index >= 0 ? e[parameters_.ranger_offset_index] : 0.0;
  point->ranger_scale =
      parameters_.ranger_scale_index >= 0 ? e[parameters_.ranger_scale_index] : 0.0;
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
  const int plane = configs.plane(i);
  const Eigen::Vector3d& n = point.planes[plane].normal;
  const Eigen::Vector3d b = pose.R_BT.col(2);
  double nb;
  *h = BeamReading(pose, point.planes[plane], &nb);
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
  for (int p = 0; p < parameters_.num_planes(); ++p) {
    const PlaneColumns& c = parameters_.plane_columns[p];
    const bool own = p == plane;
    for (int k = 0; k < 2; ++k)
      if (c.u[k] >= 0) row[c.u[k]] = own ? inv * p_hit.dot(point.dn_du[p].col(k)) : 0.0;
    if (c.f >= 0) row[c.f] = own ? inv : 0.0;
  }
  // One configuration: a 1×n row is a column-major matrix with leading dimension 1.
  ApplyRanger(point, 1, h, row);
  return nb;
}

}  // namespace lrcal
