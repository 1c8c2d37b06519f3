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
  if (!parameters_.EstimatesFrames()) return;
  point->base = FrameAt(0, e, &point->base_axes);
  Eigen::Matrix3d tool_axes_N;
  point->tool = FrameAt(1, e, &tool_axes_N);
  point->has_base = point->has_tool = true;
  point->tool_shifts_T = point->tool.rotation.transpose();
  point->tool_axes_T = point->tool.rotation.transpose() * tool_axes_N;
}

RigidTransform MeasurementModel::FrameAt(int f, const double* e, Eigen::Matrix3d* axes) const {
  const RigidTransform& nominal = f == 0 ? robot_->base() : robot_->tool();
  double d[6];
  FrameTermValues(e, f, d);
  const Eigen::Matrix4d X = MovedTransformMatrix<double>(nominal, d);
  RigidTransform out;
  out.rotation = X.block<3, 3>(0, 0);
  out.translation = X.block<3, 1>(0, 3);
  if (axes) {
    // d(R0·Rz·Ry·Rx)/dφ = [w]×·R: w = R0·Rz·Ry·e_x (roll), R0·Rz·e_y (pitch), R0·e_z (yaw).
    // With R = R0·Rz·Ry·Rx: R0·Rz·Ry·e_x = R·e_x and R0·Rz·e_y = R·Rxᵀ·e_y.
    axes->col(0) = out.rotation.col(0);
    axes->col(1) = out.rotation * Eigen::Vector3d(0, std::cos(d[3]), -std::sin(d[3]));
    axes->col(2) = nominal.rotation.col(2);
  }
  return out;
}

RigidTransform MeasurementModel::BaseAt(const double* e) const { return FrameAt(0, e, nullptr); }

RigidTransform MeasurementModel::ToolAt(const double* e) const { return FrameAt(1, e, nullptr); }

RobotModel MeasurementModel::RobotAt(const double* e) const {
  return robot_->WithFrames(BaseAt(e), ToolAt(e));
}

void MeasurementModel::FrameColumns(const ModelPoint& point, const Pose<double>& pose,
                                    const Eigen::Vector3d& p_hit, const Eigen::Vector3d& n,
                                    double inv, double* row) const {
  const auto put = [&](int f, int k, double g) {
    const int c = parameters_.frame_columns[f][k];
    if (c >= 0) row[c] = g * inv;
  };
  const Eigen::Vector3d from_base = p_hit - point.base.translation;
  const Eigen::Vector3d from_tool = p_hit - pose.p_BT;
  for (int k = 0; k < 3; ++k) {
    put(0, k, n[k]);
    put(0, 3 + k, from_base.cross(n).dot(point.base_axes.col(k)));
    put(1, k, n.dot(pose.R_BT * point.tool_shifts_T.col(k)));
    put(1, 3 + k, from_tool.cross(n).dot(pose.R_BT * point.tool_axes_T.col(k)));
  }
}

void MeasurementModel::ApplyRanger(const ModelPoint& point, int m, double* h, double* J) const {
  const int io = parameters_.ranger_offset_index, is = parameters_.ranger_scale_index;
  const double o = point.ranger_offset, s = point.ranger_scale;
  const bool changes_J = RangerChangesJacobian(point);
  if (!changes_J && o == 0) return;
  if (J && changes_J) {
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

double MeasurementModel::Evaluate(const ModelPoint& point, const TargetedConfigurations& configs,
                                  int i, double* h, double* row) const {
  ChainFrames frames;
  const Pose<double> pose = ToolPose(point, configs, i, row ? &frames : nullptr);
  const int plane = configs.target(i);
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
  if (parameters_.EstimatesFrames()) FrameColumns(point, pose, p_hit, n, inv, row);
  // One configuration: a 1×n row is a column-major matrix with leading dimension 1.
  ApplyRanger(point, 1, h, row);
  return nb;
}

}  // namespace lrcal
