// lrcal accuracy, and identify --predict-at: the calibrated arm's predicted accuracy at poses.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>

#include "cli_common.h"
#include "lrcal/core/error.h"
#include "lrcal/core/text_table.h"
#include "lrcal/design/configuration_sampling.h"
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

ConfigurationSet WorkspacePoses(const RobotModel& robot, int count, long long seed) {
  if (count < 1 || count > 100000)
    throw InputError("--workspace", "expected 1 to 100,000 poses, got " + std::to_string(count));
  if (seed < 0) throw InputError("--seed", "expected a non-negative integer");
  SamplingOptions o;
  o.require_beam_hit = false;
  return SampleConfigurations(
      robot, Plane{}, count,
      RandomStream(static_cast<std::uint64_t>(seed), 0, 0, RandomPurpose::kValidation), o);
}

int AccuracyCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal accuracy options");
  AddCommonOptions(o);
  o.add_options()("configs", po::value<std::string>(),
                  "poses to predict at: a configurations CSV (q1..qN, rad)")(
      "workspace", po::value<int>(),
      "or: this many poses drawn over the robot's joint ranges (non-singular arm)")(
      "seed", po::value<long long>()->default_value(1), "seed of the --workspace draw");
  po::variables_map vm;
  if (!Parse("accuracy", "--robot CAL.yaml --configs P.csv|--workspace N [options]", o, args, &vm))
    return 0;
  if (vm.count("configs") == vm.count("workspace"))
    throw InputError("--configs/--workspace",
                     "give exactly one: a poses CSV or a number of poses to draw");
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
      vm.count("configs")
          ? ReadRobotConfigurations(vm["configs"].as<std::string>(), rig.robot, &setup.planes)
          : WorkspacePoses(rig.robot, vm["workspace"].as<int>(), vm["seed"].as<long long>());
  const std::vector<double> zero(n, 0.0);  // the file's nominal values are the estimates
  const std::vector<PoseAccuracy> poses = PredictPoseAccuracy(model, zero.data(), C, configs);
  if (ResolveFormat(vm) == Format::kJson) {
    Json j = PoseAccuracyJson(poses, configs);
    j["sigma"] = r.sigma;
    if (vm.count("workspace"))
      j["workspace"] = {{"poses", configs.size()}, {"seed", vm["seed"].as<long long>()}};
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "covariance of " << rig.path << " (sigma " << Fixed(r.sigma * 1e3, 4)
              << " mm per reading)\n";
    if (vm.count("workspace"))
      std::cout << configs.size() << " poses drawn over the joint ranges (seed "
                << vm["seed"].as<long long>() << ")\n";
    std::cout << PoseAccuracyText(poses);
  }
  return 0;
}

}  // namespace lrcal::cli
