// Robot files: a robot model and the measurement set-up that travels with it.
//
// A robot YAML file (format: docs/FILE_FORMATS.md) gives the links of the chain (kinematics
// layer) and, optionally, the plane the ranger measures and the ranger's limits (measurement
// layer). The robot model itself knows nothing of planes or files; this reader splits the file
// into the two.
#pragma once

#include <optional>
#include <string>

#include "lrcal/kinematics/robot_model.h"
#include "lrcal/measurement/plane.h"

namespace lrcal {

/// What a robot file holds.
struct RobotFile {
  RobotModel robot;
  std::optional<Plane> plane;  ///< the plane of the file's measurement set-up, if it gives one
  RangerSpec ranger;           ///< the ranger's limits (defaults unless the file gives them)
  std::string path;            ///< where it was read from
  /// The true ranger's errors (true_errors.ranger_offset_mm, ranger_scale_ppm): it reads
  /// (1 + ranger_scale)·h + ranger_offset (m) for a true distance h. For simulation.
  double ranger_offset = 0;
  double ranger_scale = 0;
};

/// Reads a robot YAML file. Throws InputError naming the file, line and key on any problem.
RobotFile LoadRobotFile(const std::string& path);

/// Resolves a robot argument: a path to a YAML file, or a short name of a shipped robot
/// ("paper" → studies/robots/paper.yaml in the working directory or in lrcal's data folder,
/// core/data_dir.h). A relative path is taken relative to `relative_to` when given (a study
/// file's folder), else to the working directory. Throws InputError for an unknown name.
std::string ResolveRobotPath(const std::string& name_or_path, const std::string& relative_to = "");

}  // namespace lrcal
