// The laser-plane measurement model and its analytic identification Jacobian.
//
// For an estimate e (parameter_set.h) and a configuration q, the model gives the reading
// h(e, q) (m) and the row G(q) = ∂h/∂e of the identification Jacobian (the paper's Δh = G·Δe).
//
// The Jacobian is computed from the differential motion each parameter causes (all vectors in the
// base frame B; o_{i-1}, z_{i-1} origin and z axis of frame i-1; x'_i = R_{i-1}·Rz(θ)·e_x the
// common normal; y''_i = R_{i-1}·Rz(θ)·Rx(α)·e_y; o_i the origin of frame i; p_J = p_BT + h·b the
// beam's hit point, n the plane normal):
//     ∂h/∂θ_i = -n·(z_{i-1} × (p_J - o_{i-1})) / (n·b)      ∂h/∂d_i = -n·z_{i-1} / (n·b)
//     ∂h/∂a_i = -n·x'_i / (n·b)
//     ∂h/∂α_i = -n·(x'_i × (p_J - o_i)) / (n·b)            ∂h/∂β_i = -n·(y''_i × (p_J - o_i)) /
//     (n·b) ∂h/∂u   = -p_J·∂n/∂u / (n·b)                          ∂h/∂f   = -1 / (n·b)
// (differentiate h = -(n·p + f)/(n·b) and use n·p + f = -h·n·b: a motion of the tool moves the
// hit point, held fixed on the beam, and h changes by minus its normal component over n·b).
// The frame terms (parameter_set.h FrameTerms) are motions of the same kind: the base's shift c
// moves the whole arm along e_c of B, its roll, pitch and yaw turn it about the axes w =
// R0·Rz·Ry·e_x, R0·Rz·e_y, R0·e_z through the base origin p_B0; the tool's shift c moves the beam
// origin along R_BN·e_c, its rotations turn the beam about R_BN·w_N through p_BT:
//     ∂h/∂base_c = -n_c / (n·b)           ∂h/∂base_rot = -n·(w × (p_J - p_B0)) / (n·b)
//     ∂h/∂tool_c = -n·R_BN·e_c / (n·b)    ∂h/∂tool_rot = -n·(R_BN·w_N × (p_J - p_BT)) / (n·b)
// Tests check this against Ceres autodiff through kinematics.h and against central differences.
//
// Speed: joint angles enter only through cos q, sin q, precomputed once per configuration
// (TargetedConfigurations); the link angles' sines and cosines are computed once per estimate
// (ModelPoint). The per-configuration work is trig-free and allocation-free.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "lrcal/kinematics/chain.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/kinematics/robot_model.h"
#include "lrcal/measurement/parameter_set.h"
#include "lrcal/measurement/plane.h"
#include "lrcal/measurement/targeted_configurations.h"

namespace lrcal {

/// A robot + planes evaluated at one estimate: the chain's per-link trig (chain.h), each plane
/// and its chart's derivative, ready for many configurations.
struct ModelPoint : ChainPoint {
  int num_planes = 1;
  Plane planes[kMaxPlanes];
  Eigen::Matrix<double, 3, 2> dn_du[kMaxPlanes];
  /// The ranger at this estimate: it reads (1 + ranger_scale)·h + ranger_offset (m) for a
  /// geometric distance h. Zero unless the parameter set estimates them.
  double ranger_offset = 0;
  double ranger_scale = 0;
  /// For estimated frame terms (else unused): the base's rotation axes (columns: roll, pitch,
  /// yaw) in B, turning about base.translation; the tool's shift directions (columns: x, y, z of
  /// frame N) and rotation axes (roll, pitch, yaw), both in the tool frame T.
  Eigen::Matrix3d base_axes, tool_shifts_T, tool_axes_T;
};

/// Prepares a ModelPoint from explicit link values (5N, SI) and planes (a perfect ranger).
void PrepareModelPoint(const RobotModel& robot, const double* link_values, const PlaneSet& planes,
                       ModelPoint* point);

class MeasurementModel {
 public:
  /// `parameters` must have one entry of plane terms per plane (MakeParameterSet).
  MeasurementModel(const RobotModel& robot, const PlaneSet& nominal_planes,
                   ParameterSet parameters);

  const RobotModel& robot() const { return *robot_; }
  const PlaneSet& nominal_planes() const { return nominal_planes_; }
  const ParameterSet& parameters() const { return parameters_; }
  int num_parameters() const { return parameters_.size(); }
  int num_planes() const { return nominal_planes_.size(); }

