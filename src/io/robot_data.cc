#include "lrcal/io/robot_data.h"

#include "lrcal/core/error.h"
#include "lrcal/core/strings.h"
#include "lrcal/io/csv.h"

namespace lrcal {

void CheckJointRanges(const ConfigurationSet& configs, const RobotModel& robot,
                      const std::string& path) {
  for (int i = 0; i < configs.size(); ++i)
    for (int j = 0; j < configs.num_joints(); ++j) {
      const Link& link = robot.links()[j];
      const double q = configs.q(i)[j];
      if (q >= link.q_min - 1e-9 && q <= link.q_max + 1e-9) continue;
      const bool prismatic = link.joint == JointType::kPrismatic;
      throw InputError(
          path + " configuration " + std::to_string(i + 1) + " column 'q" + std::to_string(j + 1) +
              "'",
          FormatExact(q) + " is outside the joint's range [" + FormatExact(link.q_min) + ", " +
              FormatExact(link.q_max) + "] (the robot file's q_min, q_max); joint values are in " +
              (prismatic ? "m: were they written in mm?" : "rad: were they written in degrees?"));
    }
}

TargetedConfigurations ReadRobotConfigurations(const std::string& path, const RobotModel& robot,
                                               const PlaneSet* planes) {
  TargetedConfigurations configs = ReadConfigurations(path, robot.num_links(), planes);
  CheckJointRanges(configs, robot, path);
  return configs;
}

TargetedConfigurations ReadRobotTargetConfigurations(const std::string& path,
                                                     const RobotModel& robot, int num_targets) {
  TargetedConfigurations configs = ReadTargetConfigurations(path, robot.num_links(), num_targets);
  CheckJointRanges(configs, robot, path);
  return configs;
}

ConfigurationSet ReadRobotPoses(const std::string& path, const RobotModel& robot) {
  ConfigurationSet poses = ReadPoses(path, robot.num_links());
  CheckJointRanges(poses, robot, path);
  return poses;
}

MeasurementSet ReadRobotMeasurements(const std::string& path, const RobotFile& rig,
                                     const PlaneSet* planes, const Averaging& average) {
  MeasurementSet data = ReadMeasurements(path, rig.robot.num_links(), &rig.ranger, planes, average);
  CheckJointRanges(data.configs, rig.robot, path);
  return data;
}

}  // namespace lrcal
