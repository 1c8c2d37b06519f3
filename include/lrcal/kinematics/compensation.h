// Compensation: the joint commands that bring a calibrated arm's tool where a plan on the nominal
// model meant it to be. A controller that runs the nominal kinematics keeps its plans; lrcal
// corrects each command so that the calibrated model reaches the planned tool pose.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/kinematics/robot_model.h"

namespace lrcal {

/// What Compensate found for one target.
struct Compensation {
  std::vector<double> q;         ///< the compensated command (rad, or m), one per joint
  double position_error = 0;     ///< m, |p(q) − p_target| on the calibrated model
  double orientation_error = 0;  ///< rad, the angle of R(q)·R_targetᵀ (0 when not asked)
  bool converged = false;        ///< both errors below kCompensationTolerance
  bool within_limits = false;    ///< every joint within its range (Link::q_min, q_max)
  int iterations = 0;
};

/// The errors Compensate stops at (m for the position, rad for the orientation).
inline constexpr double kCompensationTolerance = 1e-12;

/// Damped least squares on the joints from `start` (the nominal plan's command, N values) until
/// the tool of `calibrated` (its nominal values: a calibrated robot file's estimates) is at
/// `target` (p_BT, and R_BT when `orientation`; base frame): steps Δq = Jᵀ(JJᵀ + λ²I)⁻¹·e on the
/// position error and the rotation vector of R_target·Rᵀ, J the geometric Jacobian (chain.h), λ
/// halved after a step that reduces the error and raised tenfold (the step retried) after one that
/// does not, so the command moves by the least joint motion that reaches the target and stays
/// defined near singular postures. Stops at kCompensationTolerance or after 100 steps. Revolute
/// joints are then brought into their ranges by whole turns where they can (within_limits says
/// whether every joint is in range).
Compensation Compensate(const RobotModel& calibrated, const Pose<double>& target,
                        const double* start, bool orientation = true);

}  // namespace lrcal
