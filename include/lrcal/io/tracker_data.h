// A tracker's measurement files: the point kind's positions and the pose kind's positions and
// orientations (point_measurement.h, pose_measurement.h) as CSV, read for a given kind and
// written by `lrcal simulate --sensor point|pose`.
//
// Columns (docs/FILE_FORMATS.md): q1..qN (rad), an optional `target` (1 to the number of targets;
// required with several), x, y, z (m, the target in the instrument's frame), for a pose qx, qy,
// qz, qw (the target's axes in the instrument's frame as a unit quaternion, Eigen's and ROS's
// order), and an optional `readings` (how many readings the row's values average; 1 if absent).
// Each row is one measured value of its configuration; rows are never merged.
#pragma once

#include <Eigen/Core>
#include <string>

#include "lrcal/measurement/measurement_kind.h"
#include "lrcal/measurement/point_measurement.h"
#include "lrcal/measurement/pose_measurement.h"

namespace lrcal {

struct CsvTable;  // csv.h

/// The measured values of `kind` in the file at `path`, joint ranges checked against the kind's
/// robot. A pose's quaternion becomes its three orientation rows (PoseMeasurement::
/// OrientationValue). Throws InputError naming the file, line and column for a missing column,
/// a cell that is not a finite number, a target out of range, a quaternion whose norm is not 1
/// within 1e-6, or a `readings` cell that is not a whole number from 1 to 1,000,000.
MeasuredValues ReadTrackerMeasurements(const std::string& path, const PointMeasurement& kind);
/// The same from a table already read (ReadRobotCsv; a mixed file's rows of one kind, csv.h
/// SplitBySensor): errors name the table's file and lines.
MeasuredValues TrackerMeasurementsFromTable(const CsvTable& t, const PointMeasurement& kind);

/// The rotation of a measured unit quaternion `xyzw` (qx, qy, qz, qw). Throws InputError at
/// `where` unless its norm is 1 within 1e-6. What every reader of measured orientations shares
/// (tracker files, compensation targets, Python's arrays).
Eigen::Matrix3d UnitQuaternionRotation(const double* xyzw, const std::string& where);

/// A pose's three orientation rows (PoseMeasurement::OrientationValue) at configuration i of
/// `configs` from its measured unit quaternion `xyzw` (qx, qy, qz, qw). Throws InputError at
/// `where` unless the quaternion's norm is 1 within 1e-6. What the file reader and Python's
/// identify_tracker share.
Eigen::Vector3d QuaternionOrientationValue(const PoseMeasurement& pose,
                                           const TargetedConfigurations& configs, int i,
                                           const double* xyzw, const std::string& where);

/// Writes `data` (values of `kind`, as SimulateMeasurements makes them) at full precision, the
/// `target` column when the kind has several targets, each row's repetitions as `readings`.
/// Written whole or not at all (StorageError naming the file on a write failure).
void WriteTrackerMeasurements(const std::string& path, const PointMeasurement& kind,
                              const MeasuredValues& data);

}  // namespace lrcal
