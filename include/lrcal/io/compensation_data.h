// The files of `lrcal compensate` (docs/FILE_FORMATS.md "Compensation targets"): the commands a
// controller planned on the nominal model, with the tool poses they were meant to reach, in; the
// compensated commands with what remains, out.
#pragma once

#include <string>
#include <vector>

#include "lrcal/kinematics/compensation.h"
#include "lrcal/kinematics/configuration_set.h"
#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/kinematics/robot_model.h"

namespace lrcal {

struct CompensationTargets {
  /// The planned commands (joint columns q1…qN or `robot`'s joint names; rad, or m).
  ConfigurationSet plans;
  /// The tool poses to reach (base frame; m), one per plan, when the file gives them (x, y, z and
  /// optionally qx, qy, qz, qw); empty otherwise (the nominal model's poses at the plans are then
  /// the targets).
  std::vector<Pose<double>> poses;
  /// The file gives orientations (qx, qy, qz, qw), not only positions.
  bool orientation = false;
};

/// Reads the targets at `path` for `robot` (whose joint names a file may use). InputError naming
/// the file, line and column for a joint outside its range, a non-finite cell, x, y, z not all
/// given, a quaternion without a position or with a zero norm.
CompensationTargets ReadCompensationTargets(const std::string& path, const RobotModel& robot);

/// The compensated commands as CSV: q1…qN, then position_error_mm, orientation_error_mrad,
/// converged (1/0), within_limits (1/0), iterations; full precision.
std::string CompensationCsvText(const std::vector<Compensation>& results, int num_joints);
/// CompensationCsvText written to `path` whole or not at all (StorageError naming it).
void WriteCompensation(const std::string& path, const std::vector<Compensation>& results,
                       int num_joints);

}  // namespace lrcal