  /// Link values (5N) at estimate e: nominal + Δ on the estimated entries.
  Eigen::VectorXd LinkValues(const double* e) const;
  /// Plane p at estimate e.
  Plane PlaneAt(const double* e, int p = 0) const;
  /// Every plane at estimate e (names kept).
  PlaneSet PlanesAt(const double* e) const;
  /// Prepares `point` at estimate e (size num_parameters()).
  void Prepare(const double* e, ModelPoint* point) const;
  /// The base and tool transforms at estimate e: the robot's, moved by the estimated frame
  /// terms (parameter_set.h FrameTerms).
  RigidTransform BaseAt(const double* e) const;
  RigidTransform ToolAt(const double* e) const;
  /// The robot with its base and tool at estimate e (its link values stay nominal: LinkValues).
  RobotModel RobotAt(const double* e) const;

  /// Reading h (m) for configuration i (on its plane, configs.target(i)) at `point`, and (if
  /// jacobian_row is not null) the num_parameters() entries of ∂h/∂e: the columns of other
  /// planes' terms are zero. Returns n·b (the cosine of the beam's incidence, signed) so callers
  /// can classify the reading; h is finite unless n·b == 0. With ranger terms the reading is
  /// r = (1 + s)·h_geo + o: the geometric columns are scaled by (1 + s), ∂r/∂o = 1 and
  /// ∂r/∂s = h_geo.
  double Evaluate(const ModelPoint& point, const TargetedConfigurations& configs, int i, double* h,
                  double* jacobian_row) const;

  /// Templated reading for autodiff (tests): e has num_parameters() entries; the beam is aimed
  /// at plane `plane`.
  template <typename T>
  T Distance(const T* e, const double* q, int plane = 0) const {
    std::vector<T> values(robot_->num_values());
    for (int k = 0; k < robot_->num_values(); ++k) values[k] = T(robot_->nominal_values()[k]);
    for (int k = 0; k < parameters_.num_robot(); ++k) values[parameters_.robot_values[k]] += e[k];
    Pose<T> pose;
    if (parameters_.EstimatesFrames()) {
      T d[2][6];
      for (int f = 0; f < 2; ++f) FrameTermValues(e, f, d[f]);
      pose = ForwardKinematics<T>(*robot_, values.data(), q,
                                  MovedTransformMatrix<T>(robot_->base(), d[0]),
                                  MovedTransformMatrix<T>(robot_->tool(), d[1]));
    } else {
      pose = ForwardKinematics<T>(*robot_, values.data(), q);
    }
    Eigen::Matrix<T, 3, 1> n = nominal_planes_[plane].normal.cast<T>();
    T f = T(nominal_planes_[plane].offset);
    const PlaneColumns& c = parameters_.plane_columns[plane];
    if (c.EstimatesNormal())
      n = charts_[plane].Normal<T>(c.u[0] >= 0 ? e[c.u[0]] : T(0), c.u[1] >= 0 ? e[c.u[1]] : T(0));
    if (c.f >= 0) f += e[c.f];
    const T h = LaserDistance<T>(pose.p_BT, pose.R_BT.col(2), n, f);
    const T o = parameters_.ranger_offset_index >= 0 ? e[parameters_.ranger_offset_index] : T(0);
    const T s = parameters_.ranger_scale_index >= 0 ? e[parameters_.ranger_scale_index] : T(0);
    return (T(1) + s) * h + o;
  }

  /// Applies the ranger terms of `point` to geometric readings h[0..m) and, if J is not null,
  /// to their Jacobian (column-major, leading dimension m): see Evaluate. A no-op for a
  /// perfect ranger that is not estimated (the paper's model keeps its bits).
  void ApplyRanger(const ModelPoint& point, int m, double* h, double* J) const;
  /// Whether ApplyRanger changes J at `point`: a ranger term is estimated (its column is set)
  /// or the ranger's scale is not zero (every column is multiplied by 1 + scale). An offset
  /// alone moves the readings only.
  bool RangerChangesJacobian(const ModelPoint& point) const {
    return parameters_.ranger_offset_index >= 0 || parameters_.ranger_scale_index >= 0 ||
           point.ranger_scale != 0;
  }

 private:
  // Frame f's six terms (x, y, z, roll, pitch, yaw) at estimate e: 0 where not estimated.
  template <typename T>
  void FrameTermValues(const T* e, int f, T* d) const {
    for (int k = 0; k < 6; ++k) {
      const int c = parameters_.frame_columns[f][k];
      d[k] = c >= 0 ? e[c] : T(0);
    }
  }
  // Frame f's transform at estimate e (0 base, 1 tool) and its rotation axes in the parent frame.
  RigidTransform FrameAt(int f, const double* e, Eigen::Matrix3d* axes) const;
  // The frame terms' entries of one configuration's row (before the ranger's scale): the file
  // comment's formulas, inv = -1/(n·b).
  void FrameColumns(const ModelPoint& point, const Pose<double>& pose, const Eigen::Vector3d& p_hit,
                    const Eigen::Vector3d& n, double inv, double* row) const;

  const RobotModel* robot_;
  PlaneSet nominal_planes_;
  ParameterSet parameters_;
  std::vector<NormalChart> charts_;
};

}  // namespace lrcal
