#include "lrcal/io/csv.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/json.h"
#include "lrcal/core/strings.h"
#include "lrcal/measurement/parameter_set.h"

namespace lrcal {

int CsvTable::Column(const std::string& name) const {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return static_cast<int>(i);
  return -1;
}

std::string FormatExact(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

CsvTable ReadCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open file");
  CsvTable t;
  t.path = path;
  std::string line;
  int number = 0;
  bool have_header = false;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos || line[0] == '#') continue;
    std::vector<std::string> cells = SplitList(line);
    if (!have_header) {
      t.header = cells;
      have_header = true;
      continue;
    }
    if (cells.size() != t.header.size())
      throw InputError(Location(path, number),
                       "expected " + std::to_string(t.header.size()) +
                           " cells (header: " + std::to_string(t.header.size()) +
                           " columns), got " + std::to_string(cells.size()));
    std::vector<double> row(cells.size());
    for (std::size_t c = 0; c < cells.size(); ++c) {
      char* end = nullptr;
      row[c] = std::strtod(cells[c].c_str(), &end);
      if (cells[c].empty() || *end != '\0' || !std::isfinite(row[c]))
        throw InputError(Location(path, number) + " column '" + t.header[c] + "'",
                         "expected a finite number, got '" + cells[c] + "'");
    }
    t.rows.push_back(std::move(row));
    t.lines.push_back(number);
  }
  if (!have_header) throw InputError(path, "empty file: expected a header line q1,...,qN");
  return t;
}

namespace {

std::vector<int> JointColumns(const CsvTable& t, int num_joints) {
  std::vector<int> cols;
  for (int j = 1; j <= num_joints; ++j) {
    int c = t.Column("q" + std::to_string(j));
    if (c < 0)
      throw InputError(Location(t.path, 1) + " column 'q" + std::to_string(j) + "'",
                       "missing; the robot has " + std::to_string(num_joints) +
                           " joints: expected columns q1..q" + std::to_string(num_joints));
    cols.push_back(c);
  }
  for (const std::string& name : t.header) {
    if (name.size() > 1 && name[0] == 'q' &&
        name.find_first_not_of("0123456789", 1) == std::string::npos &&
        std::stoi(name.substr(1)) > num_joints)
      throw InputError(Location(t.path, 1) + " column '" + name + "'",
                       "the robot has only " + std::to_string(num_joints) +
                           " joints (wrong robot or wrong file?)");
  }
  return cols;
}

}  // namespace

ConfigurationSet ReadConfigurations(const std::string& path, int num_joints) {
  CsvTable t = ReadCsv(path);
  std::vector<int> cols = JointColumns(t, num_joints);
  if (t.rows.empty()) throw InputError(path, "no configurations (only a header)");
  ConfigurationSet out(num_joints);
  std::vector<double> q(num_joints);
  for (const auto& row : t.rows) {
    for (int j = 0; j < num_joints; ++j) q[j] = row[cols[j]];
    out.Add(q);
  }
  return out;
}

MeasurementSet ReadMeasurements(const std::string& path, int num_joints) {
  CsvTable t = ReadCsv(path);
  std::vector<int> cols = JointColumns(t, num_joints);
  const int hc = t.Column("h");
  if (hc < 0)
    throw InputError(Location(path, 1) + " column 'h'", "missing: expected the reading h (m)");
  if (t.rows.empty()) throw InputError(path, "no readings (only a header)");
  // Group readings by identical q, in order of first appearance.
  std::map<std::vector<double>, int> index;
  std::vector<std::vector<double>> qs;
  std::vector<double> sums;
  std::vector<int> counts;
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    std::vector<double> q(num_joints);
    for (int j = 0; j < num_joints; ++j) q[j] = t.rows[r][cols[j]];
    const double h = t.rows[r][hc];
    if (!(h > 0))
      throw InputError(Location(path, t.lines[r]) + " column 'h'",
                       "a reading must be a positive distance in m, got " + FormatExact(h));
    auto [it, inserted] = index.emplace(q, static_cast<int>(qs.size()));
    if (inserted) {
      qs.push_back(q);
      sums.push_back(0);
      counts.push_back(0);
    }
    sums[it->second] += h;
    counts[it->second] += 1;
  }
  MeasurementSet data;
  data.configs = ConfigurationSet(num_joints);
  for (std::size_t i = 0; i < qs.size(); ++i) {
    data.configs.Add(qs[i]);
    data.mean_h.push_back(sums[i] / counts[i]);
    data.repetitions.push_back(counts[i]);
  }
  return data;
}

// The file is written whole or not at all: a failed or full disk is an error naming it.
void WriteOutputFile(const std::string& path, const std::string& text) {
  try {
    WriteFileAtomically(path, text);
  } catch (const std::runtime_error& e) {
    throw InputError(path, std::string("cannot write the output file: ") + e.what());
  }
}

void WriteConfigurations(const std::string& path, const ConfigurationSet& configs) {
  std::ostringstream out;
  for (int j = 0; j < configs.num_joints(); ++j) out << (j ? "," : "") << "q" << j + 1;
  out << "\n";
  for (int i = 0; i < configs.size(); ++i) {
    for (int j = 0; j < configs.num_joints(); ++j)
      out << (j ? "," : "") << FormatExact(configs.q(i)[j]);
    out << "\n";
  }
  WriteOutputFile(path, out.str());
}

void WriteReadings(const std::string& path, const ConfigurationSet& configs,
                   const std::vector<double>& readings, int repetitions) {
  std::ostringstream out;
  for (int j = 0; j < configs.num_joints(); ++j) out << "q" << j + 1 << ",";
  out << "h,repetition\n";
  for (int i = 0, k = 0; i < configs.size(); ++i)
    for (int r = 0; r < repetitions; ++r, ++k) {
      for (int j = 0; j < configs.num_joints(); ++j) out << FormatExact(configs.q(i)[j]) << ",";
      out << FormatExact(readings[k]) << "," << r + 1 << "\n";
    }
  WriteOutputFile(path, out.str());
}

}  // namespace lrcal
