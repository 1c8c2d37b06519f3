#include "lrcal/io/csv.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/json.h"
#include "lrcal/core/strings.h"
#include "lrcal/measurement/measurement_kind.h"
#include "lrcal/measurement/parameter_set.h"

namespace lrcal {

int CsvTable::Column(const std::string& name) const {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return static_cast<int>(i);
  return -1;
}

double CsvTable::Number(std::size_t row, int column) const {
  const std::string& cell = rows[row][column];
  double value = 0;
  if (!ParseDecimal(cell, &value))
    throw InputError(Location(path, lines[row]) + " column '" + header[column] + "'",
                     "expected a finite number, got '" + CellExcerpt(cell) + "'");
  return value;
}

namespace {

std::string ReadWholeFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(path, "is a directory; expected a CSV file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open file");
  const auto bytes = std::filesystem::file_size(path, ec);
  if (!ec && bytes > static_cast<std::uintmax_t>(kMaxCsvBytes))
    throw InputError(path, "is " + std::to_string(bytes >> 20) +
                               " MiB; lrcal reads CSV files of "
                               "up to " +
                               std::to_string(kMaxCsvBytes >> 20) +
                               " MiB (split the data, or average repeated readings first)");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Lines split at LF, CRLF or a lone CR; a leading UTF-8 byte-order mark is dropped.
std::vector<std::string> SplitLines(std::string text) {
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);
  std::vector<std::string> lines;
  std::string line;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n' || c == '\r') {
      lines.push_back(line);
      line.clear();
      if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
    } else {
      line += c;
    }
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// The cells of one line: comma-separated, blanks around unquoted cells trimmed, "..." quoting
// with "" for a quote inside.
std::vector<std::string> SplitCells(const std::string& line, const std::string& where) {
  std::vector<std::string> cells;
  std::string cell;
  bool quoted = false, was_quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c != '"')
        cell += c;
      else if (i + 1 < line.size() && line[i + 1] == '"')
        cell += line[++i];
      else
        quoted = false;
    } else if (c == '"' && Trim(cell).empty()) {
      quoted = was_quoted = true;
      cell.clear();
    } else if (c == ',') {
      cells.push_back(was_quoted ? cell : Trim(cell));
      cell.clear();
      was_quoted = false;
    } else {
      cell += c;
    }
  }
  if (quoted) throw InputError(where, "a quoted cell is not closed (missing \")");
  cells.push_back(was_quoted ? cell : Trim(cell));
  return cells;
}

void CheckHeader(const CsvTable& t, int line) {
  for (std::size_t a = 0; a < t.header.size(); ++a)
    for (std::size_t b = a + 1; b < t.header.size(); ++b)
      if (t.header[a] == t.header[b] && !t.header[a].empty())
        throw InputError(Location(t.path, line) + " column '" + CellExcerpt(t.header[a]) + "'",
                         "repeated: columns " + std::to_string(a + 1) + " and " +
                             std::to_string(b + 1) + " have the same name");
}

}  // namespace

std::vector<std::pair<std::string, CsvTable>> SplitBySensor(const CsvTable& t) {
  const int column = t.Column("sensor");
  if (column < 0)
    throw InputError(Location(t.path, 1) + " column 'sensor'",
                     "missing: a file of several kinds says each row's kind (" +
                         MeasurementKindNameList() + ")");
  std::vector<std::pair<std::string, CsvTable>> groups;
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    const std::string& kind = t.rows[r][static_cast<std::size_t>(column)];
    if (!IsMeasurementKindName(kind))
      throw InputError(Location(t.path, t.lines[r]) + " column 'sensor'",
                       "'" + CellExcerpt(kind) + "' is not a kind lrcal models: expected " +
                           MeasurementKindNameList());
    auto it =
        std::find_if(groups.begin(), groups.end(), [&](const auto& g) { return g.first == kind; });
    if (it == groups.end()) {
      CsvTable part;
      part.path = t.path;
      part.header = t.header;
      part.joint_columns = t.joint_columns;
      groups.emplace_back(kind, std::move(part));
      it = std::prev(groups.end());
    }
    it->second.rows.push_back(t.rows[r]);
    it->second.lines.push_back(t.lines[r]);
  }
  return groups;
}

