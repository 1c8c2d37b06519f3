// Forward kinematics of a RobotModel, templated on the scalar so that Ceres' Jets run through it.
//
// This is the reference implementation, written as the plain product of the five elementary
// transforms of each link (robot_model.h). The measurement model's analytic Jacobian is checked
// against autodiff through this code, so the two are deliberately written independently.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "lrcal/kinematics/robot_model.h"

namespace lrcal {

/// Pose of the tool frame T in the base frame B: p_BT (m) and R_BT.
template <typename T>
struct Pose {
  Eigen::Matrix<T, 3, 3> R_BT = Eigen::Matrix<T, 3, 3>::Identity();
  Eigen::Matrix<T, 3, 1> p_BT = Eigen::Matrix<T, 3, 1>::Zero();
};

/// Homogeneous transform of one link: Rot(z,θ)·Trans(z,d)·Trans(x,a)·Rot(x,α)·Rot(y,β).
template <typename T>
Eigen::Matrix<T, 4, 4> LinkTransform(const T& theta, const T& d, const T& a, const T& alpha,
                                     const T& beta) {
  using std::cos;
  using std::sin;
  Eigen::Matrix<T, 4, 4> rz = Eigen::Matrix<T, 4, 4>::Identity();
  rz(0, 0) = cos(theta);
  rz(0, 1) = -sin(theta);
  rz(1, 0) = sin(theta);
  rz(1, 1) = cos(theta);
  Eigen::Matrix<T, 4, 4> tz = Eigen::Matrix<T, 4, 4>::Identity();
  tz(2, 3) = d;
  Eigen::Matrix<T, 4, 4> tx = Eigen::Matrix<T, 4, 4>::Identity();
  tx(0, 3) = a;
  Eigen::Matrix<T, 4, 4> rx = Eigen::Matrix<T, 4, 4>::Identity();
  rx(1, 1) = cos(alpha);
  rx(1, 2) = -sin(alpha);
  rx(2, 1) = sin(alpha);
  rx(2, 2) = cos(alpha);
  Eigen::Matrix<T, 4, 4> ry = Eigen::Matrix<T, 4, 4>::Identity();
  ry(0, 0) = cos(beta);
  ry(0, 2) = sin(beta);
  ry(2, 0) = -sin(beta);
  ry(2, 2) = cos(beta);
  return rz * tz * tx * rx * ry;
}

/// A link's transform with its joint at zero, from its five link values `v` (robot_model.h
/// order, SI), as a RigidTransform: what the D-H conversion and the URDF writer compose.
inline RigidTransform LinkRigidTransform(const double* v) {
  const Eigen::Matrix4d A = LinkTransform<double>(v[kTheta], v[kD], v[kA], v[kAlpha], v[kBeta]);
  RigidTransform t;
  t.rotation = A.block<3, 3>(0, 0);
  t.translation = A.block<3, 1>(0, 3);
  return t;
}

/// The homogeneous matrix of a fixed transform, in the scalar T.
template <typename T>
Eigen::Matrix<T, 4, 4> FixedTransformMatrix(const RigidTransform& t) {
  Eigen::Matrix<T, 4, 4> X = Eigen::Matrix<T, 4, 4>::Identity();
  X.template block<3, 3>(0, 0) = t.rotation.cast<T>();
  X.template block<3, 1>(0, 3) = t.translation.cast<T>();
  return X;
}

/// The homogeneous matrix of `nominal` moved by six terms d = (x, y, z, roll, pitch, yaw) (m,
/// rad): translation p0 + (x, y, z) in the parent frame, rotation R0·Rz(yaw)·Ry(pitch)·Rx(roll)
/// (about the frame's own axes, URDF's order). How an estimate moves the base and the tool
/// (measurement/parameter_set.h, FrameTerms).
template <typename T>
Eigen::Matrix<T, 4, 4> MovedTransformMatrix(const RigidTransform& nominal, const T* d) {
  using std::cos;
  using std::sin;
  Eigen::Matrix<T, 3, 3> rz = Eigen::Matrix<T, 3, 3>::Identity();
  rz(0, 0) = cos(d[5]);
  rz(0, 1) = -sin(d[5]);
  rz(1, 0) = sin(d[5]);
  rz(1, 1) = cos(d[5]);
  Eigen::Matrix<T, 3, 3> ry = Eigen::Matrix<T, 3, 3>::Identity();
  ry(0, 0) = cos(d[4]);
  ry(0, 2) = sin(d[4]);
  ry(2, 0) = -sin(d[4]);
  ry(2, 2) = cos(d[4]);
  Eigen::Matrix<T, 3, 3> rx = Eigen::Matrix<T, 3, 3>::Identity();
  rx(1, 1) = cos(d[3]);
  rx(1, 2) = -sin(d[3]);
  rx(2, 1) = sin(d[3]);
  rx(2, 2) = cos(d[3]);
  Eigen::Matrix<T, 4, 4> X = Eigen::Matrix<T, 4, 4>::Identity();
  X.template block<3, 3>(0, 0) = nominal.rotation.cast<T>() * rz * ry * rx;
  for (int c = 0; c < 3; ++c) X(c, 3) = T(nominal.translation[c]) + d[c];
  return X;
}

/// Forward kinematics: base · A_1 ··· A_N · tool (robot_model.h) with the base and tool given
/// as homogeneous matrices in the scalar T (for estimated frames; MovedTransformMatrix).
template <typename T>
Pose<T> ForwardKinematics(const RobotModel& model, const T* link_values, const double* q,
                          const Eigen::Matrix<T, 4, 4>& base, const Eigen::Matrix<T, 4, 4>& tool) {
  Eigen::Matrix<T, 4, 4> X = base;
  for (int i = 0; i < model.num_links(); ++i) {
    const T* v = link_values + kValuesPerLink * i;
    T theta = v[kTheta];
    T d = v[kD];
    if (model.links()[i].joint == JointType::kRevolute) {
      theta += T(q[i]);
    } else {
      d += T(q[i]);
    }
    X = X * LinkTransform<T>(theta, d, v[kA], v[kAlpha], v[kBeta]);
  }
  X = X * tool;
  Pose<T> pose;
  pose.R_BT = X.template block<3, 3>(0, 0);
  pose.p_BT = X.template block<3, 1>(0, 3);
  return pose;
}

/// Forward kinematics: base · A_1 ··· A_N · tool (robot_model.h). `link_values` holds the
/// robot's 5N link values (robot_model.h order, SI), `q` its N joint coordinates (rad, or m for
/// prismatic joints).
template <typename T>
Pose<T> ForwardKinematics(const RobotModel& model, const T* link_values, const double* q) {
  return ForwardKinematics<T>(model, link_values, q, FixedTransformMatrix<T>(model.base()),
                              FixedTransformMatrix<T>(model.tool()));
}

}  // namespace lrcal
