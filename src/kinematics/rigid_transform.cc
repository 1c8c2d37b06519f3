#include "lrcal/kinematics/rigid_transform.h"

#include <Eigen/Geometry>
#include <cmath>

#include "lrcal/core/error.h"

namespace lrcal {

RigidTransform RigidTransform::FromXyzRpy(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy) {
  RigidTransform t;
  t.rotation = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  t.translation = xyz;
  return t;
}

Eigen::Vector3d RigidTransform::Rpy() const {
  const Eigen::Matrix3d& r = rotation;
  const double cos_pitch = std::hypot(r(0, 0), r(1, 0));
  const double pitch = std::atan2(-r(2, 0), cos_pitch);
  if (cos_pitch < 1e-12) {  // gimbal lock: R = Rz(yaw)·Ry(±π/2)·Rx(roll) depends on roll ∓ yaw
    const double roll = std::atan2(-r(1, 2), r(1, 1));
    return {roll, pitch, 0.0};
  }
  return {std::atan2(r(2, 1), r(2, 2)), pitch, std::atan2(r(1, 0), r(0, 0))};
}

bool RigidTransform::IsIdentity() const {
  return rotation == Eigen::Matrix3d::Identity() && translation == Eigen::Vector3d::Zero();
}

RigidTransform RigidTransform::operator*(const RigidTransform& other) const {
  RigidTransform t;
  t.rotation = rotation * other.rotation;
  t.translation = rotation * other.translation + translation;
  return t;
}

RigidTransform RigidTransform::Inverse() const {
  RigidTransform t;
  t.rotation = rotation.transpose();
  t.translation = -(t.rotation * translation);
  return t;
}

void RigidTransform::Validate(const std::string& where) const {
  if (!rotation.allFinite() || !translation.allFinite())
    throw InputError(where, "expected finite numbers");
  const double orthogonality =
      (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthogonality > 1e-9 || rotation.determinant() < 0)
    throw InputError(where, "expected a rotation (orthonormal, determinant +1)");
}

}  // namespace lrcal
