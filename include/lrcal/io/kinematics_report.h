// Tool pose, beam and laser reading per configuration, with the identification Jacobian row if
// asked: what `lrcal kinematics` prints, as text tables and as JSON.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "lrcal/core/text_table.h"
#include "lrcal/io/result_json.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/measurement/measurement_model.h"
#include "lrcal/measurement/parameter_set.h"

namespace lrcal {

struct KinematicsReport {
  Table poses{{}};                ///< one row per configuration: position (m), beam, h (m), status
  std::optional<Table> jacobian;  ///< dh/de rows, if asked
  /// One object per configuration: q, position, rotation, beam, h (null when the beam misses),
  /// status and, if asked, jacobian {parameter: dh/de}.
  ResultJson rows = ResultJson::array();
  std::string ToText() const;
};

/// The report for `parameters` on `planes` at the robot's nominal values (`true_model` false), or
/// at the simulated truth (`true_model` true: every link value at its true value and the
/// ranger's true offset and scale applied, so h is what a noise-free simulation reads), for
/// `configs`, readings classified against the ranger's limits. The Jacobian rows are taken
/// there.
KinematicsReport ReportKinematics(const RobotFile& rig, const PlaneSet& planes,
                                  const ParameterSet& parameters, bool true_model,
                                  const TargetedConfigurations& configs, bool jacobian);

}  // namespace lrcal
