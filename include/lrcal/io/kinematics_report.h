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

namespace lrcal {

struct KinematicsReport {
  Table poses{{}};                ///< one row per configuration: position (m), beam, h (m), status
  std::optional<Table> jacobian;  ///< dh/de rows, if asked
  /// One object per configuration: q, position, rotation, beam, h (null when the beam misses),
  /// status and, if asked, jacobian {parameter: dh/de}.
  ResultJson rows = ResultJson::array();
  std::string ToText() const;
};

/// The report of `model` at the robot's nominal values (`true_model` false) or at its simulated
/// true values (the robot parameters of model's set moved to their true values), for `configs`,
/// readings classified against `ranger`'s limits.
KinematicsReport ReportKinematics(const MeasurementModel& model, bool true_model,
                                  const ConfigurationSet& configs, const RangerSpec& ranger,
                                  bool jacobian);

}  // namespace lrcal
