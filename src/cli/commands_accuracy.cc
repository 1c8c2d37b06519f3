// lrcal accuracy, and identify --predict-at: the calibrated arm's predicted accuracy at poses.
#include <algorithm>
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
ParameterSet RecordParameterSet(const RobotModel& robot, const CalibrationRecord& r, int num_planes,
                                const std::string& source) {
  const auto named = [&](const std::string& name) {
    return std::find(r.parameters.begin(), r.parameters.end(), name) != r.parameters.end();
  };
  std::vector<PlaneTerms> planes(num_planes);
  std::vector<std::string> fixed;
  for (int p = 0; p < num_planes; ++p) {
    const std::string u1 = PlaneTermName(p, num_planes, "u1"),
                      u2 = PlaneTermName(p, num_planes, "u2");
    planes[p].normal = named(u1) || named(u2);
    planes[p].offset = named(PlaneTermName(p, num_planes, "f"));
    if (planes[p].normal && !named(u1)) fixed.push_back(u1);
    if (planes[p].normal && !named(u2)) fixed.push_back(u2);
  }
  RangerTerms ranger;
  ranger.offset = named("ranger_offset");
  ranger.scale = named("ranger_scale");
  for (int k : robot.parameter_indices())
    if (!named(robot.ValueName(k))) fixed.push_back(robot.ValueName(k));
  return MakeParameterSet(robot, planes, fixed, source, ranger);
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
  const ParameterSet ps =
      RecordParameterSet(rig.robot, r, setup.planes.size(), rig.path + " calibration.parameters");
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
  const MeasurementModel model(rig.robot, setup.planes, ps);
  const ConfigurationSet configs =
      ReadRobotConfigurations(vm["configs"].as<std::string>(), rig.robot, &setup.planes);
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
