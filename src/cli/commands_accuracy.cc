// lrcal accuracy, and identify --predict-at: the calibrated arm's predicted accuracy at poses.
#include <cmath>
#include <iostream>
#include <map>

#include "cli_common.h"
#include "lrcal/core/error.h"
#include "lrcal/core/text_table.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_file.h"

namespace lrcal::cli {

namespace {

Json Vec3(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

// The parameter set a calibration record names: plane and ranger terms from their names, robot
// parameters not named are fixed. Its order is MakeParameterSet's; `order` maps it to the
// record's.
ParameterSet RecordParameterSet(const RobotModel& robot, const CalibrationRecord& r,
                                const std::string& source) {
  PlaneTerms plane;
  RangerTerms ranger;
  for (const std::string& name : r.parameters) {
    if (name == "plane_u1" || name == "plane_u2") plane.normal = true;
    if (name == "plane_f") plane.offset = true;
    if (name == "ranger_offset") ranger.offset = true;
    if (name == "ranger_scale") ranger.scale = true;
  }
  std::vector<std::string> fixed;
  for (int k : robot.parameter_indices()) {
    const std::string name = robot.ValueName(k);
    bool named = false;
    for (const std::string& p : r.parameters) named = named || p == name;
    if (!named) fixed.push_back(name);
  }
  if (plane.normal)
    for (const char* u : {"plane_u1", "plane_u2"}) {
      bool named = false;
      for (const std::string& p : r.parameters) named = named || p == u;
      if (!named) fixed.push_back(u);
    }
  return MakeParameterSet(robot, plane, fixed, source, ranger);
}

}  // namespace

Json PoseAccuracyJson(const std::vector<PoseAccuracy>& poses, const ConfigurationSet& configs) {
  Json list = Json::array();
  for (std::size_t j = 0; j < poses.size(); ++j)
    list.push_back(
        {{"q", std::vector<double>(configs.q(static_cast<int>(j)),
                                   configs.q(static_cast<int>(j)) + configs.num_joints())},
         {"position_std", Vec3(poses[j].position_std)},
         {"orientation_std", Vec3(poses[j].orientation_std)},
         {"position_radius_95", poses[j].position_radius_95}});
  const PoseAccuracySummary s = SummarizePoseAccuracy(poses);
  return {{"poses", list},
          {"rms_position", s.rms_position},
          {"p95_position_radius_95", s.p95_radius_95},
          {"worst", s.worst + 1}};
}

std::string PoseAccuracyText(const std::vector<PoseAccuracy>& poses) {
  Table t({"pose", "position std x", "y", "z", "orientation std x", "y", "z", "95 % radius"},
          "Predicted accuracy of the calibrated arm (position in mm, orientation in mrad)");
  for (std::size_t j = 0; j < poses.size(); ++j) {
    const PoseAccuracy& p = poses[j];
    t.AddRow({std::to_string(j + 1), Fixed(p.position_std.x() * 1e3),
              Fixed(p.position_std.y() * 1e3), Fixed(p.position_std.z() * 1e3),
              Fixed(p.orientation_std.x() * 1e3), Fixed(p.orientation_std.y() * 1e3),
              Fixed(p.orientation_std.z() * 1e3), Fixed(p.position_radius_95 * 1e3)});
  }
  const PoseAccuracySummary s = SummarizePoseAccuracy(poses);
  return t.ToText() + "over these " + std::to_string(poses.size()) + " poses: RMS position error " +
         Fixed(s.rms_position * 1e3) + " mm; 95th percentile of the 95 % radius " +
         Fixed(s.p95_radius_95 * 1e3) + " mm; worst pose " + std::to_string(s.worst + 1) + "\n";
}

int AccuracyCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal accuracy options");
  AddCommonOptions(o);
  o.add_options()("configs", po::value<std::string>()->required(),
                  "poses to predict at: a configurations CSV (q1..qN, rad)");
  po::variables_map vm;
  if (!Parse("accuracy", "--robot CAL.yaml --configs P.csv [options]", o, args, &vm)) return 0;
  const Setup setup = ResolveSetup(vm);
  const RobotFile& rig = setup.rig;
  if (!rig.calibration || rig.calibration->covariance.size() == 0)
    throw InputError("--robot", "'" + rig.path +
                                    "' has no calibration record with a covariance: write one "
                                    "with lrcal identify --write-robot (give --sigma-mm, or "
                                    "more configurations than parameters)");
  const CalibrationRecord& r = *rig.calibration;
  const ParameterSet ps = RecordParameterSet(rig.robot, r, rig.path + " calibration.parameters");
  // The record's covariance in the parameter set's order.
  const int n = ps.size();
  if (n != static_cast<int>(r.parameters.size()))
    throw InputError(rig.path + " calibration.parameters",
                     "names a parameter this robot does not have");
  std::vector<int> at(n);
  for (int k = 0; k < n; ++k) {
    at[k] = -1;
    for (int i = 0; i < n; ++i)
      if (r.parameters[i] == ps.names[k]) at[k] = i;
    if (at[k] < 0) throw InputError(rig.path + " calibration.parameters", "missing " + ps.names[k]);
  }
  Eigen::MatrixXd C(n, n);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) C(a, b) = r.covariance(at[a], at[b]);
  const MeasurementModel model(rig.robot, setup.plane, ps);
  const ConfigurationSet configs =
      ReadRobotConfigurations(vm["configs"].as<std::string>(), rig.robot);
  const std::vector<double> zero(n, 0.0);  // the file's nominal values are the estimates
  const std::vector<PoseAccuracy> poses = PredictPoseAccuracy(model, zero.data(), C, configs);
  if (ResolveFormat(vm) == Format::kJson) {
    Json j = PoseAccuracyJson(poses, configs);
    j["sigma"] = r.sigma;
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "covariance of " << rig.path << " (sigma " << Fixed(r.sigma * 1e3, 4)
              << " mm per reading)\n"
              << PoseAccuracyText(poses);
  }
  return 0;
}

}  // namespace lrcal::cli
