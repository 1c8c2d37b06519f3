// The calibrated model as a robot file: its record (data provenance, σ, estimate, covariance),
// writing it, and reading back which parameters a record estimated.
#pragma once

#include <string>

#include "lrcal/identification/identification.h"
#include "lrcal/identification/total_accuracy.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/measurement/point_measurement.h"

namespace lrcal {

/// Where a calibration's readings came from, for its record: a measurement file (its bytes
/// hashed) or readings given as arrays (Python), described and hashed by the caller.
struct DataSource {
  std::string name;   ///< the file as given, or what the readings were ("Python arrays: ...")
  std::string fnv1a;  ///< FNV-1a (hex) of the file's bytes, or of the arrays'
  /// A measurement file: `path` and the hash of its bytes (of nothing if it cannot be read).
  static DataSource File(const std::string& path);
};

/// The record of an identification of `data` (hashed, dated, with lrcal's version): σ and the
/// covariance are ChooseSigma's (the given σ unless the χ² check rejects it, else σ̂; the
/// covariance empty when undefined), with the terms `held` at nominal (total_accuracy.h).
CalibrationRecord MakeCalibrationRecord(const DataSource& data, const IdentificationSummary& s,
                                        const IdentificationOptions& options,
                                        const UnestimatedTerms& held = {});

/// The calibrated model of an identification (its solved model, SolvedModel) written as a robot
/// file at `path` with its record (and the terms `held` at nominal); every command takes it as a
/// robot. Throws StorageError.
void WriteCalibratedRobot(const std::string& path, const DataSource& data, const RobotFile& rig,
                          const MeasurementModel& model, const IdentificationSummary& s,
                          const IdentificationOptions& options, const UnestimatedTerms& held = {});

/// A tracker's or a socket campaign's fit (identify --sensor point|pose|socket: its summary `s`
/// of `values` on `kind`, a PointMeasurement, PoseMeasurement or SocketMeasurement) as a
/// calibrated robot file at `path`: `rig` with the estimated link values as its nominal values,
/// its planes and ranger limits if it has them, and a record of the link terms alone with their
/// marginal covariance (the instrument's frame, the targets and the sockets belong to that
/// campaign's set-up, not to the arm; they stay in the fit's output). The link terms the fit held
/// at nominal (fixed, or confounded with the instrument's frame or a target: d1 with the tracker's
/// height) are the record's held terms, with the rig's tolerances or the defaults and their effect
/// on the estimate, so that the file's stated total accuracy includes them. Throws StorageError.
void WriteTrackerCalibratedRobot(const std::string& path, const DataSource& data,
                                 const RobotFile& rig, const MeasurementKind& kind,
                                 const MeasuredValues& values, const IdentificationSummary& s,
                                 const IdentificationOptions& options);

/// The same calibrated robot in memory (what loading that file gives, for prediction: its robot
/// at the estimated link values and its calibration record; no truth, no tolerances).
RobotFile TrackerCalibratedRobot(const DataSource& data, const RobotFile& rig,
                                 const MeasurementKind& kind, const MeasuredValues& values,
                                 const IdentificationSummary& s,
                                 const IdentificationOptions& options);

/// The parameter set the calibration record `r` names: plane and ranger terms from their names,
/// robot parameters not named are fixed, in MakeParameterSet's order. `source` names the record in
/// errors.
ParameterSet RecordParameterSet(const RobotModel& robot, const CalibrationRecord& r, int num_planes,
                                const std::string& source);

/// The record's covariance in the order of `ps` (RecordParameterSet of the same record). Throws
/// InputError naming `source` when the record names a parameter `ps` lacks or misses one.
Eigen::MatrixXd RecordCovariance(const CalibrationRecord& r, const ParameterSet& ps,
                                 const std::string& source);

/// The total predicted accuracy at `poses` of the calibrated robot file `rig` (its nominal values
/// are the estimates; its record's covariance, reordered to the parameter set it names on
/// `planes`, and its held terms). Throws SettingError (`robot`) when the file has no record with a
/// covariance, InputError naming the record when a held term is not a term of the set-up.
AccuracyPrediction PredictCalibratedAccuracy(const RobotFile& rig, const PlaneSet& planes,
                                             const ConfigurationSet& poses);

}  // namespace lrcal
