// Joint offsets: the simplest form of a calibration, the one most controllers take. The calibrated
// arm at joint values q is approximated by the nominal model at q + δ, one offset δ_j per joint;
// what that simplification costs is measured over the workspace.
#pragma once

#include <Eigen/Core>

#include "lrcal/kinematics/configuration_set.h"
#include "lrcal/kinematics/robot_model.h"

namespace lrcal {

/// The offsets that best approximate a calibrated model, and their error.
struct JointOffsetFit {
  /// δ per joint (rad, or m for a prismatic joint): the calibrated arm at q is nominal(q + δ).
  Eigen::VectorXd offsets;
  /// Over the configurations of the fit, the tool position's distance (m) between the calibrated
  /// model and nominal(q + δ): RMS and worst; and the same for the nominal model alone, nominal(q).
  double rms = 0, worst = 0, nominal_rms = 0, nominal_worst = 0;
  /// The tool orientation's angle (rad) between the calibrated model and nominal(q + δ): RMS,
  /// worst.
  double orientation_rms = 0, orientation_worst = 0;
  int iterations = 0;
};

/// The length (m) that weighs a tool orientation error against a position error in the fit: an
/// angle φ counts as a position error of kOffsetFitLength·φ (a point 10 cm from the tool origin).
inline constexpr double kOffsetFitLength = 0.1;

/// Gauss–Newton on δ (from 0) minimising Σ_i |p_cal − p_nom|² + kOffsetFitLength²·|φ_i|², the
/// tool positions of `calibrated` at q_i and of `nominal` at q_i + δ (their nominal values; the
/// same number of joints) and the rotation vector φ_i between their tool orientations, over
/// `configs`, until the step is below 1e-15 (rad or m) or after 50 steps. The orientation makes
/// every offset count, also that of a joint whose axis runs through the tool point. The offset
/// of a joint is a joint motion, so its column of the Jacobian is the geometric Jacobian's
/// (chain.h). Throws std::invalid_argument for robots with different numbers of joints or no
/// configurations.
JointOffsetFit FitJointOffsets(const RobotModel& nominal, const RobotModel& calibrated,
                               const ConfigurationSet& configs);

}  // namespace lrcal
