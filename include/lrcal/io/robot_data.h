// A robot's data files: configuration and measurement CSVs (io/csv.h) read for a given robot (its
// q1..qN columns or, for a robot whose joints have names, those names),
// every joint value checked against the robot's joint range and every reading against its
// ranger's range, so that a unit mistake (degrees for rad, mm for m) is an error naming the file,
// the configuration and the joint, never a silently wrong calibration.
#pragma once

#include <string>

#include "lrcal/io/csv.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/measurement/measurement_set.h"
#include "lrcal/measurement/targeted_configurations.h"

namespace lrcal {

/// Throws InputError (file, configuration, column, the range and the likely unit mistake) for
/// the first joint value of `configs` outside `robot`'s joint range (q_min, q_max, ±1e-9).
void CheckJointRanges(const ConfigurationSet& configs, const RobotModel& robot,
                      const std::string& path);

/// A CSV file read for `robot` (io/csv.h ReadCsv): when its header has no `q1` column, the
/// robot's joints have names (a URDF's) and the header has any of them, the joints' columns are
/// those names (CsvTable::joint_columns), so a file logged with the robot's own joint names is
/// read as it is; the readers then name the first joint whose column is missing.
CsvTable ReadRobotCsv(const std::string& path, const RobotModel& robot);

/// A configurations CSV for `robot`, joint ranges checked; its optional `plane` column is
/// resolved against `planes`.
TargetedConfigurations ReadRobotConfigurations(const std::string& path, const RobotModel& robot,
                                               const PlaneSet* planes = nullptr);

/// A tracker's configurations CSV for `robot` (ReadTargetConfigurations: an optional `target`
/// column, 1 to `num_targets`), joint ranges checked.
TargetedConfigurations ReadRobotTargetConfigurations(const std::string& path,
                                                     const RobotModel& robot, int num_targets);

/// Poses for `robot` (where to state an accuracy: no beam, so a `plane` column, if any, is not
/// read), joint ranges checked.
ConfigurationSet ReadRobotPoses(const std::string& path, const RobotModel& robot);

/// A measurement CSV for `rig` (its ranger's range and its robot's joint ranges checked; its
/// `plane` column resolved against `planes`; each configuration's readings combined by `average`).
MeasurementSet ReadRobotMeasurements(const std::string& path, const RobotFile& rig,
                                     const PlaneSet* planes = nullptr,
                                     const Averaging& average = {});

}  // namespace lrcal
