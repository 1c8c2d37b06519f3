// The real arm and ranger a simulation reads from: the errors of the link values and of the
// ranger, as a robot file's `true_errors:` section gives them. Kept apart from RobotModel, which
// is what a calibration knows (the nominal values): only simulations and studies use a Truth.
#pragma once

#include <Eigen/Core>

#include "lrcal/kinematics/robot_model.h"

namespace lrcal {

struct Truth {
  /// Errors of the robot's 5N link values (SI; zero where the file gives none). Empty: none.
  Eigen::VectorXd link_errors;
  /// The true ranger reads (1 + ranger_scale)·h + ranger_offset (m) for a true distance h.
  double ranger_offset = 0;  ///< m
  double ranger_scale = 0;   ///< dimensionless

  /// The true link values of `robot`: nominal + link_errors (the nominal values when empty).
  /// Throws InputError (`true_errors`) when link_errors has another length than the robot's.
  Eigen::VectorXd LinkValues(const RobotModel& robot) const;
  /// link_errors, or zeros of `robot`'s length when empty.
  Eigen::VectorXd LinkErrors(const RobotModel& robot) const;
  /// The true arm as a model: `robot` with LinkValues(robot) as its nominal values (its base,
  /// tool, joint ranges and parameter marks kept). What a kind built on the true geometry (a
  /// tracker's truth, point_measurement.h) needs.
  RobotModel TrueRobot(const RobotModel& robot) const;
};

}  // namespace lrcal
