// CSV files of configurations and measurements.
//
// Configurations: header `q1,...,qN` (rad, or m for prismatic joints), one configuration a row.
// Measurements: the same columns plus `h` (m), optionally `repetition`; rows with the same q are
// readings of one configuration, averaged (identification.h). Other columns, of any type, are
// ignored, unless their names look like joints of another robot (q<k> with k > N: an error).
// Read as written by spreadsheets and loggers: a UTF-8 byte-order mark, CRLF, LF or CR-only line
// endings, double-quoted headers and values ("" inside quotes is a quote), blank lines and '#'
// comment lines. A NUL byte, a repeated column name or a ragged row is an error.
// Every error names the file, the line and the column, and says what was expected.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "lrcal/core/strings.h"  // CellExcerpt
#include "lrcal/identification/identification.h"
#include "lrcal/measurement/averaging.h"
#include "lrcal/measurement/measurement_model.h"

namespace lrcal {

/// A CSV file as text: the header and the cells of every data row.
struct CsvTable {
  std::string path;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<int> lines;  ///< 1-based line of each row
  /// The joints' column names when they are not q1..qN (a robot's own joint names: robot_data.h
  /// ReadRobotCsv); empty: q1..qN.
  std::vector<std::string> joint_columns{};
  /// Index of a column, or -1.
  int Column(const std::string& name) const;
  /// Cell (row, column) as a finite number; InputError naming file:line and the column.
  double Number(std::size_t row, int column) const;
};

/// The largest CSV file lrcal reads (bytes) and the most data rows: about 2,000,000 readings of
/// a 7-joint arm, some 4 GB in memory. `lrcal simulate` writes no more rows than this.
inline constexpr long long kMaxCsvBytes = 256LL << 20;
inline constexpr long long kMaxCsvRows = 2000000;

/// A table's rows grouped by their `sensor` column (a file mixing measurement kinds: ranger,
/// scanner, point, pose, socket, contact), each group a table of its own with the same path,
/// header and joint columns and its rows' own lines, in the order the kinds first appear.
/// InputError naming the file and line for a missing column, an empty cell or a kind lrcal does
/// not model.
std::vector<std::pair<std::string, CsvTable>> SplitBySensor(const CsvTable& t);

/// Reads a CSV file with a header line (see the file comment). InputError naming the file and
/// line for a folder, an empty file, a NUL byte, repeated column names, a ragged row, or a file
/// beyond kMaxCsvBytes or kMaxCsvRows.
CsvTable ReadCsv(const std::string& path);

/// Configurations q1..qN. An optional `plane` column says which plane each row's beam is aimed at
/// (a 1-based index or a plane's name), resolved against `planes` (the set-up's; null: one
/// unnamed plane). A plane that was not given is an error naming the line; several planes given
/// and no column is an error too: a file is never read against the wrong planes silently.
TargetedConfigurations ReadConfigurations(const std::string& path, int num_joints,
                                          const PlaneSet* planes = nullptr);
/// Configurations q1..qN of a tracker's measurement (point_measurement.h) with an optional
/// `target` column: which of the `num_targets` targets (1-based) each row's instrument sees.
/// Several targets and no column is an error, as for planes.
TargetedConfigurations ReadTargetConfigurations(const std::string& path, int num_joints,
                                                int num_targets);
/// The same from a table already read (the tracker's measurement files, tracker_data.h).
TargetedConfigurations TargetConfigurations(const CsvTable& t, int num_joints, int num_targets);
/// Arm configurations only (validation poses, which need no reading): a `plane` column, if
/// any, is not read.
ConfigurationSet ReadPoses(const std::string& path, int num_joints);
/// The same three readers from a table already read (ReadRobotCsv in robot_data.h: a robot's
/// joint names as column names).
TargetedConfigurations Configurations(const CsvTable& t, int num_joints,
                                      const PlaneSet* planes = nullptr);
ConfigurationSet Poses(const CsvTable& t, int num_joints);
MeasurementSet Measurements(const CsvTable& t, int num_joints, const RangerSpec* ranger = nullptr,
                            const PlaneSet* planes = nullptr, const Averaging& average = {});
/// Readings grouped by configuration (and plane, as ReadConfigurations). With a `ranger`, a
/// reading outside its range is an error naming the line (and suggesting the likely unit
/// mistake: readings are in metres). A configuration's readings become its value by `average`
/// (their mean unless told otherwise; GroupReadings).
MeasurementSet ReadMeasurements(const std::string& path, int num_joints,
                                const RangerSpec* ranger = nullptr,
                                const PlaneSet* planes = nullptr, const Averaging& average = {});

/// Writes `text` to `path` whole or not at all: a path that cannot be a file is an InputError
/// (CheckOutputFile), a full or failing disk a StorageError naming the file.
void WriteOutputFile(const std::string& path, const std::string& text);

/// Refuses (InputError naming `option`) an output path that cannot be a file: empty, a folder,
/// or in a folder that does not exist.
void CheckOutputFile(const std::string& path, const std::string& option);

/// Writes configurations (header q1..qN, or `joint_names` when given — a tree's joints, which
/// no q1..qN of one chain names —, and `plane` with the 1-based target when they refer to
/// several) at full precision. The file is written whole or not at all; any failure (a full
/// disk, a folder that cannot be written) is an InputError naming it.
void WriteConfigurations(const std::string& path, const TargetedConfigurations& configs,
                         const std::vector<std::string>& joint_names = {});
/// Poses (no target): the columns q1..qN, as WriteConfigurations writes them.
void WritePoses(const std::string& path, const ConfigurationSet& poses);
/// Writes single readings (header q1..qN,h,repetition): `readings` holds `repetitions` readings
/// per configuration, configuration-major. Whole or not at all, like WriteConfigurations.
void WriteReadings(const std::string& path, const TargetedConfigurations& configs,
                   const std::vector<double>& readings, int repetitions);

}  // namespace lrcal
