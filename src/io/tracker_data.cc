#include "lrcal/io/tracker_data.h"

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>

#include "lrcal/core/error.h"
#include "lrcal/core/strings.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_data.h"
#include "lrcal/measurement/pose_measurement.h"

namespace lrcal {

namespace {

constexpr const char* kPositionColumns[3] = {"x", "y", "z"};
constexpr const char* kQuaternionColumns[4] = {"qx", "qy", "qz", "qw"};
constexpr double kUnitQuaternionTolerance = 1e-6;
constexpr int kMaxReadingsPerRow = 1000000;

int RequiredColumn(const CsvTable& t, const std::string& name, const std::string& what) {
  const int c = t.Column(name);
  if (c < 0)
    throw InputError(Location(t.path, 1) + " column '" + name + "'", "missing: expected " + what);
  return c;
}

}  // namespace

Eigen::Matrix3d UnitQuaternionRotation(const double* xyzw, const std::string& where) {
  const Eigen::Quaterniond q(xyzw[3], xyzw[0], xyzw[1], xyzw[2]);
  if (!(std::fabs(q.norm() - 1) <= kUnitQuaternionTolerance))
    throw InputError(where, "expected a unit quaternion (norm 1 within 1e-6), got norm " +
                                FormatExact(q.norm()));
  return q.normalized().toRotationMatrix();
}

Eigen::Vector3d QuaternionOrientationValue(const PoseMeasurement& pose,
                                           const TargetedConfigurations& configs, int i,
                                           const double* xyzw, const std::string& where) {
  return pose.OrientationValue(configs.q(i), configs.target(i),
                               UnitQuaternionRotation(xyzw, where));
}

MeasuredValues ReadTrackerMeasurements(const std::string& path, const PointMeasurement& kind) {
  return TrackerMeasurementsFromTable(ReadRobotCsv(path, kind.robot()), kind);
}

MeasuredValues TrackerMeasurementsFromTable(const CsvTable& t, const PointMeasurement& kind) {
  const RobotModel& robot = kind.robot();
  const std::string& path = t.path;
  const int num_targets = static_cast<int>(kind.setup().targets.size());
  MeasuredValues data{TargetConfigurations(t, robot.num_links(), num_targets), {}, {}};
  CheckJointRanges(data.configs, robot, path);
  int position[3], quaternion[4];
  for (int c = 0; c < 3; ++c)
    position[c] = RequiredColumn(t, kPositionColumns[c],
                                 "the target's position in the instrument's frame (m)");
  const auto* pose = dynamic_cast<const PoseMeasurement*>(&kind);
  if (pose)
    for (int c = 0; c < 4; ++c)
      quaternion[c] = RequiredColumn(
          t, kQuaternionColumns[c],
          "the target's orientation in the instrument's frame as a unit quaternion qx,qy,qz,qw");
  const int readings = t.Column("readings");
  const int k = kind.rows_per_configuration();
  data.y.reserve(static_cast<std::size_t>(k) * t.rows.size());
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    for (int c = 0; c < 3; ++c) data.y.push_back(t.Number(r, position[c]));
    if (pose) {
      double v[4];
      for (int c = 0; c < 4; ++c) v[c] = t.Number(r, quaternion[c]);
      const Eigen::Vector3d phi =
          QuaternionOrientationValue(*pose, data.configs, static_cast<int>(r), v,
                                     Location(t.path, t.lines[r]) + " columns qx,qy,qz,qw");
      for (int c = 0; c < 3; ++c) data.y.push_back(phi[c]);
    }
    int count = 1;
    if (readings >= 0) {
      const double n = t.Number(r, readings);
      if (!(n >= 1 && n <= kMaxReadingsPerRow && n == std::floor(n)))
        throw InputError(Location(t.path, t.lines[r]) + " column 'readings'",
                         "expected a whole number of readings from 1 to 1,000,000, got '" +
                             CellExcerpt(t.rows[r][readings]) + "'");
      count = static_cast<int>(n);
    }
    data.repetitions.push_back(count);
  }
  return data;
}

void WriteTrackerMeasurements(const std::string& path, const PointMeasurement& kind,
                              const MeasuredValues& data) {
  const auto* pose = dynamic_cast<const PoseMeasurement*>(&kind);
  const int k = kind.rows_per_configuration();
  const bool targets = kind.setup().targets.size() > 1;
  std::ostringstream out;
  for (int j = 0; j < data.configs.num_joints(); ++j) out << "q" << j + 1 << ",";
  out << (targets ? "target," : "") << "x,y,z," << (pose ? "qx,qy,qz,qw," : "") << "readings\n";
  for (int i = 0; i < data.size(); ++i) {
    for (int j = 0; j < data.configs.num_joints(); ++j)
      out << FormatExact(data.configs.q(i)[j]) << ",";
    if (targets) out << data.configs.target(i) + 1 << ",";
    const double* y = &data.y[static_cast<std::size_t>(i) * k];
    for (int c = 0; c < 3; ++c) out << FormatExact(y[c]) << ",";
    if (pose) {
      const Eigen::Quaterniond q(pose->OrientationOf(data.configs.q(i), data.configs.target(i),
                                                     Eigen::Vector3d(y[3], y[4], y[5])));
      for (double v : {q.x(), q.y(), q.z(), q.w()}) out << FormatExact(v) << ",";
    }
    out << data.repetitions[static_cast<std::size_t>(i)] << "\n";
  }
  WriteOutputFile(path, out.str());
}

}  // namespace lrcal
