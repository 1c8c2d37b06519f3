// The calibration report's data: everything `identify --report DIR` shows, written as
// DIR/calibration.json (SI) beside the calibrated robot file and its URDF; report.html is drawn
// from them by the report's Python part.
#pragma once

#include <cstdint>
#include <string>

#include "lrcal/core/settings.h"
#include "lrcal/identification/identification.h"
#include "lrcal/identification/measured_accuracy.h"
#include "lrcal/identification/total_accuracy.h"
#include "lrcal/io/calibration_record.h"
#include "lrcal/io/robot_file.h"

namespace lrcal {

/// What the report covers: a ranger's fit (`model` and `data`) or the fit of any other kind
/// (`kind` and `values`, with `model` and `data` null).
struct CalibrationReportInputs {
  DataSource data_source;  ///< the measurement CSV the fit used (or the arrays, from Python)
  const RobotFile* rig = nullptr;
  const MeasurementModel* model = nullptr;  ///< the model identified (before any rank fixes)
  const MeasurementSet* data = nullptr;
  const IdentificationSummary* summary = nullptr;
  IdentificationOptions options;
  /// The terms the fit held at nominal (FindUnestimatedTerms, for a usable fit): the total
  /// accuracy statement and the calibrated file's record propagate them (total_accuracy.h).
  UnestimatedTerms held{};
  /// Cross-validation folds (2 or more); 0: min(5, configurations).
  int holdout = 0;
  /// Points a tracker measured, not used in the fit (a point kind's values, as
  /// ReadTrackerMeasurements gives them for RegistrationKind): the calibrated model's error at
  /// each, its instrument registered (measured_accuracy.h), in calibration.json's
  /// `measured_points`; none when null.
  const MeasuredValues* measured = nullptr;
  PointSetup measured_setup{};
  std::string measured_file{};
  int workspace_poses = 500;         ///< poses of the accuracy map over the joint ranges
  std::uint64_t workspace_seed = 1;  ///< their seed
  /// Another kind's fit (a tracker, a scanner, contacts, sockets): the kind identified (before
  /// any rank fixes) and its values; its calibrated robot file is WriteTrackerCalibratedRobot's
  /// (the arm's link terms alone) and its cross-validation predicts every value.
  const MeasurementKind* kind = nullptr;
  const MeasuredValues* values = nullptr;
};

/// The report's folder as a setting, for errors in each front end's words (--report, report=).
const SettingSpec& ReportFolderSetting();

/// Writes dir/calibration.json and, when the solution is usable, dir/calibrated.yaml and
/// dir/calibrated.urdf (what `lrcal export` would write from it). Creates `dir`. Throws
/// SettingError (ReportFolderSetting: dir cannot be created) or StorageError. A kind's
/// calibration.json also names its `sensor`, `values_per_configuration` and `n_values`.
void WriteCalibrationReportData(const std::string& dir, const CalibrationReportInputs& in);

}  // namespace lrcal
