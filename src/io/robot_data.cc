#include "lrcal/io/robot_data.h"

#include <algorithm>

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
              "'" + (link.joint_name.empty() ? "" : " (joint '" + link.joint_name + "')"),
          FormatExact(q) + " is outside the joint's range [" + FormatExact(link.q_min) + ", " +
              FormatExact(link.q_max) + "] (the robot file's q_min, q_max); joint values are in " +
              (prismatic ? "m: were they written in mm?" : "rad: were they written in degrees?"));
    }
}

CsvTable ReadRobotCsv(const std::string& path, const RobotModel& robot) {
  CsvTable t = ReadCsv(path);
  // q1..qN are read by position, unless the joints are named so themselves (a robot YAML file's
  // coupled chain, io/urdf.h LoadRobotChains: its coupled joint's column may be left out).
  if (robot.num_links() == 0 || (t.Column("q1") >= 0 && robot.links()[0].joint_name != "q1"))
    return t;
  std::vector<std::string> names;
  for (const Link& link : robot.links()) {
    if (link.joint_name.empty()) return t;
    names.push_back(link.joint_name);
  }
  if (std::any_of(names.begin(), names.end(),
                  [&](const std::string& name) { return t.Column(name) >= 0; }))
    t.joint_columns = names;  // JointColumns names the first one missing
  return t;
}

TargetedConfigurations ReadRobotConfigurations(const std::string& path, const RobotModel& robot,
                                               const PlaneSet* planes) {
  TargetedConfigurations configs =
      Configurations(ReadRobotCsv(path, robot), robot.num_links(), planes);
  CheckJointRanges(configs, robot, path);
  return configs;
}

TargetedConfigurations ReadRobotTargetConfigurations(const std::string& path,
                                                     const RobotModel& robot, int num_targets) {
  TargetedConfigurations configs =
      TargetConfigurations(ReadRobotCsv(path, robot), robot.num_links(), num_targets);
  CheckJointRanges(configs, robot, path);
  return configs;
}

ConfigurationSet ReadRobotPoses(const std::string& path, const RobotModel& robot) {
  ConfigurationSet poses = Poses(ReadRobotCsv(path, robot), robot.num_links());
  CheckJointRanges(poses, robot, path);
  return poses;
}

MeasurementSet ReadRobotMeasurements(const std::string& path, const RobotFile& rig,
                                     const PlaneSet* planes, const Averaging& average) {
  MeasurementSet data = Measurements(ReadRobotCsv(path, rig.robot), rig.robot.num_links(),
                                     &rig.ranger, planes, average);
  CheckJointRanges(data.configs, rig.robot, path);
  return data;
}

}  // namespace lrcal
