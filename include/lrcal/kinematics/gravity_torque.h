// Gravity's load on each joint of a serial arm: what bends a compliant joint (joint compliance,
// measurement/environment_measurement.h).
//
// A mass model is a list of point masses, each fixed to one link's frame (robot_model.h: frame k
// is carried by joint k) or to the tool frame (a payload). At joint values q and gravity g (the
// acceleration of free fall in the base frame B, m/s²: (0, 0, −9.81) upright on the ground, 0 on
// orbit), the generalised gravity force on joint j is
//   revolute:  τ_j = z_{j−1} · Σ_{masses beyond j} (p_m − o_{j−1}) × (m g)   (N·m)
//   prismatic: τ_j = z_{j−1} · Σ_{masses beyond j} m g                        (N)
// where z_{j−1} and o_{j−1} are joint j's axis and a point on it (frame j−1, in B) and p_m is the
// mass's centre in B. It equals −∂V/∂q_j for the potential V = −Σ m g·p_m (tested so): the
// torque gravity exerts on the outboard bodies about the joint's positive axis.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "lrcal/kinematics/robot_model.h"

namespace lrcal {

/// A point mass on the arm: `mass` (kg) at `com` (m) in the frame of link `link` (1..N: link
/// k's frame, carried by joint k), or of the tool (`link` = N + 1: a payload).
struct PointMass {
  int link = 1;
  double mass = 0;                                ///< kg
  Eigen::Vector3d com = Eigen::Vector3d::Zero();  ///< m, in the link's (or tool's) frame
};

/// The arm's masses (a robot file's `masses:`). Empty: no gravity load anywhere.
struct MassModel {
  std::vector<PointMass> masses;
  bool empty() const { return masses.empty(); }
  /// Throws InputError (where = `source`) for a link outside 1..num_links + 1, a mass that is
  /// not positive and finite, or a centre that is not finite.
  void Validate(int num_links, const std::string& source) const;
};

/// The generalised gravity forces τ (N values: N·m for a revolute joint, N for a prismatic one)
/// at joint values `q` with gravity `gravity` (m/s², base frame), on the arm with link values
/// `link_values` (5N, SI). Zero for every joint when `masses` is empty or gravity is zero.
Eigen::VectorXd GravityTorques(const RobotModel& robot, const double* link_values,
                               const MassModel& masses, const double* q,
                               const Eigen::Vector3d& gravity);

}  // namespace lrcal
