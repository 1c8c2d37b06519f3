// Contact data files: the configurations in which the tool point touched a plane
// (contact_measurement.h), as CSV, read for a robot and its planes and written by `lrcal
// simulate --sensor contact`.
//
// Columns (docs/FILE_FORMATS.md): q1..qN (rad), `plane` (which plane, as the ranger's files name
// it: a 1-based number or a plane's name; required with several planes), an optional `flush` (1
// when the tool's z axis was square to the plane, 0 when only the point touched; one file holds
// one of the two), and an optional `readings` (how many contacts the row's joint values average;
// 1 if absent). Nothing is read: each row's measured values are zeros.
#pragma once

#include <string>

#include "lrcal/kinematics/robot_model.h"
#include "lrcal/measurement/measurement_kind.h"
#include "lrcal/measurement/plane.h"

namespace lrcal {

struct CsvTable;  // csv.h

struct ContactData {
  /// Configurations tagged by plane, their zero values (one per row, three when flush) and
  /// their `readings` as repetitions.
  MeasuredValues values;
  /// Every row a flush contact (the file's `flush` column all 1).
  bool flush = false;
};

/// The contact data at `path` on `planes`, joint ranges checked against `robot`; without a
/// `flush` column, `flush_default` says what the rows are. Throws InputError naming the file,
/// line and column for a plane that is not one of `planes`, a `flush` cell other than 0 or 1 or
/// one that differs from the first row's, a joint cell that is not a finite number, a
/// `readings` cell that is not a whole number from 1 to 1,000,000.
ContactData ReadContactData(const std::string& path, const RobotModel& robot,
                            const PlaneSet& planes, bool flush_default);
/// The same from a table already read (ReadRobotCsv; a mixed file's rows of one kind).
ContactData ContactDataFromTable(const CsvTable& t, const RobotModel& robot, const PlaneSet& planes,
                                 bool flush_default);

/// Writes `data` at full precision: q1..qN, plane (1-based), flush, readings. Written whole or
/// not at all (StorageError naming the file).
void WriteContactData(const std::string& path, const MeasuredValues& data, bool flush);

}  // namespace lrcal
