#include "lrcal/io/scanner_data.h"

#include <cmath>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/strings.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_data.h"

namespace lrcal {

namespace {

constexpr int kMaxScannerReadingsPerRow = 1000000;

// Row r's whole number in column c within [1, max]; `what` names it in the error.
int WholeNumber(const CsvTable& t, std::size_t r, int c, int max, const char* column,
                const std::string& expected) {
  const double v = t.Number(r, c);
  if (!(v >= 1 && v <= max && v == std::floor(v)))
    throw InputError(Location(t.path, t.lines[r]) + " column '" + column + "'",
                     "expected " + expected + ", got '" + CellExcerpt(t.rows[r][c]) + "'");
  return static_cast<int>(v);
}

// The rows' configurations (one per row, ReadRobotConfigurations) grouped: consecutive rows with
// the same joint values and plane.
bool SameConfiguration(const TargetedConfigurations& rows, int a, int b) {
  if (rows.target(a) != rows.target(b)) return false;
  for (int j = 0; j < rows.num_joints(); ++j)
    if (rows.q(a)[j] != rows.q(b)[j]) return false;
  return true;
}

}  // namespace

namespace {

// One configuration's rows [first, last) into `data`: B values in beam order, its repetitions.
void ReadScan(const CsvTable& t, const TargetedConfigurations& rows, std::size_t first,
              std::size_t last, int num_beams, MeasuredValues* data) {
  const int beam = t.Column("beam"), h = t.Column("h"), readings = t.Column("readings");
  const auto B = static_cast<std::size_t>(num_beams);
  const auto count = [&](std::size_t r) {
    return readings >= 0 ? WholeNumber(t, r, readings, kMaxScannerReadingsPerRow, "readings",
                                       "a whole number of readings from 1 to 1,000,000")
                         : 1;
  };
  data->configs.AddFrom(rows, static_cast<int>(first));
  data->repetitions.push_back(count(first));
  const std::size_t base = data->y.size();
  data->y.insert(data->y.end(), B, 0.0);
  std::vector<bool> seen(B, false);
  for (std::size_t r = first; r < last; ++r) {
    const auto b = static_cast<std::size_t>(
        WholeNumber(
            t, r, beam, num_beams, "beam",
            "a beam number from 1 to " + std::to_string(num_beams) + " (the scanner's beams)") -
        1);
    if (seen[b])
      throw InputError(Location(t.path, t.lines[r]) + " column 'beam'",
                       "beam " + std::to_string(b + 1) +
                           " is read twice in one configuration (consecutive rows with the same "
                           "joint values and plane)");
    seen[b] = true;
    if (count(r) != data->repetitions.back())
      throw InputError(Location(t.path, t.lines[r]) + " column 'readings'",
                       "differs from the configuration's first row: every beam of a "
                       "configuration averages the same number of readings");
    const double value = t.Number(r, h);
    if (!std::isfinite(value))
      throw InputError(Location(t.path, t.lines[r]) + " column 'h'",
                       "expected a finite reading (m)");
    data->y[base + b] = value;
  }
  for (std::size_t b = 0; b < B; ++b)
    if (!seen[b])
      throw InputError(Location(t.path, t.lines[first]) + " column 'beam'",
                       "the configuration starting here has no reading of beam " +
                           std::to_string(b + 1) + " (each configuration needs beams 1 to " +
                           std::to_string(num_beams) + ", once each, on consecutive rows)");
}

}  // namespace

MeasuredValues ReadScannerData(const std::string& path, const RobotModel& robot,
                               const PlaneSet& planes, int num_beams) {
  return ScannerDataFromTable(ReadRobotCsv(path, robot), robot, planes, num_beams);
}

MeasuredValues ScannerDataFromTable(const CsvTable& t, const RobotModel& robot,
                                    const PlaneSet& planes, int num_beams) {
  const std::string& path = t.path;
  const TargetedConfigurations rows = Configurations(t, robot.num_links(), &planes);
  CheckJointRanges(rows, robot, path);
  if (t.Column("beam") < 0)
    throw InputError(
        Location(path, 1) + " column 'beam'",
        "missing: expected the beam's number in the fan (1 to " + std::to_string(num_beams) + ")");
  if (t.Column("h") < 0)
    throw InputError(Location(path, 1) + " column 'h'", "missing: expected the reading h (m)");
  MeasuredValues data{TargetedConfigurations(rows.num_joints()), {}, {}};
  std::size_t first = 0;
  for (std::size_t r = 1; r <= t.rows.size(); ++r)
    if (r == t.rows.size() ||
        !SameConfiguration(rows, static_cast<int>(first), static_cast<int>(r))) {
      ReadScan(t, rows, first, r, num_beams, &data);
      first = r;
    }
  return data;
}

void WriteScannerData(const std::string& path, const MeasuredValues& data, int num_beams) {
  std::ostringstream out;
  for (int j = 0; j < data.configs.num_joints(); ++j) out << "q" << j + 1 << ",";
  out << "plane,beam,h,readings\n";
  for (int i = 0; i < data.size(); ++i)
    for (int b = 0; b < num_beams; ++b) {
      for (int j = 0; j < data.configs.num_joints(); ++j)
        out << FormatExact(data.configs.q(i)[j]) << ",";
      out << data.configs.target(i) + 1 << "," << b + 1 << ","
          << FormatExact(data.y[static_cast<std::size_t>(num_beams * i + b)]) << ","
          << data.repetitions[static_cast<std::size_t>(i)] << "\n";
    }
  WriteOutputFile(path, out.str());
}

}  // namespace lrcal