CsvTable ReadCsv(const std::string& path) {
  const std::string text = ReadWholeFile(path);
  CsvTable t;
  t.path = path;
  const std::vector<std::string> lines = SplitLines(text);
  bool have_header = false;
  for (std::size_t n = 0; n < lines.size(); ++n) {
    const int number = static_cast<int>(n) + 1;
    const std::string& line = lines[n];
    if (line.find('\0') != std::string::npos)
      throw InputError(Location(path, number), "a NUL byte in the line: not a text CSV file");
    const std::string trimmed = Trim(line);
    if (trimmed.empty() || trimmed[0] == '#') continue;
    std::vector<std::string> cells = SplitCells(line, Location(path, number));
    if (!have_header) {
      t.header = std::move(cells);
      CheckHeader(t, number);
      have_header = true;
      continue;
    }
    if (cells.size() != t.header.size())
      throw InputError(Location(path, number),
                       "expected " + std::to_string(t.header.size()) +
                           " cells (header: " + std::to_string(t.header.size()) +
                           " columns), got " + std::to_string(cells.size()));
    if (static_cast<long long>(t.rows.size()) >= kMaxCsvRows)
      throw InputError(Location(path, number), "more than " + std::to_string(kMaxCsvRows) +
                                                   " data rows; lrcal reads at most that many");
    t.rows.push_back(std::move(cells));
    t.lines.push_back(number);
  }
  if (!have_header) throw InputError(path, "empty file: expected a header line q1,...,qN");
  return t;
}

namespace {

// True for "q<k>" with k > num_joints (also when k has more digits than any int).
bool NamesAnotherJoint(const std::string& name, int num_joints) {
  if (name.size() < 2 || name[0] != 'q' ||
      name.find_first_not_of("0123456789", 1) != std::string::npos)
    return false;
  const std::string digits = name.substr(name.find_first_not_of('0', 1) == std::string::npos
                                             ? name.size()
                                             : name.find_first_not_of('0', 1));
  return digits.size() > 9 || (!digits.empty() && std::stol(digits) > num_joints);
}

std::vector<int> JointColumns(const CsvTable& t, int num_joints) {
  std::vector<int> cols;
  if (static_cast<int>(t.joint_columns.size()) == num_joints) {
    for (const std::string& name : t.joint_columns) {
      const int c = t.Column(name);
      if (c < 0)
        throw InputError(Location(t.path, 1) + " column '" + CellExcerpt(name) + "'",
                         "missing: the file names joints by the robot's joint names, so each of "
                         "its " +
                             std::to_string(num_joints) +
                             " joints needs its column (or give q1..q" +
                             std::to_string(num_joints) + ")");
      cols.push_back(c);
    }
    return cols;
  }
  for (int j = 1; j <= num_joints; ++j) {
    int c = t.Column("q" + std::to_string(j));
    if (c < 0)
      throw InputError(Location(t.path, 1) + " column 'q" + std::to_string(j) + "'",
                       "missing; the robot has " + std::to_string(num_joints) +
                           " joints: expected columns q1..q" + std::to_string(num_joints));
    cols.push_back(c);
  }
  for (const std::string& name : t.header)
    if (NamesAnotherJoint(name, num_joints))
      throw InputError(Location(t.path, 1) + " column '" + CellExcerpt(name) + "'",
                       "the robot has only " + std::to_string(num_joints) +
                           " joints (wrong robot or wrong file?)");
  return cols;
}

std::vector<double> JointValues(const CsvTable& t, std::size_t row, const std::vector<int>& cols) {
  std::vector<double> q(cols.size());
  for (std::size_t j = 0; j < cols.size(); ++j) q[j] = t.Number(row, cols[j]);
  return q;
}

// The error for row r's `plane` entry `ref`, which names none of `planes` (null: one plane).
InputError UnknownPlane(const CsvTable& t, std::size_t r, const std::string& ref,
                        const PlaneSet* planes) {
  const int np = planes ? planes->size() : 1;
  std::string known;
  for (int k = 0; k < np; ++k)
    known += (k ? ", " : "") + std::to_string(k + 1) +
             (planes && !planes->name(k).empty() ? " (" + planes->name(k) + ")" : "");
  return InputError(Location(t.path, t.lines[r]) + " column 'plane'",
                    "'" + CellExcerpt(ref) + "' is not one of the " + std::to_string(np) +
                        " plane(s) given: expected " + known +
                        (np == 1 ? "; give the set-up's planes (robot file planes: or "
                                   "repeated --plane)"
                                 : ""));
}

// The plane of each row: the `plane` column (a 1-based index or a plane's name) resolved
// against `planes`, or 0 for every row without the column. A column naming a plane not given,
// or several planes given and no column, is an error.
std::vector<int> PlaneColumn(const CsvTable& t, const PlaneSet* planes) {
  const int pc = t.Column("plane");
  const int np = planes ? planes->size() : 1;
  if (pc < 0) {
    if (np > 1)
      throw InputError(Location(t.path, 1) + " column 'plane'",
                       "missing: " + std::to_string(np) +
                           " planes are given, so each row must say which one it is on "
                           "(a 1-based index or a plane's name)");
    return std::vector<int>(t.rows.size(), 0);
  }
  std::vector<int> out;
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    const std::string& ref = t.rows[r][pc];
    const int p = planes ? planes->Find(ref) : (ref == "1" ? 0 : -1);
    if (p < 0) throw UnknownPlane(t, r, ref, planes);
    out.push_back(p);
  }
  return out;
}

}  // namespace

