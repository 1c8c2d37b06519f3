// Scanner data files: a line scanner's readings (scanner_measurement.h), one row per beam of
// each configuration, as CSV, read for a robot, its planes and the scanner's beam count and
// written by `lrcal simulate --sensor scanner`.
//
// Columns (docs/FILE_FORMATS.md): q1..qN (rad), `plane` (as the ranger's files name it; required
// with several planes), `beam` (1 to B, the beam's number in the fan), `h` (m, the beam's
// reading), and an optional `readings` (how many readings the row's h averages; 1 if absent).
// The rows of one configuration are consecutive, with the same joint values and plane, one per
// beam in any order and the same `readings` on each.
#pragma once

#include <string>

#include "lrcal/kinematics/robot_model.h"
#include "lrcal/measurement/measurement_kind.h"
#include "lrcal/measurement/plane.h"

namespace lrcal {

struct CsvTable;  // csv.h

/// The scanner data at `path` for a fan of `num_beams` beams on `planes`, joint ranges checked
/// against `robot`: configurations tagged by plane, B values each (beam order), their `readings`
/// as repetitions. Throws InputError naming the file, line and column for a beam outside 1..B or
/// given twice in a configuration, a configuration without every beam, rows of one
/// configuration with different `readings`, a non-finite h or joint value, or a plane that is
/// not one of `planes`.
MeasuredValues ReadScannerData(const std::string& path, const RobotModel& robot,
                               const PlaneSet& planes, int num_beams);
/// The same from a table already read (ReadRobotCsv; a mixed file's rows of one kind).
MeasuredValues ScannerDataFromTable(const CsvTable& t, const RobotModel& robot,
                                    const PlaneSet& planes, int num_beams);

/// Writes `data` (B values per configuration) at full precision: q1..qN, plane (1-based), beam,
/// h, readings. Written whole or not at all (StorageError naming the file).
void WriteScannerData(const std::string& path, const MeasuredValues& data, int num_beams);

}  // namespace lrcal
