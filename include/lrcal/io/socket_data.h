// Socket data files: the configurations in which the tool point sat in a socket
// (socket_measurement.h), as CSV, read for a robot and written by `lrcal simulate --sensor
// socket`.
//
// Columns (docs/FILE_FORMATS.md): q1..qN (rad), `socket` (the socket's id, a whole number ≥ 0:
// MUKCa's hole 0 and hole 1), and an optional `readings` (how many seatings the row's joint
// values average; 1 if absent). Nothing is read: every row's measured value is "the tool point
// is at its socket", three zeros.
#pragma once

#include <string>
#include <vector>

#include "lrcal/kinematics/robot_model.h"
#include "lrcal/measurement/measurement_kind.h"
#include "lrcal/measurement/socket_measurement.h"

namespace lrcal {

struct CsvTable;  // csv.h

struct SocketData {
  /// The socket ids found in the file, ascending; configuration i's tag is its socket's index
  /// here (SocketSetup::ids takes this list).
  std::vector<int> ids;
  /// Configurations with tags, three zero values each, and their `readings` as repetitions.
  MeasuredValues values;
};

/// The socket data at `path`, joint ranges checked against `robot`. Throws InputError naming the
/// file, line and column for a missing `socket` column, a socket cell that is not a whole number
/// from 0 to 1,000,000,000, a joint cell that is not a finite number, or a `readings` cell that
/// is not a whole number from 1 to 1,000,000.
SocketData ReadSocketData(const std::string& path, const RobotModel& robot);
/// The same from a table already read (ReadRobotCsv; a mixed file's rows of one kind).
SocketData SocketDataFromTable(const CsvTable& t, const RobotModel& robot);

/// Socket data from configurations and each one's socket id (≥ 0) and weight (repetitions ≥ 1):
/// ids sorted and tagged as ReadSocketData does. Throws InputError (where = `source`) for an id
/// below 0 or a count of repetitions below 1, or lengths that differ.
SocketData MakeSocketData(const ConfigurationSet& configs, const std::vector<int>& socket_ids,
                          std::vector<int> repetitions, const std::string& source);

/// Writes `data` (configurations tagged by index into `ids`) at full precision: q1..qN, socket
/// (the id), readings. Written whole or not at all (StorageError naming the file).
void WriteSocketData(const std::string& path, const std::vector<int>& ids,
                     const MeasuredValues& data);

}  // namespace lrcal