TargetedConfigurations TargetConfigurations(const CsvTable& t, int num_joints, int num_targets) {
  std::vector<int> cols = JointColumns(t, num_joints);
  if (t.rows.empty()) throw InputError(t.path, "no configurations (only a header)");
  const int tc = t.Column("target");
  if (tc < 0 && num_targets > 1)
    throw InputError(Location(t.path, 1) + " column 'target'",
                     "missing: " + std::to_string(num_targets) +
                         " targets are given, so each row must say which one is measured (1 to " +
                         std::to_string(num_targets) + ")");
  TargetedConfigurations out(num_joints);
  out.Reserve(static_cast<int>(t.rows.size()));
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    int target = 0;
    if (tc >= 0) {
      const std::string& ref = t.rows[r][tc];
      std::size_t used = 0;
      int k = 0;
      try {
        k = std::stoi(ref, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != ref.size() || ref.empty() || k < 1 || k > num_targets)
        throw InputError(Location(t.path, t.lines[r]) + " column 'target'",
                         "'" + CellExcerpt(ref) + "' is not a target: expected 1 to " +
                             std::to_string(num_targets) + " (the targets given, in order)");
      target = k - 1;
    }
    out.Add(JointValues(t, r, cols), target);
  }
  return out;
}

TargetedConfigurations ReadTargetConfigurations(const std::string& path, int num_joints,
                                                int num_targets) {
  return TargetConfigurations(ReadCsv(path), num_joints, num_targets);
}

TargetedConfigurations ReadConfigurations(const std::string& path, int num_joints,
                                          const PlaneSet* planes) {
  return Configurations(ReadCsv(path), num_joints, planes);
}

namespace {

// The optional environment columns of a table (environment.h): gravity_x, gravity_y, gravity_z
// (m/s², base frame; all three or none) and temperature_c (°C), into each row's configuration of
// `q` (row r is configuration r).
void ReadEnvironmentColumns(const CsvTable& t, TargetedConfigurations* q) {
  const int gx = t.Column("gravity_x"), gy = t.Column("gravity_y"), gz = t.Column("gravity_z");
  const int tc = t.Column("temperature_c");
  const int given = (gx >= 0) + (gy >= 0) + (gz >= 0);
  if (given != 0 && given != 3) {
    const char* missing = gx < 0 ? "gravity_x" : gy < 0 ? "gravity_y" : "gravity_z";
    throw InputError(Location(t.path, 1) + " column '" + missing + "'",
                     "missing: expected gravity_x, gravity_y and gravity_z together (the gravity "
                     "vector in the base frame, m/s²), or none of them");
  }
  if (given == 0 && tc < 0) return;
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    Environment e;
    if (given == 3) e.gravity = Eigen::Vector3d(t.Number(r, gx), t.Number(r, gy), t.Number(r, gz));
    if (given == 3 && e.gravity.norm() > 100)
      throw InputError(Location(t.path, t.lines[r]) + " column 'gravity_x'",
                       "a gravity of " + FormatExact(e.gravity.norm()) +
                           " m/s²: expected m/s² (9.81 on the ground, 0 on orbit)");
    if (tc >= 0) e.temperature_c = t.Number(r, tc);
    if (tc >= 0 && e.temperature_c < -273.15)
      throw InputError(Location(t.path, t.lines[r]) + " column 'temperature_c'",
                       FormatExact(e.temperature_c) + " is below absolute zero: expected °C");
    q->SetEnvironment(static_cast<int>(r), e);
  }
}

}  // namespace

TargetedConfigurations Configurations(const CsvTable& t, int num_joints, const PlaneSet* planes) {
  const std::string& path = t.path;
  std::vector<int> cols = JointColumns(t, num_joints);
  if (t.rows.empty()) throw InputError(path, "no configurations (only a header)");
  const std::vector<int> plane = PlaneColumn(t, planes);
  TargetedConfigurations out(num_joints);
  for (std::size_t r = 0; r < t.rows.size(); ++r) out.Add(JointValues(t, r, cols), plane[r]);
  ReadEnvironmentColumns(t, &out);
  return out;
}

ConfigurationSet ReadPoses(const std::string& path, int num_joints) {
  return Poses(ReadCsv(path), num_joints);
}

ConfigurationSet Poses(const CsvTable& t, int num_joints) {
  const std::string& path = t.path;
  std::vector<int> cols = JointColumns(t, num_joints);
  if (t.rows.empty()) throw InputError(path, "no configurations (only a header)");
  ConfigurationSet out(num_joints);
  for (std::size_t r = 0; r < t.rows.size(); ++r) out.Add(JointValues(t, r, cols));
  return out;
}

