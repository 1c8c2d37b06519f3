#include "lrcal/io/socket_data.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/strings.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_data.h"

namespace lrcal {

namespace {

constexpr double kMaxSocketIdValue = 1e9;
constexpr int kMaxSocketReadingsPerRow = 1000000;

}  // namespace

SocketData ReadSocketData(const std::string& path, const RobotModel& robot) {
  return SocketDataFromTable(ReadRobotCsv(path, robot), robot);
}

SocketData SocketDataFromTable(const CsvTable& t, const RobotModel& robot) {
  const std::string& path = t.path;
  const TargetedConfigurations joints = TargetConfigurations(t, robot.num_links(), 1);
  CheckJointRanges(joints, robot, path);
  const int column = t.Column("socket");
  if (column < 0)
    throw InputError(Location(t.path, 1) + " column 'socket'",
                     "missing: expected the id of the socket each row's tool point sits in (a "
                     "whole number ≥ 0)");
  const int readings = t.Column("readings");
  std::vector<int> socket(t.rows.size()), count(t.rows.size(), 1);
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    const std::string& cell = t.rows[r][column];
    double v;
    if (!ParseDecimal(cell, &v) || !(v >= 0 && v <= kMaxSocketIdValue) || v != std::floor(v))
      throw InputError(Location(t.path, t.lines[r]) + " column 'socket'",
                       "'" + CellExcerpt(cell) +
                           "' is not a socket id: expected a whole number from 0 to 1000000000");
    socket[r] = static_cast<int>(v);
    if (readings < 0) continue;
    const double n = t.Number(r, readings);
    if (!(n >= 1 && n <= kMaxSocketReadingsPerRow && n == std::floor(n)))
      throw InputError(Location(t.path, t.lines[r]) + " column 'readings'",
                       "expected a whole number of seatings from 1 to 1,000,000, got '" +
                           CellExcerpt(t.rows[r][readings]) + "'");
    count[r] = static_cast<int>(n);
  }
  return MakeSocketData(joints, socket, count, path);
}

SocketData MakeSocketData(const ConfigurationSet& configs, const std::vector<int>& socket_ids,
                          std::vector<int> repetitions, const std::string& source) {
  const auto n = static_cast<std::size_t>(configs.size());
  if (socket_ids.size() != n || repetitions.size() != n)
    throw InputError(
        source, "expected one socket id and one count of seatings per configuration (" +
                    std::to_string(n) + "), got " + std::to_string(socket_ids.size()) + " and " +
                    std::to_string(repetitions.size()));
  for (std::size_t i = 0; i < n; ++i) {
    if (socket_ids[i] < 0)
      throw InputError(source, "configuration " + std::to_string(i + 1) +
                                   ": expected a socket id ≥ 0, got " +
                                   std::to_string(socket_ids[i]));
    if (repetitions[i] < 1)
      throw InputError(source,
                       "configuration " + std::to_string(i + 1) + ": expected at least 1 seating");
  }
  SocketData data;
  data.ids = socket_ids;
  std::sort(data.ids.begin(), data.ids.end());
  data.ids.erase(std::unique(data.ids.begin(), data.ids.end()), data.ids.end());
  data.values.configs = TargetedConfigurations(configs.num_joints());
  data.values.configs.Reserve(configs.size());
  for (int i = 0; i < configs.size(); ++i) {
    const auto index = std::lower_bound(data.ids.begin(), data.ids.end(),
                                        socket_ids[static_cast<std::size_t>(i)]) -
                       data.ids.begin();
    data.values.configs.AddFrom(configs, i, static_cast<int>(index));
  }
  data.values.y.assign(3 * n, 0.0);
  data.values.repetitions = std::move(repetitions);
  return data;
}

void WriteSocketData(const std::string& path, const std::vector<int>& ids,
                     const MeasuredValues& data) {
  std::ostringstream out;
  for (int j = 0; j < data.configs.num_joints(); ++j) out << "q" << j + 1 << ",";
  out << "socket,readings\n";
  for (int i = 0; i < data.size(); ++i) {
    for (int j = 0; j < data.configs.num_joints(); ++j)
      out << FormatExact(data.configs.q(i)[j]) << ",";
    out << ids[static_cast<std::size_t>(data.configs.target(i))] << ","
        << data.repetitions[static_cast<std::size_t>(i)] << "\n";
  }
  WriteOutputFile(path, out.str());
}

}  // namespace lrcal
