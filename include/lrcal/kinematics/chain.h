// The fast forward kinematics of the hot paths: a chain prepared once per set of link values
// (per-link trig), then evaluated per configuration without trig and without allocation. The
// reference implementation, written independently, is forward_kinematics.h; tests compare them.
#pragma once

#include <Eigen/Core>

#include "lrcal/kinematics/configuration_set.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/kinematics/robot_model.h"

namespace lrcal {

/// Longest chain the fixed-size fast path handles.
inline constexpr int kMaxLinks = 16;

/// A chain evaluated at one set of link values: per-link sines and cosines, ready for many
/// configurations (the joint angles enter through the addition theorem, no trig per configuration).
struct ChainPoint {
  struct LinkTrig {
    double cos_theta0, sin_theta0, cos_alpha, sin_alpha, cos_beta, sin_beta, a, d;
    bool prismatic;
  };
  int num_links = 0;
  LinkTrig links[kMaxLinks];
  /// The robot's base and tool transforms; `has_base`/`has_tool` false when they are the
  /// identity (then they cost nothing, and the bits are those of a chain without them).
  RigidTransform base, tool;
  bool has_base = false, has_tool = false;
};

/// Frames of the chain at one configuration (in the base frame B, after the base transform),
/// kept for the Jacobian; `tool` is the tool pose, after the tool transform.
struct ChainFrames {
  Eigen::Vector3d o_prev[kMaxLinks], z_prev[kMaxLinks], x_common[kMaxLinks], y_twist[kMaxLinks],
      o[kMaxLinks];
  Pose<double> tool;
};

/// Prepares a ChainPoint from link values (5N, SI).
void PrepareChainPoint(const RobotModel& robot, const double* link_values, ChainPoint* point);

/// Forward kinematics from a prepared point (fast path); fills every frame if `frames` given.
Pose<double> ToolPose(const ChainPoint& point, const ConfigurationSet& configs, int i,
                      ChainFrames* frames = nullptr);

/// The tool's rotation axis (base frame) per unit change of link value `index` (0 ≤ index < 5N),
/// from the frames of one configuration: the joint axis z_{i−1} for θ_i, the common normal x_i
/// for α_i, the twist axis for β_i; zero for the lengths d_i and a_i.
Eigen::Vector3d LinkValueRotation(const ChainFrames& f, int index);

/// The motion ∂P/∂v (base frame) of a point P (base frame) rigidly attached to the tool per unit
/// change of link value `index`: a rotation about the link's axis through its origin, or a shift
/// along it.
Eigen::Vector3d LinkValuePointMotion(const ChainFrames& f, int index, const Eigen::Vector3d& P);

/// Geometric Jacobian (6×N, rows: linear velocity of the tool origin in B, then angular
/// velocity in B) at the given link values. Used for singularity checks.
Eigen::Matrix<double, 6, Eigen::Dynamic> GeometricJacobian(const RobotModel& model,
                                                           const Eigen::VectorXd& link_values,
                                                           const double* q);

/// The same from the frames of one configuration that ToolPose filled (no trig, no allocation
/// once J has its 6×N).
void GeometricJacobian(const RobotModel& model, const ChainFrames& frames,
                       Eigen::Matrix<double, 6, Eigen::Dynamic>* J);

}  // namespace lrcal
