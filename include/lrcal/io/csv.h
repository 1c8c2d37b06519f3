// CSV files of configurations and measurements.
//
// Configurations: header `q1,...,qN` (rad, or m for prismatic joints), one configuration a row.
// Measurements: the same columns plus `h` (m), optionally `repetition`; rows with the same q are
// readings of one configuration, averaged (identification.h). Other columns are ignored only if
// their names do not look like joints (q<k> with k > N is an error: wrong robot).
// Every error names the file, the line and the column, and says what was expected.
#pragma once

#include <string>
#include <vector>

#include "lrcal/identification/identification.h"
#include "lrcal/measurement/measurement_model.h"

namespace lrcal {

struct CsvTable {
  std::string path;
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  std::vector<int> lines;  ///< 1-based line of each row
  int Column(const std::string& name) const;
};

/// Reads a CSV of numbers with a header line; '#' lines and blank lines are skipped.
CsvTable ReadCsv(const std::string& path);

ConfigurationSet ReadConfigurations(const std::string& path, int num_joints);
MeasurementSet ReadMeasurements(const std::string& path, int num_joints);

/// Writes `q1..qN` rows with 17 significant digits (exact round trip).
/// Writes configurations (header q1..qN) at full precision. The file is written whole or not at
/// all; any failure (a full disk, a folder that cannot be written) is an InputError naming it.
void WriteConfigurations(const std::string& path, const ConfigurationSet& configs);
/// Writes single readings (header q1..qN,h,repetition): `readings` holds `repetitions` readings
/// per configuration, configuration-major. Whole or not at all, like WriteConfigurations.
void WriteReadings(const std::string& path, const ConfigurationSet& configs,
                   const std::vector<double>& readings, int repetitions);

/// Formats a double with 17 significant digits.
std::string FormatExact(double v);

}  // namespace lrcal
