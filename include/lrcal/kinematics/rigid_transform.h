// A fixed rigid transform between two frames: the robot's base transform (the D-H chain's
// frame 0 in the robot's base frame) and its tool transform (the tool frame in the chain's last
// frame). Not identified: they come from the robot file or the URDF.
#pragma once

#include <Eigen/Core>
#include <string>

namespace lrcal {

/// x_parent = rotation · x_child + translation (m). `rotation` is orthonormal with det +1.
struct RigidTransform {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  /// From a translation (m) and URDF roll-pitch-yaw angles (rad): rotation = Rz(yaw)·Ry(pitch)·
  /// Rx(roll), fixed axes x, y, z of the parent in that order (REP 103, URDF `<origin rpy>`).
  static RigidTransform FromXyzRpy(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy);
  /// The roll-pitch-yaw angles (rad) of `rotation`, pitch in [-π/2, π/2]. At pitch ±π/2 (gimbal
  /// lock) only roll ∓ yaw is defined: yaw is then 0. FromXyzRpy(translation, Rpy()) gives the
  /// same rotation to about 1e-15 / cos(pitch) (the angles' rounding near gimbal lock), and to a
  /// few ulps at it.
  Eigen::Vector3d Rpy() const;

  /// True if exactly the identity (the chain needs no extra work for it).
  bool IsIdentity() const;
  /// Composition: (*this · other)(x) = this(other(x)).
  RigidTransform operator*(const RigidTransform& other) const;
  RigidTransform Inverse() const;

  /// Checks that `rotation` is a rotation (orthonormal within 1e-9, det +1); throws InputError
  /// at `where` if not.
  void Validate(const std::string& where) const;
};

}  // namespace lrcal