MeasurementSet ReadMeasurements(const std::string& path, int num_joints, const RangerSpec* ranger,
                                const PlaneSet* planes, const Averaging& average) {
  return Measurements(ReadCsv(path), num_joints, ranger, planes, average);
}

MeasurementSet Measurements(const CsvTable& t, int num_joints, const RangerSpec* ranger,
                            const PlaneSet* planes, const Averaging& average) {
  const std::string& path = t.path;
  std::vector<int> cols = JointColumns(t, num_joints);
  const int hc = t.Column("h");
  if (hc < 0)
    throw InputError(Location(path, 1) + " column 'h'", "missing: expected the reading h (m)");
  if (t.rows.empty()) throw InputError(path, "no readings (only a header)");
  const std::vector<int> plane = PlaneColumn(t, planes);
  TargetedConfigurations q(num_joints);
  q.Reserve(static_cast<int>(t.rows.size()));
  std::vector<double> h;
  // An optional `configuration` column labels the readings of one pose (any text).
  const int cc = t.Column("configuration");
  std::vector<std::string> labels;
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    q.Add(JointValues(t, r, cols), plane[r]);
    h.push_back(t.Number(r, hc));
    if (cc >= 0) {
      if (t.rows[r][cc].empty())
        throw InputError(Location(path, t.lines[r]) + " column 'configuration'",
                         "empty: expected the label of the configuration this reading was taken "
                         "at");
      labels.push_back(t.rows[r][cc]);
    }
  }
  ReadEnvironmentColumns(t, &q);
  return GroupReadings(
      q, h, ranger,
      [&](int r) { return r < 0 ? path : Location(path, t.lines[r]) + " column 'h'"; },
      cc >= 0 ? &labels : nullptr, average);
}

// The file is written whole or not at all. A path that cannot be a file is bad input (exit 2);
// a full or failing disk is a StorageError naming the file (exit 5).
void WriteOutputFile(const std::string& path, const std::string& text) {
  CheckOutputFile(path, "output file");
  WriteFileAtomically(path, text);
}

void CheckOutputFile(const std::string& path, const std::string& option) {
  namespace fs = std::filesystem;
  if (path.empty()) throw InputError(option, "expected a file name, got an empty string");
  std::error_code ec;
  if (fs::is_directory(path, ec))
    throw InputError(option, "'" + path + "' is a directory; expected a file name");
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty() && !fs::is_directory(parent, ec))
    throw InputError(
        option, "cannot write '" + path + "': the folder '" + parent.string() + "' does not exist");
}

void WriteConfigurations(const std::string& path, const TargetedConfigurations& configs,
                         const std::vector<std::string>& joint_names) {
  std::ostringstream out;
  const bool planes = configs.num_targets_referenced() > 1;
  for (int j = 0; j < configs.num_joints(); ++j)
    out << (j ? "," : "")
        << (joint_names.empty() ? "q" + std::to_string(j + 1)
                                : joint_names[static_cast<std::size_t>(j)]);
  out << (planes ? ",plane\n" : "\n");
  for (int i = 0; i < configs.size(); ++i) {
    for (int j = 0; j < configs.num_joints(); ++j)
      out << (j ? "," : "") << FormatExact(configs.q(i)[j]);
    if (planes) out << "," << configs.target(i) + 1;
    out << "\n";
  }
  WriteOutputFile(path, out.str());
}

void WritePoses(const std::string& path, const ConfigurationSet& poses) {
  WriteConfigurations(path, TargetedConfigurations(poses));
}

void WriteReadings(const std::string& path, const TargetedConfigurations& configs,
                   const std::vector<double>& readings, int repetitions) {
  std::ostringstream out;
  for (int j = 0; j < configs.num_joints(); ++j) out << "q" << j + 1 << ",";
  const bool planes = configs.num_targets_referenced() > 1;
  const bool environments = configs.HasEnvironments();
  if (environments) out << "gravity_x,gravity_y,gravity_z,temperature_c,";
  out << (planes ? "plane,h,repetition\n" : "h,repetition\n");
  for (int i = 0, k = 0; i < configs.size(); ++i)
    for (int r = 0; r < repetitions; ++r, ++k) {
      for (int j = 0; j < configs.num_joints(); ++j) out << FormatExact(configs.q(i)[j]) << ",";
      if (environments) {
        const Environment& e = configs.environment(i);
        for (int c = 0; c < 3; ++c) out << FormatExact(e.gravity[c]) << ",";
        out << FormatExact(e.temperature_c) << ",";
      }
      if (planes) out << configs.target(i) + 1 << ",";
      out << FormatExact(readings[k]) << "," << r + 1 << "\n";
    }
  WriteOutputFile(path, out.str());
}

}  // namespace lrcal
