// Conversion of a serial chain given by its joint axes (URDF's description: each joint's axis
// line at the zero configuration) into the extended D-H chain of robot_model.h, with a base and a
// tool transform around it, such that forward kinematics is the same for every configuration.
//
// Why it is exact: both descriptions are a product of exponentials. A URDF chain's tool pose is
// exp(ξ_1 q_1) ··· exp(ξ_N q_N) · X_BT(0), ξ_i the screw of joint i (rotation about, or
// translation along, its axis line at q = 0). The D-H chain's is the same product with ξ_i the z
// axis of frame i-1 at q = 0. So the D-H frames are built with frame i-1's z axis on joint i's
// axis line (same direction: a positive q turns the same way), and the tool transform closes the
// chain on the URDF's tool pose at q = 0. What remains is rounding (tests: 1e-12).
//
// Link i (frame i-1 → frame i, frame i's z on joint i+1's axis):
//  - axes not parallel: the classic D-H link along the common normal (β = 0; θ, d, a, α are its
//    parameters);
//  - axes parallel or nearly so (angle ≤ `parallel_tolerance`): Hayati's link, d = 0 and a twist
//    β (θ, α, a, β are its parameters), as the paper does for its axes 2 and 3: the common normal
//    of nearly parallel axes is ill-defined, and d along it would be huge and ill-conditioned.
//  - the last link: its frame's origin is the tool origin (d along the last axis, a across it),
//    α = β = 0; the tool transform is then a rotation only.
// Frame 0 has its z on joint 1's axis, its origin the point of that axis nearest the base origin
// and its x the base x projected (or y if x is along the axis); the base transform places it.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "lrcal/kinematics/rigid_transform.h"
#include "lrcal/kinematics/robot_model.h"

namespace lrcal {

/// One movable joint of a chain at the zero configuration, in the robot's base frame B.
struct JointAxis {
  JointType joint = JointType::kRevolute;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();       ///< a point of the axis line (m)
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  ///< unit; positive q turns right-handed
  double q_min = -3.141592653589793;                     ///< joint range (rad, or m)
  double q_max = 3.141592653589793;
  std::string name{};  ///< the joint's name (a URDF's), carried to Link::joint_name
};

/// Angle (rad) below which consecutive axes are treated as parallel (Hayati's β link): 1°.
inline constexpr double kParallelAxesTolerance = 0.017453292519943295;

/// The D-H + β robot whose forward kinematics equals the chain's: `axes` in order from the base,
/// `tool_at_zero` the tool frame's pose in B at q = 0. Throws InputError at `source` for fewer
/// than one joint, more than 16, or a zero axis direction.
RobotModel RobotFromJointAxes(const std::string& name, const std::vector<JointAxis>& axes,
                              const RigidTransform& tool_at_zero, const std::string& source,
                              double parallel_tolerance = kParallelAxesTolerance);

}  // namespace lrcal
