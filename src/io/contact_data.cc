#include "lrcal/io/contact_data.h"

#include <cmath>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/strings.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_data.h"

namespace lrcal {

namespace {

constexpr int kMaxContactReadingsPerRow = 1000000;

}  // namespace

ContactData ReadContactData(const std::string& path, const RobotModel& robot,
                            const PlaneSet& planes, bool flush_default) {
  return ContactDataFromTable(ReadRobotCsv(path, robot), robot, planes, flush_default);
}

ContactData ContactDataFromTable(const CsvTable& t, const RobotModel& robot, const PlaneSet& planes,
                                 bool flush_default) {
  ContactData data;
  data.values.configs = Configurations(t, robot.num_links(), &planes);
  CheckJointRanges(data.values.configs, robot, t.path);
  const int flush = t.Column("flush"), readings = t.Column("readings");
  data.flush = flush_default;
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    if (flush >= 0) {
      const double v = t.Number(r, flush);
      if (v != 0 && v != 1)
        throw InputError(Location(t.path, t.lines[r]) + " column 'flush'",
                         "expected 1 (the tool square to the plane) or 0 (the point only), got '" +
                             CellExcerpt(t.rows[r][flush]) + "'");
      if (r == 0) data.flush = v == 1;
      if ((v == 1) != data.flush)
        throw InputError(Location(t.path, t.lines[r]) + " column 'flush'",
                         "one file holds flush or point contacts, not both (this row differs "
                         "from the first): give them as two files");
    }
    int count = 1;
    if (readings >= 0) {
      const double n = t.Number(r, readings);
      if (!(n >= 1 && n <= kMaxContactReadingsPerRow && n == std::floor(n)))
        throw InputError(Location(t.path, t.lines[r]) + " column 'readings'",
                         "expected a whole number of contacts from 1 to 1,000,000, got '" +
                             CellExcerpt(t.rows[r][readings]) + "'");
      count = static_cast<int>(n);
    }
    data.values.repetitions.push_back(count);
  }
  data.values.y.assign((data.flush ? 3 : 1) * t.rows.size(), 0.0);
  return data;
}

void WriteContactData(const std::string& path, const MeasuredValues& data, bool flush) {
  std::ostringstream out;
  for (int j = 0; j < data.configs.num_joints(); ++j) out << "q" << j + 1 << ",";
  out << "plane,flush,readings\n";
  for (int i = 0; i < data.size(); ++i) {
    for (int j = 0; j < data.configs.num_joints(); ++j)
      out << FormatExact(data.configs.q(i)[j]) << ",";
    out << data.configs.target(i) + 1 << "," << (flush ? 1 : 0) << ","
        << data.repetitions[static_cast<std::size_t>(i)] << "\n";
  }
  WriteOutputFile(path, out.str());
}

}  // namespace lrcal
