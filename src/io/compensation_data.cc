#include "lrcal/io/compensation_data.h"

#include <Eigen/Geometry>
#include <cmath>

#include "lrcal/core/error.h"
#include "lrcal/core/json.h"
#include "lrcal/core/strings.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_data.h"
#include "lrcal/io/tracker_data.h"

namespace lrcal {

CompensationTargets ReadCompensationTargets(const std::string& path, const RobotModel& robot) {
  const CsvTable t = ReadRobotCsv(path, robot);
  CompensationTargets out;
  out.plans = Poses(t, robot.num_links());
  CheckJointRanges(out.plans, robot, path);
  const int x = t.Column("x"), y = t.Column("y"), z = t.Column("z");
  const int qx = t.Column("qx"), qy = t.Column("qy"), qz = t.Column("qz"), qw = t.Column("qw");
  const int position_columns = (x >= 0) + (y >= 0) + (z >= 0);
  const int quaternion_columns = (qx >= 0) + (qy >= 0) + (qz >= 0) + (qw >= 0);
  if (position_columns != 0 && position_columns != 3)
    throw InputError(Location(path, 1),
                     "a target position needs the columns x, y and z (m, base frame), all three");
  if (quaternion_columns != 0 && (quaternion_columns != 4 || position_columns != 3))
    throw InputError(Location(path, 1),
                     "a target orientation needs qx, qy, qz and qw, with x, y and z");
  if (position_columns == 0) return out;
  out.orientation = quaternion_columns == 4;
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    Pose<double> pose;
    pose.p_BT = Eigen::Vector3d(t.Number(r, x), t.Number(r, y), t.Number(r, z));
    if (out.orientation) {
      const double xyzw[4] = {t.Number(r, qx), t.Number(r, qy), t.Number(r, qz), t.Number(r, qw)};
      pose.R_BT =
          UnitQuaternionRotation(xyzw, Location(t.path, t.lines[r]) + " columns qx, qy, qz, qw");
    }
    out.poses.push_back(pose);
  }
  return out;
}

std::string CompensationCsvText(const std::vector<Compensation>& results, int num_joints) {
  std::string text;
  for (int j = 0; j < num_joints; ++j) text += "q" + std::to_string(j + 1) + ",";
  text += "position_error_mm,orientation_error_mrad,converged,within_limits,iterations\n";
  for (const Compensation& c : results) {
    for (double q : c.q) text += FileNumber(q) + ",";
    text += FileNumber(c.position_error * 1e3) + "," + FileNumber(c.orientation_error * 1e3) + "," +
            (c.converged ? "1" : "0") + "," + (c.within_limits ? "1" : "0") + "," +
            std::to_string(c.iterations) + "\n";
  }
  return text;
}

void WriteCompensation(const std::string& path, const std::vector<Compensation>& results,
                       int num_joints) {
  WriteFileAtomically(path, CompensationCsvText(results, num_joints));
}

}  // namespace lrcal
